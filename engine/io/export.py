"""Writing trajectories: synthesized or original face points as C3D, TSV/CSV or NPZ."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import InputError
from .files import atomic_write, write_npz
from .markerfiles import write_c3d, write_marker_tsv
from .numtext import fixed_point_lines


def write_labelled_table(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
                         names: Sequence[str], labels: Mapping[str, Sequence[str]],
                         overwrite: bool = True) -> Path:
    """The trajectory table of :func:`~facetraj_engine.io.markerfiles.write_marker_tsv` with a
    text column per entry of ``labels`` after the coordinates (e.g. ``phone`` and ``word``: the
    label at each frame, :func:`facetraj_engine.analysis.apertures.frame_labels`); tab separated,
    or comma separated for ``.csv`` (a label holding the separator has it replaced by a space).
    :func:`~facetraj_engine.io.markerfiles.read_marker_table` reads it back, label columns left
    out."""
    path = Path(path)
    n = markers.shape[0]
    for key, column in labels.items():
        if len(column) != n:
            raise ValueError(f"{key}: {len(column)} labels for {n} frames")
    sep = "," if path.suffix.lower() == ".csv" else "\t"
    t = np.arange(n) / rate
    header = ["time"] + [f"{m}_{a}" for m in names for a in "xyz"] + list(labels)
    table = np.column_stack([t, markers.reshape(n, -1)])
    rows = fixed_point_lines(table, [6] + [4] * (table.shape[1] - 1), sep).decode().splitlines()
    columns = [[str(v).replace(sep, " ").replace("\n", " ") for v in col] for col in labels.values()]
    text = "\n".join([sep.join(header)] + [sep.join([row, *(c[i] for c in columns)])
                                           for i, row in enumerate(rows)]) + "\n"
    with atomic_write(path, overwrite) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def write_trajectories(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
                       names: Sequence[str], arrays: Mapping[str, np.ndarray] | None = None,
                       overwrite: bool = True, which: str = "synthesized",
                       compress: bool = False,
                       labels: Mapping[str, Sequence[str]] | None = None) -> Path:
    """Write ``(T, M, 3)`` trajectories (``rate`` frames per second, marker ``names``, head frame)
    as C3D, TSV/CSV or NPZ (by the suffix). The NPZ also holds ``arrays`` (for a synthesis, its
    :meth:`~facetraj_engine.method.pipeline.Synthesis.arrays`: times, smoothed and raw PCs, gamma, input LSF
    and settings), and says ``which`` trajectories it holds (synthesized or original). A TSV/CSV
    carries ``labels`` (``{"phone": [...], "word": [...]}``, one per frame) as text columns after
    the coordinates (:func:`write_labelled_table`).

    The NPZ is stored uncompressed unless ``compress``: the coordinates are 64-bit floats whose
    low bits do not compress, so deflate saves little and takes longer than the synthesis
    (docs/benchmarks.md)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        write_c3d(path, markers, rate, list(names), overwrite)
    elif suffix in (".tsv", ".txt", ".csv") and labels:
        write_labelled_table(path, markers, rate, list(names), labels, overwrite)
    elif suffix in (".tsv", ".txt", ".csv"):
        write_marker_tsv(path, markers, rate, list(names), overwrite)
    elif suffix == ".npz":
        out = {"markers": markers, "marker_names": np.array(list(names)), "which": np.array(which)}
        out.update(arrays or {})
        with atomic_write(path, overwrite) as tmp, open(tmp, "wb") as handle:
            if compress:
                np.savez_compressed(handle, **out)
            else:
                write_npz(handle, out)
    else:
        raise InputError(path, "unknown format (use .c3d, .tsv, .csv or .npz)")
    return path
