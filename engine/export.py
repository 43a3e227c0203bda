"""Writing trajectories: synthesized or original face points as C3D, TSV/CSV or NPZ."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from .errors import InputError
from .formats import atomic_write, write_c3d, write_marker_tsv
from .model import Model
from .pipeline import Synthesis


def write_trajectories(path: str | os.PathLike[str], markers: np.ndarray, model: Model,
                       synthesis: Synthesis | None = None, overwrite: bool = True,
                       which: str = "synthesized") -> Path:
    """Write ``(T, M, 3)`` trajectories in the model's head frame as C3D, TSV/CSV or NPZ (by the
    suffix). The NPZ also holds ``synthesis``'s times, smoothed and raw PCs, gamma, input LSF and
    settings, and says ``which`` trajectories it holds (synthesized or original)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        write_c3d(path, markers, model.marker_rate, model.marker_names, overwrite)
    elif suffix in (".tsv", ".txt", ".csv"):
        write_marker_tsv(path, markers, model.marker_rate, model.marker_names, overwrite)
    elif suffix == ".npz":
        arrays = {"markers": markers, "marker_names": np.array(model.marker_names),
                  "which": np.array(which)}
        if synthesis is not None:
            arrays.update(times=synthesis.times, pcs=synthesis.pcs, raw_pcs=synthesis.raw_pcs,
                          gamma=synthesis.frames.gamma, lsf=synthesis.lsf,
                          config=np.array(json.dumps(synthesis.config.to_dict())))
        with atomic_write(path, overwrite) as tmp, open(tmp, "wb") as handle:
            np.savez_compressed(handle, **arrays)
    else:
        raise InputError(path, "unknown format (use .c3d, .tsv, .csv or .npz)")
    return path
