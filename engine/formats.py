"""Reading and writing the file formats facetraj uses: audio, phone labels, markers.

Every reader raises :class:`~engine.errors.InputError` naming the file and the problem; every
writer goes through :func:`atomic_write`, so an interrupted write never leaves a half-written file
where the user's file was.
"""

from __future__ import annotations

import contextlib
import errno
import io
import logging
import os
import signal
import stat
import tempfile
import threading
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .c3d_check import MAX_RATE as MAX_C3D_RATE
from .c3d_check import MIN_RATE as MIN_C3D_RATE
from .c3d_check import check_c3d
from .data import PhoneSegment
from .errors import InputError, OutputError, OutputExistsError

log = logging.getLogger(__name__)

MIN_SAMPLE_RATE = 8000
AUDIO_SUFFIXES = (".wav", ".flac")
LABEL_SUFFIXES = (".textgrid", ".lab", ".phn")
_NAME_MAX = 255  # bytes in one file name on the usual file systems


# --------------------------------------------------------------------------- writing safely
#: What an OS error while writing means, in words (instead of the raw errno text).
_WRITE_PROBLEMS = {
    errno.EACCES: "permission denied", errno.EPERM: "permission denied",
    errno.EROFS: "the file system is read-only", errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "the disk quota is exceeded", errno.ENAMETOOLONG: "the name is too long",
    errno.EISDIR: "it is a folder", errno.ENOTDIR: "a folder in the path is a file",
    errno.ENOENT: "the folder does not exist", errno.EFBIG: "the file would be too large",
}


def write_problem(exc: OSError) -> str:
    """The reason an output cannot be written, in words."""
    return _WRITE_PROBLEMS.get(exc.errno, exc.strerror or type(exc).__name__)


def check_output_path(path: str | os.PathLike[str], overwrite: bool = True) -> Path:
    """Refuse an output path that cannot be written, before any work is done: an existing file
    without ``overwrite`` (:class:`~engine.errors.OutputExistsError`), a folder at the path, a
    parent that is a regular file, a name too long, a folder we may not write in.
    Raises :class:`InputError` naming the path; returns it as a :class:`Path`."""
    path = Path(path)
    if len(os.fsencode(path.name)) > _NAME_MAX:
        raise OutputError(path, f"the file name is too long ({len(os.fsencode(path.name))} bytes; "
                               f"at most {_NAME_MAX})")
    if path.is_dir():
        raise OutputError(path, "a folder is at this path; give a file name")
    if path.exists() and not overwrite:
        raise OutputExistsError(path, "already exists; choose to overwrite it (--overwrite) or "
                                      "give another name")
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if folder.exists() and not folder.is_dir():
        raise OutputError(path, f"cannot be written: {folder} is a file, not a folder")
    if folder.is_dir() and not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(path, f"cannot be written: no permission to write in {folder}")
    return path


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


class _TermToExit:
    """While a write is under way in the main thread, SIGTERM raises ``SystemExit(143)`` (as
    SIGINT raises KeyboardInterrupt), so the temporary file is removed; the previous handler is
    restored afterwards."""

    def __enter__(self):
        self.previous = None
        if threading.current_thread() is threading.main_thread():
            try:
                self.previous = signal.signal(signal.SIGTERM, self._raise)
            except ValueError:  # not the main interpreter
                self.previous = None
        return self

    @staticmethod
    def _raise(signum, frame):
        raise SystemExit(128 + signum)

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGTERM, self.previous)
        return False


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], overwrite: bool = True) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it into place only if the block succeeds.

    The file gets the mode of the file it replaces, or the user's umask for a new one. The
    temporary file is removed when the block fails, on Ctrl-C and on SIGTERM. Raises
    :class:`~engine.errors.OutputExistsError` when ``path`` exists and ``overwrite`` is false, and
    :class:`InputError` naming ``path`` when it cannot be written (see :func:`check_output_path`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "x.txt"
    >>> with atomic_write(out) as tmp:
    ...     _ = tmp.write_text("done")
    >>> out.read_text()
    'done'
    """
    path = check_output_path(path, overwrite)
    try:
        mode = stat.S_IMODE(path.stat().st_mode) if path.exists() else 0o666 & ~_umask()
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem[:40]}.part-", suffix=path.suffix[:20],
                                   dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise OutputError(path, f"cannot be written ({write_problem(exc)})") from exc
    tmp_path = Path(tmp)
    try:
        with _TermToExit():
            try:
                yield tmp_path
                os.chmod(tmp_path, mode)
                os.replace(tmp_path, path)
            except OSError as exc:
                if isinstance(exc, InputError):
                    raise
                raise OutputError(path, f"cannot be written ({write_problem(exc)})") from exc
    finally:
        with contextlib.suppress(OSError):
            if tmp_path.exists():
                tmp_path.unlink()


# --------------------------------------------------------------------------- audio
def read_audio(path: str | os.PathLike[str]) -> tuple[np.ndarray, int]:
    """Read a WAV or FLAC file as mono float64 samples and its rate.

    Stereo and multi-channel files are mixed down (a note is logged). Raises
    :class:`InputError` for a missing, unreadable, empty file or a rate below 8 kHz.
    """
    import soundfile as sf

    path = Path(path)
    if not path.exists():
        raise InputError(path, "no such audio file")
    if path.stat().st_size == 0:
        raise InputError(path, "the audio file is empty (0 bytes)")
    try:
        data, rate = sf.read(str(path), dtype="float64", always_2d=True)
    except Exception as exc:  # soundfile raises several types for corrupt data
        raise InputError(path, f"cannot read audio ({exc})") from exc
    if data.shape[0] == 0:
        raise InputError(path, "the audio file holds no samples")
    if rate < MIN_SAMPLE_RATE:
        raise InputError(path, f"sample rate {rate} Hz is below the {MIN_SAMPLE_RATE} Hz minimum")
    if data.shape[1] > 1:
        log.warning("%s: %d channels mixed down to mono", path, data.shape[1])
    samples = data.mean(axis=1)
    if not np.all(np.isfinite(samples)):
        raise InputError(path, "the audio holds NaN or infinite samples")
    return samples, int(rate)


def write_audio(path: str | os.PathLike[str], samples: np.ndarray, rate: int,
                overwrite: bool = True) -> None:
    """Write mono samples as WAV (16-bit) or FLAC (16-bit), chosen by the suffix."""
    import soundfile as sf

    path = Path(path)
    fmt = "FLAC" if path.suffix.lower() == ".flac" else "WAV"
    with atomic_write(path, overwrite) as tmp:
        sf.write(str(tmp), np.clip(samples, -1.0, 1.0), int(rate), subtype="PCM_16", format=fmt)


def write_json(path: str | os.PathLike[str], data: object, overwrite: bool = True) -> Path:
    """Write ``data`` as indented JSON (UTF-8, a final newline) through :func:`atomic_write`.

    >>> import tempfile, pathlib
    >>> out = write_json(pathlib.Path(tempfile.mkdtemp()) / "r.json", {"r": 0.87})
    >>> out.read_text().splitlines()
    ['{', ' "r": 0.87', '}']
    """
    import json

    path = Path(path)
    with atomic_write(path, overwrite) as tmp:
        tmp.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return path


def read_json(path: str | os.PathLike[str]) -> object | None:
    """The JSON value in the file at ``path`` (what :func:`write_json` wrote), or ``None`` when
    there is no such file.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> read_json(write_json(folder / "r.json", {"r": 0.87})), read_json(folder / "none.json")
    ({'r': 0.87}, None)
    """
    import json

    path = Path(path)
    if not path.is_file():
        return None
    return json.loads(path.read_text(encoding="utf-8"))


# --------------------------------------------------------------------------- labels
def _read_text(path: Path) -> str:
    if not path.exists():
        raise InputError(path, "no such label file")
    if path.is_dir():
        raise InputError(path, "is a folder, not a file")
    raw = path.read_bytes()
    try:
        if raw.startswith((b"\xff\xfe", b"\xfe\xff")):  # UTF-16 (Praat writes it) only with a BOM
            return raw.decode("utf-16")
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(path, "the file is not UTF-8 (or UTF-16) text") from None


def read_textgrid_tiers(path: str | os.PathLike[str]) -> dict[str, list[PhoneSegment]]:
    """Read every interval tier of a Praat TextGrid (long or short text form)."""
    from praatio import textgrid

    path = Path(path)
    _check_interval_order(path, _read_text(path))  # our own messages, before praatio's
    try:
        tg = textgrid.openTextgrid(str(path), includeEmptyIntervals=True)
    except Exception as exc:
        raise InputError(path, f"not a readable TextGrid ({exc})") from exc
    tiers: dict[str, list[PhoneSegment]] = {}
    for name in tg.tierNames:
        tier = tg.getTier(name)
        if tier.tierType != textgrid.INTERVAL_TIER:
            continue
        tiers[name] = [PhoneSegment(float(s), float(e), str(lab).strip())
                       for s, e, lab in tier.entries]
    return tiers


def _check_interval_order(path: Path, text: str) -> None:
    """Refuse interval tiers whose intervals are out of order, overlap or are not numbers (praatio
    would sort them silently, or fail with its own text)."""
    from praatio.utilities import textgrid_io

    try:
        parsed = textgrid_io.parseTextgridStr(text, includeEmptyIntervals=True)
    except Exception as exc:  # praatio raises several types for malformed text
        raise InputError(path, f"not a readable TextGrid ({exc})") from exc
    for tier in parsed.get("tiers", []):
        if tier.get("class") != "IntervalTier":
            continue
        prev_end = -np.inf
        for i, (start, end, label) in enumerate(tier["entries"]):
            try:
                start, end = float(start), float(end)
            except ValueError:
                raise InputError(path, f"tier {tier['name']!r}: interval {i + 1} has a time that "
                                       f"is not a number ({start} {end})") from None
            if not (np.isfinite(start) and np.isfinite(end)):
                raise InputError(path, f"tier {tier['name']!r}: interval {i + 1} has a time that "
                                       f"is not a finite number ({start} {end})")
            if start < prev_end - 1e-6:
                raise InputError(path, f"tier {tier['name']!r}: interval {i + 1} ({label!r}) at "
                                       f"{start:.3f} s overlaps or precedes the one before, "
                                       f"ending {prev_end:.3f} s")
            prev_end = max(prev_end, end)


def read_textgrid(path: str | os.PathLike[str], tier: str = "phones") -> list[PhoneSegment]:
    """Read one interval tier of a TextGrid; empty intervals become ``sil``."""
    tiers = read_textgrid_tiers(path)
    if tier not in tiers:
        raise InputError(path, f"no interval tier named {tier!r} (tiers: {sorted(tiers)})")
    return [PhoneSegment(s.start, s.end, s.label or "sil") for s in tiers[tier]]


def write_textgrid(path: str | os.PathLike[str], tiers: dict[str, Sequence[PhoneSegment]],
                   duration: float, overwrite: bool = True) -> None:
    """Write interval tiers (name -> segments) as a long-form TextGrid."""
    from praatio import textgrid

    tg = textgrid.Textgrid()
    duration = round(float(duration), 6)
    for name, segs in tiers.items():
        entries = [(round(s.start, 6), round(s.end, 6), s.label) for s in segs]
        if entries and abs(entries[-1][1] - duration) < 1e-3:  # no rounding sliver at the end
            entries[-1] = (entries[-1][0], duration, entries[-1][2])
        tg.addTier(textgrid.IntervalTier(name, entries, 0.0, duration))
    with atomic_write(path, overwrite) as tmp:
        tg.save(str(tmp), format="long_textgrid", includeBlankSpaces=True)


def _parse_columns(path: Path) -> list[list[str]]:
    rows = []
    for lineno, line in enumerate(_read_text(path).splitlines(), 1):
        parts = line.split()
        if not parts or parts[0].startswith(("#", "!")) or parts[0] in {".", "MillisecondsPerFrame:"}:
            continue
        if len(parts) < 3:
            raise InputError(path, f"line {lineno}: expected 'start end label', got {line!r}")
        rows.append(parts)
    return rows


def read_lab(path: str | os.PathLike[str]) -> list[PhoneSegment]:
    """Read an HTK label file (times in 100 ns units) or a MOCHA ``.lab`` (times in seconds).

    The unit is told apart by the magnitude: integers above 10^4 are HTK units.
    """
    path = Path(path)
    rows = _parse_columns(path)
    try:
        times = np.array([[float(r[0]), float(r[1])] for r in rows])
    except ValueError as exc:
        raise InputError(path, f"a start or end time is not a number ({exc})") from exc
    if times.size and not np.all(np.isfinite(times)):
        row = int(np.flatnonzero(~np.isfinite(times).all(axis=1))[0])
        raise InputError(path, f"segment {row + 1} has a time that is not a finite number "
                               f"({rows[row][0]} {rows[row][1]})")
    scale = 1e-7 if times.size and times.max() > 1e4 else 1.0
    return [PhoneSegment(a * scale, b * scale, r[2]) for (a, b), r in zip(times, rows, strict=True)]


def read_phn(path: str | os.PathLike[str], sample_rate: int = 16000) -> list[PhoneSegment]:
    """Read a TIMIT ``.phn`` file (sample indices at ``sample_rate``); ``h#``/``pau`` -> ``sil``."""
    path = Path(path)
    segs = []
    for r in _parse_columns(path):
        try:
            a, b = int(r[0]), int(r[1])
        except ValueError as exc:
            raise InputError(path, f"sample index is not an integer ({exc})") from exc
        lab = "sil" if r[2] in {"h#", "pau", "epi"} else r[2]
        segs.append(PhoneSegment(a / sample_rate, b / sample_rate, lab))
    return segs


def read_labels(path: str | os.PathLike[str], sample_rate: int = 16000,
                tier: str = "phones") -> list[PhoneSegment]:
    """Read phone labels from a TextGrid, an HTK/MOCHA ``.lab`` or a TIMIT ``.phn``."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".textgrid":
        segs = read_textgrid(path, tier)
    elif suffix == ".lab":
        segs = read_lab(path)
    elif suffix == ".phn":
        segs = read_phn(path, sample_rate)
    else:
        raise InputError(path, f"unknown label format {suffix!r} (use .TextGrid, .lab or .phn)")
    if not segs:
        raise InputError(path, "the label file holds no segments")
    return segs


def validate_phones(phones: Sequence[PhoneSegment], duration: float,
                    path: str | os.PathLike[str] | None = None,
                    tolerance: float = 0.05) -> list[PhoneSegment]:
    """Check labels are sorted, do not overlap and cover ``[0, duration]``; return them tidied.

    Gaps between segments are filled with ``sil``; slivers shorter than 1 ms (rounding left-overs)
    are absorbed by the segment before; the first segment is extended to 0 and the last to
    ``duration`` when they fall short by at most ``tolerance`` seconds.
    """
    if not phones:
        raise InputError(path, "the label file holds no segments")
    out: list[PhoneSegment] = []
    for i, seg in enumerate(phones):
        if out and 0 <= seg.end - seg.start < 1e-3 and seg.start >= out[-1].end - 1e-6:
            out[-1] = PhoneSegment(out[-1].start, seg.end, out[-1].label)
            continue
        if not seg.end > seg.start:
            raise InputError(path, f"segment {i + 1} ({seg.label!r}) ends at {seg.end:.3f} s, "
                                   f"not after its start {seg.start:.3f} s")
        if out and seg.start < out[-1].end - 1e-6:
            raise InputError(path, f"segment {i + 1} ({seg.label!r}) at {seg.start:.3f} s overlaps "
                                   f"or precedes the one before, ending {out[-1].end:.3f} s")
        if out and seg.start > out[-1].end + 1e-6:
            out.append(PhoneSegment(out[-1].end, seg.start, "sil"))
        out.append(seg)
    if out[0].start > tolerance:
        raise InputError(path, f"labels start at {out[0].start:.3f} s, not at 0")
    if abs(out[-1].end - duration) > max(tolerance, 0.02 * duration):
        raise InputError(path, f"labels end at {out[-1].end:.3f} s but the audio lasts "
                               f"{duration:.3f} s")
    out[0] = PhoneSegment(0.0, out[0].end, out[0].label)
    out[-1] = PhoneSegment(out[-1].start, max(duration, out[-1].start + 1e-3), out[-1].label)
    return out


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
    used when every coordinate fits in +-327 mm, else the float form. Read back with
    :func:`read_c3d` (ezc3d), which reads both.
    """
    import warnings

    import c3d

    markers = np.asarray(markers, dtype=np.float64)
    if markers.ndim != 3 or markers.shape[2] != 3 or markers.shape[1] != len(names):
        raise ValueError(f"markers must be (frames, {len(names)}, 3), got {markers.shape}")
    finite = np.isfinite(markers).all(axis=2)
    span = np.abs(markers[finite]).max() if finite.any() else 0.0
    if integer is None:
        integer = span < 32000 * C3D_INT_SCALE
    scale = C3D_INT_SCALE if integer else -1.0
    if integer:  # c3d truncates toward zero: put values on the grid, nudged away from zero
        q = np.round(markers / C3D_INT_SCALE) * C3D_INT_SCALE
        markers = q + np.copysign(C3D_INT_SCALE * 1e-3, q)
    writer = c3d.Writer(point_rate=float(rate), analog_rate=0.0, point_scale=scale,
                        point_units="mm  ")
    frames = []
    empty = np.zeros((0, 0))
    for t in range(markers.shape[0]):
        p = np.zeros((markers.shape[1], 5))
        p[:, :3] = np.where(finite[t, :, None], markers[t], 0.0)
        p[:, 3] = np.where(finite[t], 0.0, -1.0)
        frames.append((p, empty))
    writer.add_frames(frames)
    writer.set_point_labels(list(names))
    with atomic_write(path, overwrite) as tmp, open(tmp, "wb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        writer.write(handle)


def write_marker_tsv(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
                     names: Sequence[str], overwrite: bool = True) -> None:
    """Write trajectories as a table: a ``time`` column then ``<name>_x <name>_y <name>_z``;
    tab separated, or comma separated for a ``.csv`` path."""
    t = np.arange(markers.shape[0]) / rate
    header = ["time"] + [f"{n}_{a}" for n in names for a in "xyz"]
    table = np.column_stack([t, markers.reshape(markers.shape[0], -1)])
    sep = "," if Path(path).suffix.lower() == ".csv" else "\t"
    with atomic_write(path, overwrite) as tmp:
        np.savetxt(tmp, table, delimiter=sep, header=sep.join(header), comments="",
                   fmt=["%.6f"] + ["%.4f"] * (table.shape[1] - 1))


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


def read_marker_table(path: str | os.PathLike[str], rate: float | None = None) -> MarkerData:
    """Read TSV/CSV trajectories with a header ``[time] name_x name_y name_z ...`` (mm).

    Two-dimensional data (``name_x name_y`` only) gets z = 0. Without a time column, ``rate`` is
    required.
    """
    path = Path(path)
    text = _read_text(path)
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if len(lines) < 2:
        raise InputError(path, "the marker table has no data rows")
    delim = "\t" if "\t" in lines[0] else ","
    header = [h.strip() for h in lines[0].split(delim)]
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
        log.info("%s: markers resampled from %g Hz to %g Hz", path, data.rate, rate)
        data = MarkerData(resample_markers(data.markers, data.rate, rate), float(rate), data.names)
    return data
