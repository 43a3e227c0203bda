"""Writing trajectories: synthesized or original face points as C3D, TSV/CSV or NPZ."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import InputError
from .files import atomic_write
from .markerfiles import write_c3d, write_marker_tsv
from .npz import write_npz


def write_trajectories(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
                       names: Sequence[str], arrays: Mapping[str, np.ndarray] | None = None,
                       overwrite: bool = True, which: str = "synthesized",
                       compress: bool = False) -> Path:
    """Write ``(T, M, 3)`` trajectories (``rate`` frames per second, marker ``names``, head frame)
    as C3D, TSV/CSV or NPZ (by the suffix). The NPZ also holds ``arrays`` (for a synthesis, its
    :meth:`~facetraj_engine.method.pipeline.Synthesis.arrays`: times, smoothed and raw PCs, gamma, input LSF
    and settings), and says ``which`` trajectories it holds (synthesized or original).

    The NPZ is stored uncompressed unless ``compress``: on 60 s of synthesized speech, deflate
    made it 17 % smaller (6.4 -> 5.3 MB; the coordinates are 64-bit floats whose low bits do not
    compress) and took 156 ms against 4 ms, longer than the synthesis (issue 28)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        write_c3d(path, markers, rate, list(names), overwrite)
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
