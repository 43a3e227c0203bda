"""C3D (Vicon, Optotrak, Qualisys, and facetraj's own outputs), read with ezc3d.

Units in m or cm are converted to mm; points flagged unseen (a negative residual) become NaN. The
axes are taken as facetraj's (x right, y up, z forward): a C3D file does not say which is which.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError
from ..c3d_check import MAX_RATE, MIN_RATE, check_c3d
from .recording import MarkerRecording
from .registry import MarkerFormat

_UNIT_TO_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0}


def read_c3d(path: str | Path) -> MarkerRecording:
    """Read 3-D points from a C3D file, converted to mm."""
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
    if not MIN_RATE <= rate <= MAX_RATE:  # NaN fails too
        raise InputError(path, f"the C3D frame rate {rate:g} Hz is outside {MIN_RATE:g}-"
                               f"{MAX_RATE:g} Hz")
    residuals = np.asarray(c3d["data"]["meta_points"]["residuals"])[0]  # (M, T)
    markers = np.transpose(pts, (2, 1, 0)) * scale
    markers[residuals.T < 0] = np.nan
    return MarkerRecording(markers, rate, names)


FORMATS = (MarkerFormat("C3D", (".c3d",), read_c3d, order=10),)
