"""Marker files: reading any format of the registry (:mod:`.markerformats`), resampled to a
rate on request, and writing C3D and TSV/CSV trajectories."""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import InputError, warn_file
from .c3d_layout import MAX_POINTS as MAX_C3D_POINTS
from .c3d_layout import C3dExtras, c3d_bytes
from .files import atomic_write, write_bytes
from .markerformats import MarkerRecording, apply_names, marker_suffixes, read_recording
from .markerformats.c3d import read_c3d
from .markerformats.common import resample_markers
from .markerformats.mocha import MOCHA_COILS, MOCHA_RATE
from .markerformats.table import read_marker_table
from .numtext import fixed_point_blocks

log = logging.getLogger(__name__)

#: Marker trajectories read from a file (the name older code uses).
MarkerData = MarkerRecording

__all__ = ["C3D_INT_SCALE", "MOCHA_COILS", "MOCHA_RATE", "MarkerData",
           "MarkerRecording", "read_c3d", "read_marker_table", "read_markers", "read_mocha_ema",
           "resample_markers", "write_c3d", "write_marker_tsv"]


C3D_INT_SCALE = 0.01  # mm per integer step in integer C3D files


def write_c3d(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
              names: Sequence[str], overwrite: bool = True, integer: bool | None = None,
              extras: C3dExtras | None = None) -> None:
    """Write ``(frames, markers, 3)`` mm trajectories as C3D; NaN points are written as unseen.

    By default the compact integer form (int16, 0.01 mm steps, half the size of the float form) is
    used when every coordinate fits in +-327 mm, else the float form. The bytes are those the
    ``c3d`` package writes (:mod:`.c3d_layout`), and with ``extras`` the screen axes and an analog
    channel beside (:class:`~.c3d_layout.C3dExtras`). Read back with :func:`read_c3d` (ezc3d),
    which reads both.
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
    data = c3d_bytes(raw, float(rate), scale, list(names), extras=extras)
    with atomic_write(path, overwrite) as tmp:
        write_bytes(tmp, data)


def write_marker_tsv(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
                     names: Sequence[str], overwrite: bool = True,
                     labels: Mapping[str, Sequence[str]] | None = None) -> None:
    """Write trajectories as a table: a ``time`` column then ``<name>_x <name>_y <name>_z``, then
    a text column per entry of ``labels`` (e.g. ``phone`` and ``word``: the label at each frame,
    :func:`facetraj_engine.analysis.apertures.frame_labels`; a label holding the separator has it
    replaced by a space); tab separated, or comma separated for a ``.csv`` path.
    :func:`~facetraj_engine.io.markerformats.table.read_marker_table` reads it back, label columns
    left out."""
    n = markers.shape[0]
    labels = labels or {}
    for key, column in labels.items():
        if len(column) != n:
            raise ValueError(f"{key}: {len(column)} labels for {n} frames")
    header = ["time"] + [f"{m}_{a}" for m in names for a in "xyz"] + list(labels)
    sep = "," if Path(path).suffix.lower() == ".csv" else "\t"
    ends = None                                # each line's labels after its numbers
    if labels:
        columns = [_label_text(col, sep) for col in labels.values()]
        ends = [(sep + sep.join(cells) + "\n").encode() for cells in zip(*columns, strict=True)]
    text = fixed_point_blocks([((np.arange(n) / rate)[:, None], 6),       # what savetxt wrote
                               (np.asarray(markers, dtype=np.float64).reshape(n, -1), 4)], sep, ends)
    with atomic_write(path, overwrite) as tmp:
        write_bytes(tmp, (sep.join(header) + "\n").encode(), text)


def _label_text(column: Sequence[str], sep: str) -> list[str]:
    """A label column as text, the separator and newlines in a label replaced by spaces (each
    distinct label once)."""
    text = {v: str(v).replace(sep, " ").replace("\n", " ") for v in set(column)}
    return [text[v] for v in column]


def __getattr__(name: str):
    if name == "MARKER_SUFFIXES":      # from the registry, which finds its formats on first use
        return marker_suffixes()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def read_mocha_ema(path: str | os.PathLike[str]) -> MarkerRecording:
    """Read MOCHA-TIMIT EMA (MOCHAtools' 22-column text, or an EST track): the registry's reader
    for the file's content."""
    return read_recording(path)


def read_markers(path: str | os.PathLike[str], rate: float | None = None,
                 channel_names: Sequence[str] | None = None) -> MarkerRecording:
    """Read a marker file of any registered format (:mod:`.markerformats`), its channels renamed
    by ``channel_names`` (:mod:`.markerformats.channels`), resampled to ``rate`` if given."""
    path = Path(path)
    data = apply_names(read_recording(path, rate), channel_names, path)
    if rate is not None and abs(data.rate - rate) > 1e-6:
        warn_file(log, path, "markers resampled to the corpus rate",
                  f"markers resampled from {data.rate:g} Hz to {rate:g} Hz", logging.INFO)
        data = data.with_markers(resample_markers(data.markers, data.rate, rate), rate)
    return data
