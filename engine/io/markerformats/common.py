"""What the readers share: bounded file reading, rates from times, missing samples, resampling."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from ...errors import InputError, warn_file
from ..c3d_check import MAX_RATE, MIN_RATE
from ..files import read_text

log = logging.getLogger(__name__)

#: The largest binary marker file read (a 24-channel AG501 at 1250 Hz for 25 minutes is 1 GiB).
MAX_BINARY_BYTES = 2 << 30


def read_binary(path: Path, what: str) -> bytes:
    """The bytes of a binary marker file; ``what`` names its kind in the errors."""
    if not path.exists():
        raise InputError(path, f"no such {what}")
    if path.is_dir():
        raise InputError(path, f"is a folder, not a {what}")
    size = path.stat().st_size
    if size > MAX_BINARY_BYTES:
        raise InputError(path, f"is {size} bytes, more than facetraj reads as a {what} (at most "
                               f"{MAX_BINARY_BYTES >> 20} MiB)")
    data = path.read_bytes()
    if not data:
        raise InputError(path, f"the {what} is empty")
    return data


def text_rows(path: Path, what: str, sep: str | None = None) -> list[list[str]]:
    """The non-empty lines of a text file split into fields (whitespace unless ``sep``)."""
    text = read_text(path, what)
    rows = [ln.split(sep) if sep else ln.split() for ln in text.splitlines() if ln.strip()]
    if not rows:
        raise InputError(path, f"the {what} is empty")
    return rows


def numbers(path: Path, rows: list[list[str]], first_line: int = 1) -> np.ndarray:
    """Rows of numbers as a 2-D array; every row must have the first row's count. Empty fields
    are NaN."""
    width = len(rows[0])
    out = np.empty((len(rows), width))
    for i, row in enumerate(rows):
        if len(row) != width:
            raise InputError(path, f"line {i + first_line} has {len(row)} values, the first "
                                   f"{width} (truncated or damaged?)")
        try:
            out[i] = [float(v) if v.strip() else np.nan for v in row]
        except ValueError:
            bad = next(v for v in row if v.strip() and not _is_number(v))
            raise InputError(path, f"line {i + first_line}: {bad.strip()[:20]!r} is not a "
                                   f"number") from None
    return out


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def check_rate(path: Path, rate: float, where: str = "") -> float:
    """``rate`` if it is within the marker rates facetraj reads, else an :class:`InputError`."""
    if not MIN_RATE <= rate <= MAX_RATE:  # NaN fails too
        raise InputError(path, f"the marker rate {rate:g} Hz{where} is outside {MIN_RATE:g}-"
                               f"{MAX_RATE:g} Hz")
    return float(rate)


def rate_of_times(path: Path, times: np.ndarray, unit: float = 1.0) -> float:
    """The frame rate of a time column in ``unit`` seconds: (frames - 1) / span, rounded to a whole
    number when within 0.1 %; refused unless the times increase and the rate is sane."""
    times = np.asarray(times, dtype=np.float64) * unit
    steps = np.diff(times)
    if len(steps) and not (steps > 0).all() and np.isfinite(times).all():
        raise InputError(path, f"its times do not increase (frame {int(np.argmax(~(steps > 0))) + 2}: "
                               f"{times[np.argmax(~(steps > 0)) + 1]:g} s after "
                               f"{times[np.argmax(~(steps > 0))]:g} s)")
    span = float(times[-1] - times[0]) if len(times) > 1 else np.nan
    rate = (len(times) - 1) / span if np.isfinite(span) and span > 0 else np.nan
    if not MIN_RATE <= rate <= MAX_RATE:
        raise InputError(path, f"its times ({times[0]:g} to {times[-1]:g} s over {len(times)} "
                               f"frames) give no marker rate within {MIN_RATE:g}-{MAX_RATE:g} Hz")
    return whole(rate)


def whole(rate: float) -> float:
    """``rate`` rounded to a whole number of Hz when within 0.1 % of one (times in files are
    rounded).

    >>> whole(99.99999999999999), whole(145.7286)
    (100.0, 145.7286)
    """
    return float(round(rate)) if abs(rate - round(rate)) < 1e-3 * rate else float(rate)


def mark_missing(path: Path, markers: np.ndarray, missing: np.ndarray, why: str) -> int:
    """Set the samples ``missing`` ``(frames, markers)`` to NaN; log their count once per file."""
    count = int(np.count_nonzero(missing))
    if count:
        markers[missing] = np.nan
        warn_file(log, path, "marker samples marked missing",
                  f"{count} of {missing.size} marker samples marked missing ({why}); gaps up to "
                  f"100 ms are bridged, longer ones left out", logging.INFO)
    return count


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
