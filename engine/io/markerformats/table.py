"""Marker tables: TSV or CSV with a header ``[time] name_x name_y name_z ...`` (mm).

Tab separated (comma when the header has no tab); ``time`` (or ``t``, ``time_s``) first is
optional: without it the caller gives the rate. Empty or ``nan`` cells are missing samples. Two
columns per marker (``name_x name_y``) are 2-D data with z = 0, in facetraj's axes as written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError
from ..files import read_text
from .common import rate_of_times
from .recording import MarkerRecording
from .registry import MarkerFormat

#: text columns of a trajectory table that hold labels, not coordinates (left out when read:
#: facetraj's labelled tables, :func:`facetraj_engine.io.markerfiles.write_marker_tsv`)
LABEL_COLUMNS = frozenset({"phone", "word"})


def _table(path: Path) -> tuple[list[str], np.ndarray]:
    lines = [ln for ln in read_text(path, "marker file").splitlines() if ln.strip()]
    if len(lines) < 2:
        raise InputError(path, "the marker table has no data rows")
    delim = "\t" if "\t" in lines[0] else ","
    header = [h.strip() for h in lines[0].split(delim)]
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
    if table.ndim != 2:
        raise InputError(path, "rows have different numbers of columns (truncated or damaged?)")
    if table.shape[1] != len(header):
        raise InputError(path, f"rows have {table.shape[1]} columns but the header {len(header)}")
    return header, table


def read_marker_table(path: str | Path, rate: float | None = None) -> MarkerRecording:
    """Read TSV/CSV trajectories (label columns, :data:`LABEL_COLUMNS`, left out); without a
    time column, ``rate`` is required."""
    path = Path(path)
    header, table = _table(path)
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
        rate = rate_of_times(path, times)
    if rate is None:
        raise InputError(path, "no time column: give the marker rate")
    return MarkerRecording(markers, float(rate), names)


FORMATS = (MarkerFormat("TSV/CSV marker table", (".tsv", ".csv"), read_marker_table, takes_rate=True,
                        order=20),)
