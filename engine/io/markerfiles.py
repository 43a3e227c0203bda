"""Marker files: C3D, TSV/CSV trajectory tables and MOCHA-TIMIT EMA, resampled on request."""

from __future__ import annotations

import io
import logging
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError, warn_file
from .c3d_check import MAX_RATE as MAX_C3D_RATE
from .c3d_check import MIN_RATE as MIN_C3D_RATE
from .c3d_check import check_c3d
from .c3d_layout import MAX_POINTS as MAX_C3D_POINTS
from .c3d_layout import c3d_bytes
from .files import MAX_TEXT_BYTES, atomic_write, read_text, write_bytes
from .numtext import fixed_point_lines

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- markers
@dataclass
class MarkerData:
    """Marker trajectories read from a file: ``(frames, markers, 3)`` mm, NaN where unseen."""

    markers: np.ndarray
    rate: float
    names: list[str]


_UNIT_TO_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0}


def read_c3d(path: str | os.PathLike[str]) -> MarkerData:
    """Read 3-D points from a C3D file (any of Vicon, Optotrak, Qualisys), converted to mm."""
    import ezc3d

    path = Path(path)
    if not path.exists():
        raise InputError(path, "no such C3D file")
    if path.is_dir():
        raise InputError(path, "is a folder, not a C3D file")
    check_c3d(path)
    try:
        c3d = ezc3d.c3d(str(path))
    except Exception as exc:
        reason = str(exc).split(". ")[0].split("\n")[0]  # not ezc3d's advice to set options
        raise InputError(path, f"not a readable C3D file ({reason})") from exc
    point = c3d["parameters"].get("POINT", {})

    def values(name: str) -> list:
        return list(point.get(name, {}).get("value", []))

    pts = np.asarray(c3d["data"]["points"], dtype=np.float64)[:3]  # (3, M, T)
    if pts.ndim != 3 or pts.shape[1] == 0 or pts.shape[2] == 0:
        raise InputError(path, "the C3D file holds no points")
    names = [str(n).strip() for n in values("LABELS")][: pts.shape[1]]
    if len(names) != pts.shape[1]:
        raise InputError(path, f"the C3D file names {len(names)} of its {pts.shape[1]} points "
                               f"(POINT:LABELS)")
    unit = str((values("UNITS") or ["mm"])[0]).strip().lower() or "mm"
    scale = _UNIT_TO_MM.get(unit)
    if scale is None:
        raise InputError(path, f"unknown point unit {unit!r}")
    rate = float((values("RATE") or [c3d["header"]["points"]["frame_rate"]])[0])
    if not MIN_C3D_RATE <= rate <= MAX_C3D_RATE:  # NaN fails too
        raise InputError(path, f"the C3D frame rate {rate:g} Hz is outside {MIN_C3D_RATE:g}-"
                               f"{MAX_C3D_RATE:g} Hz")
    residuals = np.asarray(c3d["data"]["meta_points"]["residuals"])[0]  # (M, T)
    markers = np.transpose(pts, (2, 1, 0)) * scale
    markers[residuals.T < 0] = np.nan
    return MarkerData(markers, rate, names)


C3D_INT_SCALE = 0.01  # mm per integer step in integer C3D files


def write_c3d(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
              names: Sequence[str], overwrite: bool = True, integer: bool | None = None) -> None:
    """Write ``(frames, markers, 3)`` mm trajectories as C3D; NaN points are written as unseen.

    By default the compact integer form (int16, 0.01 mm steps, half the size of the float form) is
    used when every coordinate fits in +-327 mm, else the float form. The bytes are those the
    ``c3d`` package writes (:mod:`.c3d_layout`). Read back with :func:`read_c3d` (ezc3d), which
    reads both.
    """
    markers = np.asarray(markers, dtype=np.float64)
    if markers.ndim != 3 or markers.shape[2] != 3 or markers.shape[1] != len(names):
        raise ValueError(f"markers must be (frames, {len(names)}, 3), got {markers.shape}")
    if not 1 <= len(names) <= MAX_C3D_POINTS or max(map(len, names), default=0) > MAX_C3D_POINTS:
        raise InputError(path, f"C3D holds 1 to {MAX_C3D_POINTS} points with names of at most "
                               f"{MAX_C3D_POINTS} characters ({len(names)} here): write .tsv or .npz")
    finite = np.isfinite(markers).all(axis=2)
    span = np.abs(markers[finite]).max() if finite.any() else 0.0
    if integer is None:
        integer = span < 32000 * C3D_INT_SCALE
    scale = C3D_INT_SCALE if integer else -1.0
    if integer:  # c3d truncates toward zero: put values on the grid, nudged away from zero
        q = np.round(markers / C3D_INT_SCALE) * C3D_INT_SCALE
        markers = q + np.copysign(C3D_INT_SCALE * 1e-3, q)
    raw = np.zeros((*markers.shape[:2], 4), dtype="<i2" if integer else "<f4")
    with np.errstate(invalid="ignore"):      # every frame at once; to int16: toward zero
        raw[..., :3] = np.where(finite[..., None], markers / (C3D_INT_SCALE if integer else 1.0),
                                0.0)
    raw[..., 3] = np.where(finite, 0, -1)     # residual 0 and no camera bits; -1: unseen
    data = c3d_bytes(raw, float(rate), scale, list(names))
    with atomic_write(path, overwrite) as tmp:
        write_bytes(tmp, data)


def write_marker_tsv(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
                     names: Sequence[str], overwrite: bool = True) -> None:
    """Write trajectories as a table: a ``time`` column then ``<name>_x <name>_y <name>_z``;
    tab separated, or comma separated for a ``.csv`` path."""
    t = np.arange(markers.shape[0]) / rate
    header = ["time"] + [f"{n}_{a}" for n in names for a in "xyz"]
    table = np.column_stack([t, markers.reshape(markers.shape[0], -1)])
    sep = "," if Path(path).suffix.lower() == ".csv" else "\t"
    text = fixed_point_lines(table, [6] + [4] * (table.shape[1] - 1), sep)   # what savetxt wrote
    with atomic_write(path, overwrite) as tmp:
        write_bytes(tmp, (sep.join(header) + "\n").encode() + text)


def _rate_of(path: Path, times: np.ndarray) -> float:
    """The frame rate of a time column: (frames - 1) / span, refused unless the span is finite and
    positive and the rate within the marker rates facetraj reads."""
    span = float(times[-1] - times[0])
    rate = (len(times) - 1) / span if np.isfinite(span) and span > 0 else np.nan
    if not MIN_C3D_RATE <= rate <= MAX_C3D_RATE:  # NaN fails too
        raise InputError(path, f"its times ({times[0]:g} to {times[-1]:g} s over {len(times)} "
                               f"frames) give no marker rate within {MIN_C3D_RATE:g}-"
                               f"{MAX_C3D_RATE:g} Hz")
    return rate


#: text columns of a trajectory table that hold labels, not coordinates (left out when read)
LABEL_COLUMNS = frozenset({"phone", "word"})


def read_marker_table(path: str | os.PathLike[str], rate: float | None = None) -> MarkerData:
    """Read TSV/CSV trajectories with a header ``[time] name_x name_y name_z ...`` (mm); label
    columns (:data:`LABEL_COLUMNS`) are left out.

    Two-dimensional data (``name_x name_y`` only) gets z = 0. Without a time column, ``rate`` is
    required.
    """
    path = Path(path)
    text = read_text(path, "marker file")
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if len(lines) < 2:
        raise InputError(path, "the marker table has no data rows")
    delim = "\t" if "\t" in lines[0] else ","
    header = [h.strip() for h in lines[0].split(delim)]
    # text columns of labels (``phone``, ``word``: facetraj's labelled tables) are left out
    labelled = {i for i, h in enumerate(header) if h.lower() in LABEL_COLUMNS}
    if labelled:
        header = [h for i, h in enumerate(header) if i not in labelled]
        lines = [lines[0]] + [delim.join(v for i, v in enumerate(ln.split(delim)) if i not in labelled)
                              for ln in lines[1:]]
    try:
        table = np.array([[float(v) if v.strip() not in {"", "nan", "NaN"} else np.nan
                           for v in ln.split(delim)] for ln in lines[1:]])
    except ValueError as exc:
        raise InputError(path, f"a value is not a number ({exc})") from exc
    if table.shape[1] != len(header):
        raise InputError(path, f"rows have {table.shape[1]} columns but the header {len(header)}")
    times = None
    if header[0].lower() in {"time", "t", "time_s"}:
        times, header, table = table[:, 0], header[1:], table[:, 1:]
    names: list[str] = []
    for h in header:
        base, _, axis = h.rpartition("_")
        if axis.lower() not in {"x", "y", "z"} or not base:
            raise InputError(path, f"column {h!r} is not of the form <marker>_x|y|z")
        if base not in names:
            names.append(base)
    markers = np.zeros((table.shape[0], len(names), 3))
    for col, h in enumerate(header):
        base, _, axis = h.rpartition("_")
        markers[:, names.index(base), "xyz".index(axis.lower())] = table[:, col]
    if times is not None and len(times) > 1:
        rate = _rate_of(path, times)
        rate = float(round(rate)) if abs(rate - round(rate)) < 1e-3 * rate else float(rate)
    if rate is None:
        raise InputError(path, "no time column: give the marker rate")
    return MarkerData(markers, rate, names)


# --------------------------------------------------------------------------- MOCHA-TIMIT EMA
#: MOCHA-TIMIT coils and their (x, y) columns (1-based) in the ASCII conversion of MOCHAtools.
MOCHA_COILS = {"UI": (3, 8), "LI": (4, 9), "UL": (5, 10), "LL": (6, 11), "TT": (7, 12),
               "TB": (13, 18), "TD": (14, 19), "V": (15, 20), "BN": (17, 22)}
MOCHA_RATE = 500.0


def _midsagittal(x_ap: np.ndarray, y_up: np.ndarray) -> np.ndarray:
    """MOCHA midsagittal (x toward the back, y up; 1/100 mm) to facetraj axes in mm: x = 0 (the
    midsagittal plane), y up, z forward = -x."""
    return np.stack([np.zeros_like(x_ap), y_up / 100.0, -x_ap / 100.0], axis=-1)


def _read_est_track(path: Path, raw: bytes) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Edinburgh Speech Tools track file (ascii or binary): times, channel values, names."""
    end = raw.find(b"EST_Header_End")
    if end < 0:
        raise InputError(path, "EST track file without EST_Header_End")
    header = raw[:end].decode("ascii", errors="replace").splitlines()
    body = raw[raw.index(b"\n", end) + 1:]
    fields: dict[str, str] = {}
    names: dict[int, str] = {}
    for line in header[1:]:
        parts = line.split(None, 1)
        if len(parts) != 2:
            continue
        key, val = parts[0], parts[1].strip()
        if key.startswith("Channel_"):
            names[int(key.split("_")[1])] = val
        fields[key] = val
    try:
        n_frames, n_chan = int(fields["NumFrames"]), int(fields["NumChannels"])
    except (KeyError, ValueError) as exc:
        raise InputError(path, "EST header lacks NumFrames/NumChannels") from exc
    if n_frames < 0 or not 1 <= n_chan <= 10000:
        raise InputError(path, f"EST header gives {n_frames} frames of {n_chan} channels")
    width = 2 + n_chan
    if fields.get("DataType", "ascii") == "binary":
        order = ">" if fields.get("ByteOrder", "10") == "10" else "<"
        data = np.frombuffer(body, dtype=f"{order}f4")
        if data.size < n_frames * width:
            raise InputError(path, f"binary EST data holds {data.size} values, "
                                   f"{n_frames * width} expected (truncated?)")
        data = data[: n_frames * width].reshape(n_frames, width).astype(np.float64)
    else:
        rows = [ln.split() for ln in body.decode("ascii", errors="replace").splitlines() if ln.strip()]
        try:
            data = np.array([[float(v) for v in r[:width]] for r in rows])
        except ValueError as exc:
            raise InputError(path, f"EST data is not numeric ({exc})") from exc
        if data.ndim != 2 or data.shape[1] != width:
            raise InputError(path, f"EST rows have {data.shape[-1]} columns, {width} expected")
    return data[:, 0], data[:, 2:], [names.get(i, f"ch{i}") for i in range(n_chan)]


def read_mocha_ema(path: str | os.PathLike[str]) -> MarkerData:
    """Read MOCHA-TIMIT EMA: the 22-column ASCII form of MOCHAtools or the EST track form.

    Coils become 2-D (midsagittal) markers in mm: x = 0, y up, z forward (MOCHA's x points to
    the back of the mouth). The rate is 500 Hz as recorded.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(path, "no such EMA file")
    if path.is_file() and path.stat().st_size > MAX_TEXT_BYTES:
        raise InputError(path, f"is {path.stat().st_size} bytes, more than facetraj reads as an "
                               f"EMA file (at most {MAX_TEXT_BYTES >> 20} MiB)")
    raw = path.read_bytes()
    if not raw.strip():
        raise InputError(path, "the EMA file is empty")
    names = list(MOCHA_COILS)
    if raw.startswith(b"EST_File"):
        times, chans, chan_names = _read_est_track(path, raw)
        lower = [c.lower() for c in chan_names]
        cols = []
        for coil, (cx, cy) in MOCHA_COILS.items():
            key_x, key_y = f"{coil.lower()}_x", f"{coil.lower()}_y"
            if key_x in lower and key_y in lower:
                cols.append((lower.index(key_x), lower.index(key_y)))
            else:  # unnamed channels: the MOCHAtools column order (channel = column - 3)
                cols.append((cx - 3, cy - 3))
        if max(max(c) for c in cols) >= chans.shape[1]:
            raise InputError(path, f"EST track has {chans.shape[1]} channels; MOCHA EMA needs 20")
    else:
        try:
            table = np.loadtxt(io.StringIO(raw.decode("ascii")), ndmin=2)
        except (ValueError, UnicodeDecodeError) as exc:
            raise InputError(path, f"not a MOCHA EMA text file ({exc})") from exc
        if table.shape[1] != 22:
            raise InputError(path, f"expected 22 columns (time, flag, 20 coil values), "
                                   f"found {table.shape[1]}")
        times, chans = table[:, 0], table[:, 2:]
        cols = [(cx - 3, cy - 3) for cx, cy in MOCHA_COILS.values()]
    markers = np.stack([_midsagittal(chans[:, cx], chans[:, cy]) for cx, cy in cols], axis=1)
    rate = MOCHA_RATE
    if len(times) > 1:
        rate = float(round(_rate_of(path, times)))
    return MarkerData(markers, rate, names)


# --------------------------------------------------------------------------- any marker file
MARKER_SUFFIXES = (".c3d", ".tsv", ".csv", ".ema")


def resample_markers(markers: np.ndarray, rate: float, target: float) -> np.ndarray:
    """Markers at another frame rate: polyphase filtering when complete, else linear
    interpolation in which frames next to a gap stay NaN."""
    if abs(rate - target) < 1e-9:
        return markers
    n_out = int(np.floor((markers.shape[0] - 1) / rate * target + 1e-9)) + 1
    if np.isfinite(markers).all():
        from fractions import Fraction

        frac = Fraction(target / rate).limit_denominator(1000)
        from scipy.signal import resample_poly  # here: scipy.signal takes 1-2 s to import

        out = resample_poly(markers, frac.numerator, frac.denominator, axis=0, padtype="line")
        if out.shape[0] >= n_out:
            return out[:n_out]
    t_in = np.arange(markers.shape[0]) / rate
    t_out = np.arange(n_out) / target
    flat = markers.reshape(markers.shape[0], -1)
    out = np.empty((n_out, flat.shape[1]))
    for c in range(flat.shape[1]):
        ok = np.isfinite(flat[:, c])
        out[:, c] = np.interp(t_out, t_in[ok], flat[ok, c]) if ok.sum() > 1 else np.nan
        bad = np.interp(t_out, t_in, (~ok).astype(float)) > 0
        out[bad, c] = np.nan
    return out.reshape(n_out, *markers.shape[1:])


def read_markers(path: str | os.PathLike[str], rate: float | None = None) -> MarkerData:
    """Read markers from C3D, TSV/CSV or MOCHA EMA (by suffix); resample to ``rate`` if given."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        data = read_c3d(path)
    elif suffix in (".tsv", ".csv", ".txt"):
        data = read_marker_table(path, rate)
    elif suffix == ".ema":
        data = read_mocha_ema(path)
    else:
        raise InputError(path, f"unknown marker format {suffix!r} (use .c3d, .tsv, .csv or .ema)")
    if not MIN_C3D_RATE <= data.rate <= MAX_C3D_RATE:  # NaN fails too
        raise InputError(path, f"the marker rate {data.rate:g} Hz (from the file's times) is "
                               f"outside {MIN_C3D_RATE:g}-{MAX_C3D_RATE:g} Hz")
    if data.markers.shape[0] == 0 or data.markers.shape[1] == 0:
        raise InputError(path, "the marker file holds no frames or no markers")
    if rate is not None and abs(data.rate - rate) > 1e-6:
        warn_file(log, path, "markers resampled to the corpus rate",
                  f"markers resampled from {data.rate:g} Hz to {rate:g} Hz", logging.INFO)
        data = MarkerData(resample_markers(data.markers, data.rate, rate), float(rate), data.names)
    return data
