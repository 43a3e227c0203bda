"""MOCHA-TIMIT EMA as text: the 22-column ASCII conversion of MOCHAtools (``.ema``).

Columns: time (s), a "present" flag, then the 20 coil values of :data:`MOCHA_COILS` (midsagittal
x toward the back of the mouth and y up, in 1/100 mm). Coils become 2-D markers in mm: x = 0, y
up, z forward (= -x). MOCHA's EST-track files are read by :mod:`.est`, with the same conversion.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from ...errors import InputError
from .common import numbers, rate_of_times, text_rows
from .recording import MarkerRecording, midsagittal
from .registry import MarkerFormat

log = logging.getLogger(__name__)

#: MOCHA-TIMIT coils and their (x, y) columns (1-based) in the ASCII conversion of MOCHAtools.
MOCHA_COILS = {"UI": (3, 8), "LI": (4, 9), "UL": (5, 10), "LL": (6, 11), "TT": (7, 12),
               "TB": (13, 18), "TD": (14, 19), "V": (15, 20), "BN": (17, 22)}
MOCHA_RATE = 500.0
#: MOCHA's unit: 1/100 mm.
MOCHA_SCALE = 0.01


def mocha_markers(x_back: np.ndarray, y_up: np.ndarray) -> np.ndarray:
    """MOCHA coil values ``(frames, coils)`` (1/100 mm, x toward the back) as facetraj markers."""
    return midsagittal(-x_back * MOCHA_SCALE, y_up * MOCHA_SCALE)


def mocha_recording(path: Path, times: np.ndarray, x_back: np.ndarray, y_up: np.ndarray,
                    names: list[str]) -> MarkerRecording:
    """A recording of MOCHA coils; the rate from the times (500 Hz for a single frame)."""
    rate = float(round(rate_of_times(path, times))) if len(times) > 1 else MOCHA_RATE
    return MarkerRecording(mocha_markers(x_back, y_up), rate, names)


def read_mocha_text(path: Path) -> MarkerRecording:
    """Read MOCHA-TIMIT EMA in MOCHAtools' 22-column text form."""
    table = numbers(path, text_rows(path, "EMA file"))
    if table.shape[1] != 22:
        raise InputError(path, f"expected 22 columns (time, flag, 20 coil values), found "
                               f"{table.shape[1]}")
    chans = table[:, 2:]
    xs = np.stack([chans[:, cx - 3] for cx, _ in MOCHA_COILS.values()], axis=1)
    ys = np.stack([chans[:, cy - 3] for _, cy in MOCHA_COILS.values()], axis=1)
    return mocha_recording(path, table[:, 0], xs, ys, list(MOCHA_COILS))


FORMATS = (MarkerFormat("MOCHA-TIMIT EMA text", (".ema",), read_mocha_text, order=30),)
