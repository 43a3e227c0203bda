"""Reading a model file safely: the ``.npz`` archive of :meth:`engine.method.model.Model.save`, checked
before anything is trusted.

Every zip member's compression method and size, and every array's ``.npy`` header (dtype, shape)
are checked before any array is allocated; then the metadata's types, and every array's dtype,
shape (against the metadata and against the other arrays) and values (finite). Any problem is a
:class:`~engine.errors.ModelFileError` naming the file.
"""

from __future__ import annotations

import json
import math
import os
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..data import LABEL_KINDS
from ..errors import ModelFileError
from .c3d_check import MAX_RATE, MIN_RATE

#: Largest single array a model file may hold (a codebook of about 10^7 codewords).
MAX_ARRAY_BYTES = 1 << 30
#: Largest metadata entry (phone and utterance lists).
MAX_META_BYTES = 64 << 20
_COMPRESSIONS = (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED)


def read_members(path: Path) -> tuple[dict, dict[str, np.ndarray]]:
    """The metadata dict and the arrays of a model archive, each header checked first."""
    try:
        with zipfile.ZipFile(path) as zf:
            infos = zf.infolist()
            arrays: dict[str, np.ndarray] = {}
            for info in infos:
                name = info.filename.removesuffix(".npy")
                if info.compress_type not in _COMPRESSIONS:
                    raise ModelFileError(path, f"entry {name!r} uses an unsupported compression "
                                               f"method ({info.compress_type})")
                limit = MAX_META_BYTES if name == "meta" else MAX_ARRAY_BYTES
                if info.file_size > limit + 4096:
                    raise ModelFileError(path, f"entry {name!r} is {info.file_size} bytes, more than "
                                               f"a model holds (at most {limit})")
                with zf.open(info) as handle:
                    arrays[name] = _read_npy(path, name, handle, info.file_size, limit)
    except ModelFileError:
        raise
    except OSError as exc:
        raise ModelFileError(path, f"not a readable facetraj model (damaged zip structure: "
                                   f"{exc.strerror or exc})") from exc
    except (zipfile.BadZipFile, zlib.error, EOFError, ValueError, RuntimeError,
            NotImplementedError) as exc:
        raise ModelFileError(path, f"not a readable facetraj model ({exc})") from exc
    if "meta" not in arrays:
        raise ModelFileError(path, "not a facetraj model (no metadata entry)")
    meta_arr = arrays.pop("meta")
    if meta_arr.shape != () or meta_arr.dtype.kind != "U":
        raise ModelFileError(path, "not a facetraj model (metadata is not a text entry)")
    try:
        meta = json.loads(str(meta_arr))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise ModelFileError(path, f"the metadata is not valid JSON ({exc})") from exc
    if not isinstance(meta, dict):
        raise ModelFileError(path, "not a facetraj model (metadata is not a JSON object)")
    return meta, arrays


def _read_npy(path: Path, name: str, handle, member_size: int, limit: int) -> np.ndarray:
    """One ``.npy`` member: header checked (version, dtype, shape, size) before reading."""
    fmt = np.lib.format
    version = fmt.read_magic(handle)
    if version == (1, 0):
        shape, fortran, dtype = fmt.read_array_header_1_0(handle)
    elif version == (2, 0):
        shape, fortran, dtype = fmt.read_array_header_2_0(handle)
    else:
        raise ModelFileError(path, f"entry {name!r} has an unsupported .npy version {version}")
    if dtype.hasobject or dtype.kind not in "biufU":
        raise ModelFileError(path, f"entry {name!r} has data type {dtype}, not numbers or text")
    if any(d < 0 for d in shape):
        raise ModelFileError(path, f"entry {name!r} has a negative size {shape}")
    nbytes = math.prod(shape) * dtype.itemsize
    if nbytes > limit:
        raise ModelFileError(path, f"entry {name!r} asks for {nbytes} bytes ({shape}), more than a "
                                   f"model holds (at most {limit})")
    if nbytes > member_size:
        raise ModelFileError(path, f"entry {name!r} is shorter than its header says (truncated?)")
    data = handle.read(nbytes)
    if len(data) != nbytes:
        raise ModelFileError(path, f"entry {name!r} is shorter than its header says (truncated?)")
    handle.read(1 << 16)  # to the member's end, where the zip checks its CRC
    arr = np.frombuffer(data, dtype=dtype)
    if fortran:
        return arr.reshape(shape[::-1]).T.copy()
    return arr.reshape(shape).copy()


# --------------------------------------------------------------------------- the metadata
def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v) -> bool:
    return (isinstance(v, (int, float)) and not isinstance(v, bool)) and math.isfinite(v)


def _str_list(v) -> bool:
    return isinstance(v, list) and all(isinstance(x, str) for x in v)


def check_meta(path: Path, meta: dict, newest: int, fmt: str) -> None:
    """The metadata fields' presence, types and ranges."""
    if meta.get("format") != fmt:
        raise ModelFileError(path, "not a facetraj model")
    version = meta.get("version")
    if not _is_int(version) or version < 1:
        raise ModelFileError(path, f"the model format version is {version!r}, not a whole number")
    if version > newest:
        raise ModelFileError(path, f"model format {version} is newer than this facetraj reads "
                                   f"({newest}); upgrade facetraj")
    need = {"config": dict, "phones": list, "marker_names": list, "marker_rate": float,
            "upper_lip": int, "lower_lip": int, "pca_total_variance": float, "scale": float,
            "n_per_phone": int}
    missing = [k for k in need if k not in meta]
    if missing:
        raise ModelFileError(path, f"model file is incomplete: missing {', '.join(missing)}")

    def bad(field: str, what: str):
        return ModelFileError(path, f"metadata {field!r} is {meta.get(field)!r:.60}, not {what}")

    if not isinstance(meta["config"], dict):
        raise bad("config", "an object")
    for key in ("phones", "marker_names"):
        if not _str_list(meta[key]) or not meta[key] or len(set(meta[key])) != len(meta[key]):
            raise bad(key, "a list of distinct names")
    for key in ("marker_rate", "pca_total_variance", "scale"):
        if not _is_num(meta[key]) or meta[key] <= 0:
            raise bad(key, "a positive number")
    if not MIN_RATE <= meta["marker_rate"] <= MAX_RATE:
        raise bad("marker_rate", f"a frame rate from {MIN_RATE:g} to {MAX_RATE:g} Hz")
    n_markers = len(meta["marker_names"])
    for key in ("upper_lip", "lower_lip"):
        if not _is_int(meta[key]) or not 0 <= meta[key] < n_markers:
            raise bad(key, f"a marker index below {n_markers}")
    corners = meta.get("lip_corners", [])
    if not isinstance(corners, list) or not all(_is_int(c) and 0 <= c < n_markers for c in corners):
        raise bad("lip_corners", f"a list of marker indices below {n_markers}")
    if not _is_int(meta["n_per_phone"]) or not 1 <= meta["n_per_phone"] <= 100:
        raise bad("n_per_phone", "a whole number from 1 to 100")
    if not _str_list(meta.get("train_utterances", [])):
        raise bad("train_utterances", "a list of names")
    if not isinstance(meta.get("corpus_fingerprint", ""), str):
        raise bad("corpus_fingerprint", "text")
    tuned = meta.get("tuned", {})
    if not isinstance(tuned, dict) or not isinstance(tuned.get("settings", {}), dict) or \
            not all(_is_num(v) for v in tuned.get("settings", {}).values()):
        raise bad("tuned", "an object of cross-validated settings (numbers)")
    closed, d0 = meta.get("closure_closed"), meta.get("voice_distance")
    if closed is not None and (not _is_num(closed) or not abs(closed) < 1e6):
        raise bad("closure_closed", "a lip aperture in mm")
    if d0 is not None and (not _is_num(d0) or not 0 < d0 < 1e6):
        raise bad("voice_distance", "a positive number")
    kinds = meta.get("trained_labels", {})
    if not isinstance(kinds, dict) or not all(k in LABEL_KINDS and _is_int(n) and n >= 0
                                              for k, n in kinds.items()):
        raise bad("trained_labels", f"an object of utterance counts by label kind "
                                    f"({', '.join(LABEL_KINDS)})")


def check_config(path: Path, config: dict) -> None:
    """The training configuration's types and ranges (as the command line would accept them)."""
    ints = {"audio_rate": (8000, 192000), "lpc_order": (2, 64), "context": (0, 10),
            "codewords_per_phone": (1, 100), "lsf_context_frames": (0, 100)}
    reals = {"window_s": (1e-3, 1.0), "preemphasis": (0.0, 1.0), "max_gap_s": (0.0, 10.0),
             "variance_target": (1e-9, 1.0), "nu": (0.0, 1e6)}
    for key, (lo, hi) in ints.items():
        v = config.get(key, lo)
        if not _is_int(v) or not lo <= v <= hi:
            raise ModelFileError(path, f"training setting {key!r} is {v!r:.40}, not a whole number "
                                       f"from {lo} to {hi}")
    for key, (lo, hi) in reals.items():
        v = config.get(key, lo)
        if not _is_num(v) or not lo <= v <= hi:
            raise ModelFileError(path, f"training setting {key!r} is {v!r:.40}, not a number "
                                       f"from {lo:g} to {hi:g}")
    for key, lo in (("n_components", 1), ("index_cells", 1)):
        v = config.get(key)
        if v is not None and (not _is_int(v) or v < lo):
            raise ModelFileError(path, f"training setting {key!r} is {v!r:.40}, not a whole number "
                                       f"of at least {lo} (or null)")
    choices = {"placement": ("centres", "edges"), "distance_scale": ("max", "median", "none")}
    for key, allowed in choices.items():
        v = config.get(key, allowed[0])
        if v not in allowed:
            raise ModelFileError(path, f"training setting {key!r} is {v!r:.40}, not one of "
                                       f"{', '.join(allowed)}")


# --------------------------------------------------------------------------- the arrays
def check_arrays(path: Path, meta: dict, a: dict[str, np.ndarray]) -> None:
    """Every array's kind, shape against the metadata and the other arrays, and finite values."""
    required = ("fixed", "reference", "pca_mean", "pca_components", "pca_variances", "cb_contexts",
                "cb_lsf", "cb_pcs", "cb_token_utt", "cb_token_start", "cb_token_end", "means",
                "distances", "coord_std")
    missing = [k for k in required if k not in a]
    if missing:
        raise ModelFileError(path, f"model file is incomplete: missing {', '.join(missing)}")
    index_keys = ("ix_centroids", "ix_order", "ix_offsets")
    present = [k for k in index_keys if k in a]
    if present and len(present) != len(index_keys):
        raise ModelFileError(path, "its LSF index does not match its codebook (damaged file?)")
    m = len(meta["marker_names"])
    n_phones = len(meta["phones"])
    cfg = meta["config"]
    p_order = cfg.get("lpc_order", 18)
    ctx = 2 * cfg.get("context", 3) + 1
    n_per = meta["n_per_phone"]
    k = a["pca_components"].shape[0] if a["pca_components"].ndim == 2 else -1
    n_ctx = a["cb_contexts"].shape[0] if a["cb_contexts"].ndim == 2 else -1
    n_fixed = a["fixed"].shape[0] if a["fixed"].ndim == 1 else -1
    n_cells = a["ix_centroids"].shape[0] if "ix_centroids" in a and a["ix_centroids"].ndim == 2 else -1
    n_utt = len(meta.get("train_utterances", []))
    # name: (kind "f" float / "i" integer, expected shape with -1 for "any")
    expect = {
        "fixed": ("i", (n_fixed,)), "reference": ("f", (n_fixed, 3)),
        "pca_mean": ("f", (3 * m,)), "pca_components": ("f", (k, 3 * m)),
        "pca_variances": ("f", (k,)),
        "cb_contexts": ("i", (n_ctx, ctx)), "cb_lsf": ("f", (n_ctx * n_per, p_order)),
        "cb_pcs": ("f", (n_ctx * n_per, k)), "cb_token_utt": ("i", (n_ctx,)),
        "cb_token_start": ("f", (n_ctx,)), "cb_token_end": ("f", (n_ctx,)),
        "means": ("f", (n_phones, k)), "distances": ("f", (n_phones, n_phones)),
        "coord_std": ("f", (3 * m,)),
        "ix_centroids": ("f", (n_cells, p_order)), "ix_order": ("i", (n_ctx * n_per,)),
        "ix_offsets": ("i", (n_cells + 1,)),
        "cb_lsf_context": ("f", (n_ctx * n_per, 2, p_order)),
        "closure_direction": ("f", (k,)), "rest_pcs": ("f", (k,)),
    }
    if ("closure_closed" in meta) != ("closure_direction" in a) or \
            ("closure_direction" in a) != ("rest_pcs" in a):
        raise ModelFileError(path, "its closure statistics are incomplete (damaged file?)")
    for name, (kind, shape) in expect.items():
        if name not in a:
            continue
        arr = a[name]
        kinds = "iu" if kind == "i" else "fiu"
        if arr.dtype.kind not in kinds:
            raise ModelFileError(path, f"array {name!r} has data type {arr.dtype}, not "
                                       f"{'integers' if kind == 'i' else 'numbers'}")
        if name.startswith("ix_") and (arr.dtype.kind not in kinds or arr.shape != shape):
            raise ModelFileError(path, "its LSF index does not match its codebook (damaged file?)")
        if arr.shape != shape or min(shape) < 0:
            raise ModelFileError(path, f"array {name!r} has shape {arr.shape}, {_shape(shape)} "
                                       f"expected from the rest of the model")
        if kind == "f" and not np.all(np.isfinite(arr)):
            raise ModelFileError(path, f"array {name!r} holds NaN or infinite values")
    if k < 1 or n_ctx < 1 or n_fixed < 2:
        raise ModelFileError(path, f"the model is empty ({k} PCs, {n_ctx} context-phones, "
                                   f"{n_fixed} fixed markers)")
    ranges = {"fixed": m, "cb_contexts": n_phones, "cb_token_utt": n_utt or np.iinfo(np.int64).max,
              }
    for name, hi in ranges.items():
        if name in a and a[name].size and (a[name].min() < 0 or a[name].max() >= hi):
            raise ModelFileError(path, f"array {name!r} holds indices outside 0..{hi - 1}")
    if np.any(a["pca_variances"] < 0) or np.any(a["coord_std"] < 0):
        raise ModelFileError(path, "negative variances or deviations in the model")


def _shape(shape: tuple[int, ...]) -> str:
    return "(" + ", ".join("?" if d < 0 else str(d) for d in shape) + (",)" if len(shape) == 1
                                                                         else ")")


def is_compressed(path: str | os.PathLike[str]) -> bool:
    """Whether a model archive has deflated members (as facetraj wrote them before storing
    them uncompressed); False for an unreadable file."""
    try:
        with zipfile.ZipFile(path) as zf:
            return any(info.compress_type != zipfile.ZIP_STORED for info in zf.infolist())
    except (OSError, zipfile.BadZipFile):
        return False


def read_model_file(path: str | os.PathLike[str], newest: int, fmt: str
                    ) -> tuple[dict, dict[str, np.ndarray]]:
    """The checked metadata and arrays of a model file (see the module's description)."""
    path = Path(path)
    if not path.exists():
        raise ModelFileError(path, "no such model file")
    if path.is_dir():
        raise ModelFileError(path, "is a folder, not a model file")
    if not zipfile.is_zipfile(path):
        raise ModelFileError(path, "not a facetraj model (not an .npz archive, or truncated)")
    meta, arrays = read_members(path)
    check_meta(path, meta, newest, fmt)
    check_config(path, meta["config"])
    check_arrays(path, meta, arrays)
    return meta, arrays
