"""The Wisconsin X-ray microbeam database's pellet files (``.txy``).

Whitespace-separated text, one row per sample: the time in milliseconds, then x and y of the 8
pellets UL LL T1 T2 T3 T4 MNI MNM in micrometres, in the database's head frame (origin at the
maxillary incisors, x along the maxillary occlusal plane, forward; y up): head-corrected, 2-D.
``1000000`` is a pellet not tracked (missing). Read as midsagittal markers in mm (x = 0, y up,
z forward).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError
from .common import mark_missing, numbers, rate_of_times, text_rows
from .recording import MarkerRecording, midsagittal
from .registry import MarkerFormat

PELLETS = ("UL", "LL", "T1", "T2", "T3", "T4", "MNI", "MNM")
#: The value of a coordinate not tracked.
MISSING = 1_000_000.0
UM_PER_MM = 1000.0


def read_txy(path: Path) -> MarkerRecording:
    """Read an XRMB ``.txy`` file (see the module's description)."""
    table = numbers(path, text_rows(path, "XRMB .txy file"))
    if table.shape[1] != 1 + 2 * len(PELLETS):
        raise InputError(path, f"expected {1 + 2 * len(PELLETS)} columns (time in ms, then x and y "
                               f"of {' '.join(PELLETS)}), found {table.shape[1]}")
    if len(table) < 2:
        raise InputError(path, "the XRMB file holds a single row: no rate")
    rate = rate_of_times(path, table[:, 0], unit=0.001)
    xy = table[:, 1:].reshape(len(table), len(PELLETS), 2)
    bad = (xy == MISSING).any(axis=2) | ~np.isfinite(xy).all(axis=2)
    markers = midsagittal(xy[..., 0] / UM_PER_MM, xy[..., 1] / UM_PER_MM)
    rec = MarkerRecording(markers, rate, list(PELLETS), head_corrected=True)
    rec.missing = mark_missing(path, markers, bad, f"pellets not tracked ({MISSING:.0f})")
    return rec


FORMATS = (MarkerFormat("XRMB pellets", (".txy",), read_txy, order=60),)
