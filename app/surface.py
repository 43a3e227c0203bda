"""The geometry of the 3-D view's face: the lip contour polylines, the face surface's triangles
over the markers, computed once per model and kept in the cache folder (``stored_face_triangles``)
so that a start with a cached model needs no triangulation (and no ``scipy.spatial``), and the
lips between their markers and the mouth opening (:class:`Mouth`), which close when the lips meet.
"""

from __future__ import annotations

import hashlib
import json
import logging
from dataclasses import dataclass

import numpy as np

from facetraj_engine.errors import InputError
from facetraj_engine.io.cachedir import cache_dir
from facetraj_engine.io.files import atomic_write

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


def mouth_region(neutral: np.ndarray, contours: list[list[int]],
                 margin: tuple[float, float] = (0.15, 0.3)) -> np.ndarray:
    """The markers around the lips (indices): within the lip contours' box on the neutral face
    widened by ``margin`` (across, up and down) of the mouth's width (the close-up of the lips
    shows their patch of the face alone: the lips, the skin above and below them to the nose's
    base; no cheeks, no chin).

    >>> face = np.array([[-20, 0, 0], [20, 0, 0], [0, 5, 0], [0, -5, 0], [0, 40, 0], [0, -9, 0],
    ...                  [27, 0, 0]], float)
    >>> mouth_region(face, [[0, 2, 1], [0, 3, 1]]).tolist()
    [0, 1, 2, 3, 5]
    """
    lips = sorted({i for c in contours for i in c})
    box = neutral[lips, :2]
    pad = np.asarray(margin, float) * float(np.ptp(box[:, 0]))
    lo, hi = box.min(axis=0) - pad, box.max(axis=0) + pad
    inside = ((neutral[:, :2] >= lo) & (neutral[:, :2] <= hi)).all(axis=1)
    return np.flatnonzero(inside)


@dataclass(frozen=True)
class Mouth:
    """The lips' surface from their markers to the mouth opening, which closes when they meet.

    The lip markers sit on the outside of the lips: with the lips together, an upper and a lower
    marker are still a lip's thickness apart (about 11 mm at the centre). Each lip marker gets an
    *inner edge* point on the way to its partner on the other lip (the nearest in x), as far
    from it as half their distance at closure (``facetraj_engine.analysis.lips.closed_lips``), so that the
    two inner edges meet, and the mouth is shut, when the pair is no farther apart than at the
    talker's closures, and open by the rest when they part. The strips between each lip's
    markers and its inner edge are triangles over the markers and these extra points
    (:meth:`points`, after the markers; :meth:`triangles`).

    ``upper``, ``lower``: the lip contour markers between the corners; ``partner_of_upper`` /
    ``partner_of_lower``: each one's partner on the other lip; ``half_closed_upper`` /
    ``half_closed_lower``: half the pair's distance at closure (mm); ``corners``: left, right.
    """

    upper: np.ndarray
    lower: np.ndarray
    partner_of_upper: np.ndarray
    partner_of_lower: np.ndarray
    half_closed_upper: np.ndarray
    half_closed_lower: np.ndarray
    corners: tuple[int, int]

    @classmethod
    def between(cls, neutral: np.ndarray, contours: list[list[int]],
                closed: np.ndarray) -> Mouth | None:
        """The mouth of a face whose lip contours (corner .. corner, upper then lower) are
        ``contours``; ``closed``: ``(M, 3)`` the markers at closure. None without two contours
        with markers between their corners."""
        if len(contours) != 2 or len(contours[0]) < 3 or len(contours[1]) < 3:
            return None
        up, lo = np.array(contours[0][1:-1]), np.array(contours[1][1:-1])
        pu = lo[np.argmin(np.abs(neutral[up, None, 0] - neutral[None, lo, 0]), axis=1)]
        pl = up[np.argmin(np.abs(neutral[lo, None, 0] - neutral[None, up, 0]), axis=1)]
        return cls(up, lo, pu, pl,
                   0.5 * np.linalg.norm(closed[up] - closed[pu], axis=1),
                   0.5 * np.linalg.norm(closed[lo] - closed[pl], axis=1),
                   (int(contours[0][0]), int(contours[0][-1])))

    @property
    def n_points(self) -> int:
        return len(self.upper) + len(self.lower)

    def points(self, markers: np.ndarray) -> np.ndarray:
        """The inner edge points ``(n_points, 3)`` of ``markers`` ``(M, 3)``: the upper lip's,
        then the lower lip's."""
        return np.concatenate([_inner(markers, self.upper, self.partner_of_upper, self.half_closed_upper),
                               _inner(markers, self.lower, self.partner_of_lower, self.half_closed_lower)])

    def shut(self, markers: np.ndarray, tol: float = 0.05) -> bool:
        """Whether every pair of lip markers is no farther apart than at closure (within
        ``tol`` mm): the mouth is shut all along (no opening anywhere to see into)."""
        return all(bool((np.linalg.norm(markers[partner] - markers[own], axis=1) <= 2 * half + tol).all())
                   for own, partner, half in ((self.upper, self.partner_of_upper, self.half_closed_upper),
                                              (self.lower, self.partner_of_lower, self.half_closed_lower)))

    def opening_loop(self, n_markers: int) -> np.ndarray:
        """The mouth opening's outline as vertex ids of the surface (inner points numbered from
        ``n_markers``): left corner, the upper inner edge, right corner, the lower one back."""
        left, right = self.corners
        nu = len(self.upper)
        upper = list(range(n_markers, n_markers + nu))
        lower = list(range(n_markers + nu, n_markers + self.n_points))
        return np.array([left, *upper, right, *lower[::-1]], dtype=np.int64)

    def owners(self) -> np.ndarray:
        """The marker each inner edge point belongs to, ``(n_points,)``."""
        return np.concatenate([self.upper, self.lower])

    def triangles(self, n_markers: int) -> np.ndarray:
        """The lips' strips ``(n, 3)``, inner points numbered from ``n_markers`` on."""
        left, right = self.corners
        tri = []
        first = n_markers
        for lip in (self.upper, self.lower):
            outer = [left, *lip.tolist(), right]
            inner = [left, *range(first, first + len(lip)), right]
            first += len(lip)
            for k in range(len(outer) - 1):
                a, b, c, d = outer[k], outer[k + 1], inner[k + 1], inner[k]
                if a != d:
                    tri.append((a, c, d))
                if b != c:
                    tri.append((a, b, c))
        return np.array(tri, dtype=np.int64)


def _inner(markers: np.ndarray, own: np.ndarray, partner: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Each ``own`` marker moved towards its partner by ``half`` its closed distance, at most to
    the middle of the pair (the lips meet there)."""
    d = markers[partner] - markers[own]
    gap = np.linalg.norm(d, axis=1)
    t = np.minimum(0.5, half / np.maximum(gap, 1e-9))
    return markers[own] + t[:, None] * d
