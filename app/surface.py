"""The geometry of the 3-D view's face: the lip contour polylines and the face surface's triangles
over the markers, computed once per model and kept in the cache folder (``stored_face_triangles``)
so that a start with a cached model needs no triangulation (and no ``scipy.spatial``).
"""

from __future__ import annotations

import hashlib
import json
import logging

import numpy as np

from engine.errors import InputError
from engine.io.cachedir import cache_dir
from engine.io.files import atomic_write

log = logging.getLogger(__name__)

#: changes when face_triangles changes what it returns: stored triangulations are then remade
SURFACE_VERSION = 1


def lip_contours(neutral: np.ndarray, upper: int, lower: int, corners: list[int]) -> list[list[int]]:
    """Upper and lower lip contour polylines (marker indices, corner to corner), found from the
    neutral face: the markers between the corners that lie close to each lip centre's height."""
    if len(corners) != 2:
        return [[upper, lower]]
    xs = neutral[corners, 0]
    x_lo, x_hi = float(xs.min()), float(xs.max())
    y_c = float(neutral[corners, 1].mean())
    lines = []
    for centre, sign in ((upper, 1.0), (lower, -1.0)):
        height = abs(float(neutral[centre, 1]) - y_c) + 1e-6
        picked = []
        for i, (x, y, _z) in enumerate(neutral):
            if i in corners or not x_lo + 1.0 < x < x_hi - 1.0:
                continue
            if 0.15 * height <= (y - y_c) * sign <= 1.5 * height:
                picked.append(i)
        if centre not in picked:
            picked.append(centre)
        left, right = sorted(corners, key=lambda i: neutral[i, 0])
        lines.append([left, *sorted(picked, key=lambda i: neutral[i, 0]), right])
    return lines


def unroll(points: np.ndarray) -> np.ndarray:
    """The face unrolled onto a plane, ``(M, 2)``: arc length around a vertical axis behind the
    face (x centred, z = front - 0.6 x width; z points forward) and height y. Markers that turn
    away from the viewer (jaw line, temples) stay beside the cheeks instead of folding onto them."""
    xc = float(np.median(points[:, 0]))
    zc = float(points[:, 2].max()) - 0.6 * float(np.ptp(points[:, 0]))
    dx, dz = points[:, 0] - xc, points[:, 2] - zc
    radius = float(np.median(np.hypot(dx, dz)))
    return np.column_stack([radius * np.arctan2(dx, dz), points[:, 1]])


def face_triangles(neutral: np.ndarray, contours: list[list[int]], alpha: float = 2.5) -> np.ndarray:
    """Triangles ``(n, 3)`` of a face surface over the markers.

    2-D Delaunay triangulation of the neutral face unrolled around a vertical axis
    (:func:`unroll`), without the mouth opening (triangles joining upper- and lower-lip contour
    markers only), and peeled from the outline: a triangle whose side on the outline is longer
    than ``alpha`` times the marker spacing at both its ends (each end's nearest-neighbour
    distance) bridges a notch of the outline and is removed, repeatedly (as an alpha shape
    does). Midsagittal (2-D) data, or markers not spanning the x-y plane, have no surface: no
    triangles.
    """
    if len(neutral) < 4 or np.ptp(neutral[:, 0]) == 0 or np.ptp(neutral[:, 1]) == 0:
        return np.zeros((0, 3), dtype=int)
    from scipy.spatial import Delaunay  # here: scipy.spatial takes about 0.45 s to import

    uv = unroll(neutral)
    delaunay = Delaunay(uv)
    tri, neighbours = delaunay.simplices, delaunay.neighbors
    a, b, c = uv[tri[:, 0]], uv[tri[:, 1]], uv[tri[:, 2]]
    sides = np.stack([np.linalg.norm(b - c, axis=1), np.linalg.norm(c - a, axis=1),
                      np.linalg.norm(a - b, axis=1)], axis=1)
    area = 0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    keep = area > 1e-9 * float(np.ptp(uv[:, 0]) * np.ptp(uv[:, 1]))         # no degenerate slivers
    if len(contours) == 2:
        up, lo = set(contours[0]), set(contours[1])
        lips = up | lo
        keep &= ~np.array([set(t) <= lips and bool(set(t) & (up - lo)) and bool(set(t) & (lo - up))
                           for t in tri.tolist()])
    # the local marker spacing: each marker's distance to its nearest Delaunay neighbour
    spacing = np.full(len(uv), np.inf)
    for k in range(3):                                      # side k is opposite vertex k
        for v in ((k + 1) % 3, (k + 2) % 3):
            np.minimum.at(spacing, tri[:, v], sides[:, k])
    ends = np.stack([np.maximum(spacing[tri[:, (k + 1) % 3]], spacing[tri[:, (k + 2) % 3]])
                     for k in range(3)], axis=1)
    too_long = sides > alpha * ends
    while True:
        outside = np.append(~keep, True)[neighbours]           # neighbour -1: the hull
        peel = keep & (outside & too_long).any(axis=1)
        if not peel.any():
            return tri[keep]
        keep &= ~peel


def stored_face_triangles(neutral: np.ndarray, contours: list[list[int]],
                          alpha: float = 2.5) -> np.ndarray:
    """:func:`face_triangles`, read from the cache folder when this face was triangulated before
    (keyed by the neutral face, the contours, ``alpha`` and :data:`SURFACE_VERSION`). A stored
    file that is unreadable or does not fit this face is made again; a cache folder that cannot
    be written only costs the triangulation at the next start."""
    neutral = np.ascontiguousarray(neutral, dtype=np.float64)
    key = hashlib.sha256(neutral.tobytes() + json.dumps([contours, alpha, SURFACE_VERSION,
                                                          list(neutral.shape)]).encode()).hexdigest()
    path = cache_dir() / "surfaces" / f"{key[:32]}.npy"
    try:
        tri = np.load(path, allow_pickle=False)
        if (tri.ndim == 2 and tri.shape[1] == 3 and tri.dtype.kind in "iu"
                and (tri.size == 0 or (tri.min() >= 0 and tri.max() < len(neutral)))):
            return tri.astype(np.int64)
        log.info("stored face surface %s does not fit this face: made again", path)
    except FileNotFoundError:
        pass
    except (OSError, ValueError, EOFError) as exc:
        log.info("stored face surface %s unreadable (%s): made again", path, exc)
    tri = face_triangles(neutral, contours, alpha).astype(np.int64)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(path) as tmp:
            with open(tmp, "wb") as fh:
                np.save(fh, tri, allow_pickle=False)
    except (OSError, InputError) as exc:
        log.info("face surface not stored (%s)", exc)
    return tri
