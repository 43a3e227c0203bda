"""Reading a model file safely: the ``.npz`` archive of :meth:`facetraj_engine.method.model.Model.save`,
checked
before anything is trusted.

Every zip member's compression method and size, and every array's ``.npy`` header (dtype, shape)
are checked before any array is allocated; then the metadata's types and ranges (the
cross-validated settings too), and every array's data type (whole or floating-point numbers,
returned as int64 and float64 whatever the file stored), shape (against the metadata and the
other arrays), values (finite; LSFs in (0, pi) and in order, phone tokens ending after they
start, orthonormal PCs, variances not negative, distances a distance matrix) and
cross-references (marker, phone and utterance indices within their lists; the LSF index a
partition of the codebook). Any problem is a :class:`~facetraj_engine.errors.ModelFileError` naming the
file, before anything uses the model.
"""

from __future__ import annotations

import io
import json
import math
import os
import struct
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..data import LABEL_KINDS
from ..errors import ModelFileError
from ..labels.phoneset import SILENCE
from .c3d_check import MAX_RATE, MIN_RATE
from .sensor_roles import overrides_problem

#: Largest single array a model file may hold (a codebook of about 10^7 codewords).
MAX_ARRAY_BYTES = 1 << 30
#: Largest metadata entry (phone and utterance lists).
MAX_META_BYTES = 64 << 20
_COMPRESSIONS = (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED)


def read_members(path: Path) -> tuple[dict, dict[str, np.ndarray]]:
    """The metadata dict and the arrays of a model archive, each header checked first; a stored
    member read once, straight into the buffer its array keeps (checksum checked), a deflated one
    (older files) through ``zipfile``."""
    try:
        with zipfile.ZipFile(path) as zf, open(path, "rb") as raw:
            arrays: dict[str, np.ndarray] = {}
            for info in zf.infolist():
                name = info.filename.removesuffix(".npy")
                if info.compress_type not in _COMPRESSIONS:
                    raise ModelFileError(path, f"entry {name!r} uses an unsupported compression "
                                               f"method ({info.compress_type})")
                limit = MAX_META_BYTES if name == "meta" else MAX_ARRAY_BYTES
                if info.file_size > limit + 4096:
                    raise ModelFileError(path, f"entry {name!r} is {info.file_size} bytes, more than "
                                               f"a model holds (at most {limit})")
                data = (_stored(path, name, raw, info) if info.compress_type == zipfile.ZIP_STORED
                        else bytearray(zf.read(info)))
                arrays[name] = _npy_array(path, name, data, limit)
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


def _stored(path: Path, name: str, raw, info: zipfile.ZipInfo) -> np.ndarray:
    """The bytes of a stored (uncompressed) member, read from after its local header into an
    uninitialised byte array (a ``bytearray`` is zeroed first: 13 MB took twice as long); its
    CRC-32 checked as ``zipfile`` checks it."""
    raw.seek(info.header_offset)
    head = raw.read(30)
    if len(head) != 30 or head[:4] != b"PK\x03\x04":
        raise ModelFileError(path, f"not a readable facetraj model (entry {name!r} has no local "
                                   f"header where the directory says)")
    name_len, extra_len = struct.unpack("<HH", head[26:30])
    raw.seek(info.header_offset + 30 + name_len + extra_len)
    data = np.empty(info.file_size, dtype=np.uint8)
    if raw.readinto(data) != info.file_size:
        raise ModelFileError(path, f"entry {name!r} is shorter than the archive says (truncated?)")
    if zlib.crc32(data) != info.CRC:
        raise ModelFileError(path, f"not a readable facetraj model (entry {name!r} is damaged: "
                                   f"its CRC-32 does not match)")
    return data


def _npy_array(path: Path, name: str, data: bytearray | np.ndarray, limit: int) -> np.ndarray:
    """One ``.npy`` member's array: header checked (version, dtype, shape, size) before it is
    used; the array a view of ``data`` (no copy) unless stored in Fortran order."""
    fmt = np.lib.format
    handle = io.BytesIO(memoryview(data)[:1 << 16])
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
    start = handle.tell()
    if nbytes > len(data) - start:
        raise ModelFileError(path, f"entry {name!r} is shorter than its header says (truncated?)")
    arr = np.frombuffer(data, dtype=dtype, count=math.prod(shape), offset=start)
    if fortran:
        return arr.reshape(shape[::-1]).T.copy()
    return arr.reshape(shape)


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
    if SILENCE not in meta["phones"]:
        raise bad("phones", f"a phone set with silence ({SILENCE!r})")
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
    _check_tuned(path, meta.get("tuned", {}))
    _check_detector_meta(path, meta.get("closure_detector"), meta["config"].get("lpc_order", 18))
    closed, d0 = meta.get("closure_closed"), meta.get("voice_distance")
    if closed is not None and (not _is_num(closed) or not abs(closed) < 1e6):
        raise bad("closure_closed", "a lip aperture in mm")
    if d0 is not None and (not _is_num(d0) or not 0 < d0 < 1e6):
        raise bad("voice_distance", "a positive number")
    problem = overrides_problem(meta.get("sensor_roles", {}), meta["marker_names"])
    if problem:
        raise ModelFileError(path, f"metadata {problem}")
    kinds = meta.get("trained_labels", {})
    if not isinstance(kinds, dict) or not all(k in LABEL_KINDS and _is_int(n) and n >= 0
                                              for k, n in kinds.items()):
        raise bad("trained_labels", f"an object of utterance counts by label kind "
                                    f"({', '.join(LABEL_KINDS)})")


#: the cross-validated synthesis settings a model may hold, and their ranges (as the options')
TUNED_RANGES = {"n_context_phones": (1, 1000, int), "robust_candidates": (1, 100000, int),
                "xi": (1.0, 1e6, float), "label_weight": (0.0, 1e6, float),
                "context_weight": (0.0, 1e6, float), "gamma_max": (1e-3, 1e3, float),
                "triangle_s": (1e-3, 10.0, float), "chain_beta": (0.0, 1e3, float)}


def _check_tuned(path: Path, tuned) -> None:
    settings = tuned.get("settings", {}) if isinstance(tuned, dict) else None
    if not isinstance(settings, dict) or not all(_is_num(v) for v in settings.values()):
        raise ModelFileError(path, f"metadata 'tuned' is {tuned!r:.60}, not an object of "
                                   f"cross-validated settings (numbers)")
    for key, value in settings.items():
        if key not in TUNED_RANGES:
            continue      # a setting of a newer facetraj: not used here
        lo, hi, kind = TUNED_RANGES[key]
        if not lo <= value <= hi or (kind is int and not _is_int(value)):
            raise ModelFileError(path, f"metadata 'tuned' setting {key!r} is {value!r:.40}, not "
                                       f"{'a whole number' if kind is int else 'a number'} "
                                       f"from {lo:g} to {hi:g}")


#: the bilabial-closure detector's feature settings (``facetraj_engine.method.closure_detector.
#: DetectorSpec``): their kind and range
DETECTOR_SPEC = {"back": (1, 600, int), "floor_db": (-200.0, -1e-3, float),
                 "n_lsf": (1, 64, int), "prior_frames": (0.0, 1e9, float),
                 "min_frames": (1, 600, int)}


def _check_detector_meta(path: Path, det, lpc_order: int) -> None:
    """The closure detector's metadata (``None``: a model without one): its feature settings in
    range, known to this facetraj, and a finite bias."""
    if det is None:
        return

    def bad(what: str) -> ModelFileError:
        return ModelFileError(path, f"metadata 'closure_detector' {what}")

    spec = det.get("spec") if isinstance(det, dict) else None
    biases = [det.get(k) for k in ("bias", "search_bias") if k in det] if spec is not None else []
    if not isinstance(spec, dict) or "bias" not in det or \
            not all(_is_num(b) and math.isfinite(b) for b in biases):
        raise bad(f"is {det!r:.60}, not an object with the detector's settings and bias")
    unknown = set(spec) - set(DETECTOR_SPEC) - {"gate_db", "offsets"}
    if unknown:
        raise bad(f"has settings this facetraj does not know ({', '.join(sorted(unknown))}): "
                  f"written by a newer version?")
    for key, (lo, hi, kind) in DETECTOR_SPEC.items():
        v = spec.get(key)
        if not _is_num(v) or not lo <= v <= hi or (kind is int and not _is_int(v)):
            what = "a whole number" if kind is int else "a number"
            raise bad(f"setting {key!r} is {v!r:.40}, not {what} from {lo:g} to {hi:g}")
    if _is_int(lpc_order) and spec["n_lsf"] > lpc_order:        # (a bad order: check_config's)
        raise bad(f"uses {spec['n_lsf']} LSFs of {lpc_order}")
    gate, offsets = spec.get("gate_db"), spec.get("offsets")
    if not (isinstance(gate, list) and len(gate) == 2 and all(_is_num(g) for g in gate)
            and gate[0] < gate[1] <= 0):
        raise bad(f"setting 'gate_db' is {gate!r:.40}, not two dips in dB, the first lower")
    if not (isinstance(offsets, list) and 0 < len(offsets) <= 121 and
            all(_is_int(o) and abs(o) <= 60 for o in offsets) and len(set(offsets)) == len(offsets)):
        raise bad(f"setting 'offsets' is {offsets!r:.40}, not distinct frame offsets within 60")


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
REQUIRED = ("fixed", "reference", "pca_mean", "pca_components", "pca_variances", "cb_contexts",
            "cb_lsf", "cb_pcs", "cb_token_utt", "cb_token_start", "cb_token_end", "means",
            "distances", "coord_std")
INDEX = ("ix_centroids", "ix_order", "ix_offsets")
DETECTOR = ("cd_lsf_mean", "cd_mean", "cd_scale", "cd_weights")
DETECTOR_SEARCH = ("cs_mean", "cs_scale", "cs_weights")
_DAMAGED_INDEX = "its LSF index does not match its codebook (damaged file?)"
#: the tolerance of the structural checks (orthonormal PCs, symmetric distances)
_TOL = 1e-6


def _expected(meta: dict, a: dict[str, np.ndarray]) -> dict[str, tuple[str, tuple[int, ...]]]:
    """Every array's kind ("f" floating point, "i" whole numbers) and shape, from the metadata
    and the other arrays (-1 where the array sets the size itself)."""
    def rows(name: str, ndim: int) -> int:
        return a[name].shape[0] if name in a and a[name].ndim == ndim else -1

    m, n_phones, cfg = len(meta["marker_names"]), len(meta["phones"]), meta["config"]
    p_order, ctx = cfg.get("lpc_order", 18), 2 * cfg.get("context", 3) + 1
    k, n_ctx, n_fixed = rows("pca_components", 2), rows("cb_contexts", 2), rows("fixed", 1)
    n_cw, n_cells = n_ctx * meta["n_per_phone"], rows("ix_centroids", 2)
    spec = (meta.get("closure_detector") or {}).get("spec", {})
    n_lsf, n_det = spec.get("n_lsf", -1), len(spec.get("offsets", [])) * (1 + spec.get("n_lsf", 0))
    n_search = n_det + 2 * len(spec.get("offsets", []))
    return {
        "fixed": ("i", (n_fixed,)), "reference": ("f", (n_fixed, 3)),
        "pca_mean": ("f", (3 * m,)), "pca_components": ("f", (k, 3 * m)),
        "pca_variances": ("f", (k,)),
        "cb_contexts": ("i", (n_ctx, ctx)), "cb_lsf": ("f", (n_cw, p_order)),
        "cb_pcs": ("f", (n_cw, k)), "cb_token_utt": ("i", (n_ctx,)),
        "cb_token_start": ("f", (n_ctx,)), "cb_token_end": ("f", (n_ctx,)),
        "means": ("f", (n_phones, k)), "distances": ("f", (n_phones, n_phones)),
        "coord_std": ("f", (3 * m,)),
        "ix_centroids": ("f", (n_cells, p_order)), "ix_order": ("i", (n_cw,)),
        "ix_offsets": ("i", (n_cells + 1,)),
        "cb_lsf_context": ("f", (n_cw, 2, p_order)),
        "closure_direction": ("f", (k,)), "rest_pcs": ("f", (k,)),
        "cd_lsf_mean": ("f", (n_lsf,)), "cd_mean": ("f", (n_det,)), "cd_scale": ("f", (n_det,)),
        "cd_weights": ("f", (n_det,)),
        "cs_mean": ("f", (n_search,)), "cs_scale": ("f", (n_search,)),
        "cs_weights": ("f", (n_search,)),
    }


def _checked_array(path: Path, name: str, arr: np.ndarray, kind: str,
                   shape: tuple[int, ...]) -> np.ndarray:
    """One array's data type and shape checked, and the array as float64 or int64 (whatever
    integer or floating-point type and byte order the file stored: the method computes in
    these, and mixing others fails in numpy's in-place operations)."""
    index = name.startswith("ix_")
    if arr.dtype.kind not in ("iu" if kind == "i" else "f"):
        raise ModelFileError(path, _DAMAGED_INDEX if index else
                             f"array {name!r} has data type {arr.dtype}, not "
                             f"{'whole numbers' if kind == 'i' else 'floating-point numbers'}")
    if arr.shape != shape or min(shape, default=0) < 0:
        raise ModelFileError(path, _DAMAGED_INDEX if index else
                             f"array {name!r} has shape {arr.shape}, {_shape(shape)} expected "
                             f"from the rest of the model")
    if kind == "i":
        if arr.dtype.kind == "u" and arr.size and arr.max() > np.iinfo(np.int64).max:
            raise ModelFileError(path, f"array {name!r} holds indices outside 0..2^63")
        return arr.astype(np.int64, copy=False)        # the file's own copy: no second one
    with np.errstate(over="ignore", invalid="ignore"):       # inf - inf: NaN, no warning
        out = arr.astype(np.float64, copy=False)
        finite = np.isfinite(out.sum())    # NaN and inf reach the sum: one pass, nothing made
    if not finite and not np.all(np.isfinite(out)):   # (a sum that overflows: each value)
        raise ModelFileError(path, f"array {name!r} holds NaN or infinite values")
    return out


def _check_indices(path: Path, meta: dict, a: dict[str, np.ndarray]) -> None:
    """Indices within what they index: markers, phones, training utterances."""
    n_utt = len(meta.get("train_utterances", []))
    ranges = {"fixed": len(meta["marker_names"]), "cb_contexts": len(meta["phones"]),
              "cb_token_utt": n_utt or np.iinfo(np.int64).max}
    for name, hi in ranges.items():
        if a[name].size and (a[name].min() < 0 or a[name].max() >= hi):
            raise ModelFileError(path, f"array {name!r} holds indices outside 0..{hi - 1}")
    if np.any(np.diff(np.sort(a["fixed"])) == 0):
        raise ModelFileError(path, "array 'fixed' names a marker twice")


def _check_values(path: Path, meta: dict, a: dict[str, np.ndarray]) -> None:
    """Values in their ranges: LSFs in (0, pi) and in order, phone tokens that end after they
    start, orthonormal PCs, variances and deviations not negative, a matrix of distances."""
    for name in ("cb_lsf", "cb_lsf_context", "ix_centroids"):
        lsf = a.get(name)
        if lsf is not None and lsf.size and (lsf.min() < 0 or lsf.max() > np.pi
                                             or np.any(lsf[..., 1:] < lsf[..., :-1])):
            raise ModelFileError(path, f"array {name!r} holds LSFs outside 0..pi or out of order")
    if np.any(a["cb_token_start"] < 0) or np.any(a["cb_token_end"] < a["cb_token_start"]):
        raise ModelFileError(path, "arrays 'cb_token_start' and 'cb_token_end' hold a phone token "
                                   "that starts before 0 s or ends before it starts")
    c = a["pca_components"]
    if np.abs(c @ c.T - np.eye(len(c))).max() > _TOL:
        raise ModelFileError(path, "array 'pca_components' does not hold orthonormal components")
    if np.any(a["pca_variances"] < 0) or np.any(a["coord_std"] < 0):
        raise ModelFileError(path, "negative variances or deviations in the model")
    if a["pca_variances"].sum() > meta["pca_total_variance"] * (1 + _TOL):
        raise ModelFileError(path, "the PCs' variances add up to more than the total variance "
                                   "(metadata 'pca_total_variance')")
    if "cd_scale" in a and (np.any(a["cd_scale"] <= 0) or np.any(a.get("cs_scale", 1.0) <= 0)
                            or np.any(a["cd_lsf_mean"] >= np.log(np.pi))):
        raise ModelFileError(path, "the closure detector's arrays hold a scale that is not "
                                   "positive or a mean log LSF at or above log(pi)")
    d = a["distances"]
    scale = max(float(np.abs(d).max()), 1.0)
    if np.any(d < 0) or np.abs(d - d.T).max() > _TOL * scale or np.abs(np.diag(d)).max() > _TOL * scale:
        raise ModelFileError(path, "array 'distances' is not a matrix of distances (negative, "
                                   "not symmetric, or not 0 on its diagonal)")


def _check_index(path: Path, a: dict[str, np.ndarray]) -> None:
    """The stored LSF index partitions exactly the codebook: ``ix_order`` a permutation of the
    codewords, ``ix_offsets`` from 0 to their number, never decreasing."""
    present = [k for k in INDEX if k in a]
    if not present:
        return
    if len(present) != len(INDEX):
        raise ModelFileError(path, _DAMAGED_INDEX)
    n, order, offsets = a["cb_lsf"].shape[0], a["ix_order"], a["ix_offsets"]
    if not (n > 0 and offsets[0] == 0 and offsets[-1] == n and np.all(np.diff(offsets) >= 0)
            and len(order) == n and order.min() >= 0 and order.max() < n     # a permutation:
            and np.all(np.bincount(order, minlength=n) == 1)):              # each index once
        raise ModelFileError(path, _DAMAGED_INDEX)


def check_arrays(path: Path, meta: dict, a: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Every array's data type, shape against the metadata and the other arrays, values (finite,
    in range) and cross-references (indices within what they index, the LSF index over the
    codebook); the arrays returned as float64 and int64."""
    missing = [k for k in REQUIRED if k not in a]
    if missing:
        raise ModelFileError(path, f"model file is incomplete: missing {', '.join(missing)}")
    if ("closure_closed" in meta) != ("closure_direction" in a) or \
            ("closure_direction" in a) != ("rest_pcs" in a):
        raise ModelFileError(path, "its closure statistics are incomplete (damaged file?)")
    search = "search_bias" in (meta.get("closure_detector") or {})
    if any((name in a) != ("closure_detector" in meta) for name in DETECTOR) or \
            any((name in a) != search for name in DETECTOR_SEARCH):
        raise ModelFileError(path, "its closure detector is incomplete (damaged file?)")
    out = dict(a)
    for name, (kind, shape) in _expected(meta, a).items():
        if name in a:
            out[name] = _checked_array(path, name, a[name], kind, shape)
    k, n_ctx, n_fixed = len(out["pca_components"]), len(out["cb_contexts"]), len(out["fixed"])
    if k < 1 or n_ctx < 1:
        raise ModelFileError(path, f"the model is empty ({k} PCs, {n_ctx} context-phones)")
    if n_fixed == 1:  # none: trained on head-corrected data
        raise ModelFileError(path, "the model has 1 fixed marker (head motion needs 2 or more)")
    _check_indices(path, meta, out)
    _check_values(path, meta, out)
    _check_index(path, out)
    return out


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
    path = _archive(path)
    meta, arrays = read_members(path)
    check_meta(path, meta, newest, fmt)
    check_config(path, meta["config"])
    return meta, check_arrays(path, meta, arrays)


def _archive(path: str | os.PathLike[str]) -> Path:
    """``path``, refused unless it is a zip archive."""
    path = Path(path)
    if not path.exists():
        raise ModelFileError(path, "no such model file")
    if path.is_dir():
        raise ModelFileError(path, "is a folder, not a model file")
    if not zipfile.is_zipfile(path):
        raise ModelFileError(path, "not a facetraj model (not an .npz archive, or truncated)")
    return path
