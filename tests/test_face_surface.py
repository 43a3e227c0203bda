"""The 3-D view's face surface (app/view3d.face_triangles): one piece over every marker of the
default face, open at the mouth, no triangle folded across the outline, none for 2-D data."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from facetraj_app.surface import face_triangles, lip_contours, unroll


def _pieces(tri: np.ndarray) -> int:
    """Number of edge-connected pieces of a triangle set."""
    parent = list(range(len(tri)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    owner: dict[tuple[int, int], int] = {}
    for k, t in enumerate(tri.tolist()):
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            e = (min(a, b), max(a, b))
            if e in owner:
                parent[root(k)] = root(owner[e])
            else:
                owner[e] = k
    return len({root(k) for k in range(len(tri))})


@pytest.fixture(scope="module")
def face(default_model):
    m = default_model
    neutral = m.neutral_face()
    contours = lip_contours(neutral, m.upper_lip, m.lower_lip, list(m.lip_corners))
    return m, neutral, contours, face_triangles(neutral, contours)


def test_surface_is_one_piece_over_every_marker(face):
    m, _neutral, _contours, tri = face
    assert set(np.unique(tri).tolist()) == set(range(m.n_markers))
    assert _pieces(tri) == 1
    # a closed 2-D triangulation of the unrolled face: Euler V - E + F = 1 - holes; the only hole
    # is the mouth
    edges = {tuple(sorted(e)) for t in tri.tolist() for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert m.n_markers - len(edges) + len(tri) == 0


def test_mouth_stays_open(face):
    _m, _neutral, contours, tri = face
    up, lo = set(contours[0]), set(contours[1])
    for t in tri.tolist():
        s = set(t)
        assert not (s <= up | lo and s & (up - lo) and s & (lo - up)), t


def test_no_triangle_folds_or_bridges_the_outline(face):
    m, neutral, contours, tri = face
    uv = unroll(neutral)
    a, b, c = uv[tri[:, 0]], uv[tri[:, 1]], uv[tri[:, 2]]
    assert (0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])).min() > 0
    # outline edges (used by one triangle, not the mouth's) are ordinary edges, not bridges
    count: dict[tuple[int, int], int] = {}
    for t in tri.tolist():
        for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            key = (min(e), max(e))
            count[key] = count.get(key, 0) + 1
    length = {e: float(np.linalg.norm(neutral[e[0]] - neutral[e[1]])) for e in count}
    median = float(np.median(list(length.values())))
    lips = set(contours[0]) | set(contours[1])
    outline = [length[e] for e, k in count.items() if k == 1 and not set(e) <= lips]
    assert max(outline) < 3.5 * median
    # unrolling keeps the jaw line beside the cheeks: the lowest jaw-line markers are the
    # outermost on each side, as they are around the head
    names = m.marker_names
    right, left = names.index("JL4_R"), names.index("JL4_L")
    assert uv[right, 0] == uv[:, 0].min() and uv[left, 0] == uv[:, 0].max()


def test_notch_in_the_outline_is_peeled():
    """A U-shaped marker layout: Delaunay fills the notch up to the convex hull; the surface
    does not."""
    xy = [(x, y) for x in range(7) for y in range(7) if not (2 <= x <= 4 and y >= 3)]
    pts = np.array([(x * 10.0, y * 10.0, 0.0) for x, y in xy])
    tri = face_triangles(pts, [])
    centres = pts[tri].mean(axis=1)
    inside_notch = (centres[:, 0] > 15) & (centres[:, 0] < 45) & (centres[:, 1] > 25)
    assert len(tri) > 30 and not inside_notch.any()
    assert set(np.unique(tri).tolist()) == set(range(len(pts)))


def test_no_surface_for_midsagittal_data():
    flat = np.column_stack([np.zeros(6), np.arange(6.0), np.arange(6.0) ** 2])   # x constant
    assert face_triangles(flat, [[0, 1], [2, 3]]).shape == (0, 3)


def test_the_triangulation_is_stored_and_read_back(tmp_path, monkeypatch, default_model):
    """stored_face_triangles: made once and kept in the cache folder; read back without
    triangulating; a damaged or foreign file is made again, a folder that cannot be written
    only costs the triangulation."""
    from facetraj_app import surface

    monkeypatch.setenv("FACETRAJ_CACHE_DIR", str(tmp_path / "cache"))
    neutral = default_model.neutral_face()
    contours = lip_contours(neutral, default_model.upper_lip, default_model.lower_lip,
                            list(default_model.lip_corners))
    made = surface.stored_face_triangles(neutral, contours)
    np.testing.assert_array_equal(made, face_triangles(neutral, contours))
    [stored] = (tmp_path / "cache" / "surfaces").glob("*.npy")

    def no_triangulation(*_a, **_k):
        raise AssertionError("triangulated again")

    monkeypatch.setattr(surface, "face_triangles", no_triangulation)
    np.testing.assert_array_equal(surface.stored_face_triangles(neutral, contours), made)
    monkeypatch.undo()
    monkeypatch.setenv("FACETRAJ_CACHE_DIR", str(tmp_path / "cache"))
    for damage in (b"not a numpy file", None):
        if damage is None:
            np.save(stored, np.full((4, 3), len(neutral) + 5))       # indices beyond the face
        else:
            stored.write_bytes(damage)
        np.testing.assert_array_equal(surface.stored_face_triangles(neutral, contours), made)
        np.testing.assert_array_equal(np.load(stored), made)           # and stored right again
    (tmp_path / "blocked").write_text("a file where the cache folder should be")
    monkeypatch.setenv("FACETRAJ_CACHE_DIR", str(tmp_path / "blocked"))
    np.testing.assert_array_equal(surface.stored_face_triangles(neutral, contours), made)


# ---------------------------------------------------------------------- the mouth (issue 29)
@pytest.fixture(scope="module")
def boy(default_model, default_corpus):
    """The original markers of s002 ("The boy enjoyed the noisy toy.") and its /b/ and /oy/."""
    utt = default_corpus.utterance("s002")
    markers = default_model.normalise_markers(utt.markers)
    b = next(p for p in utt.phones if p.label == "b")
    oy = next(p for p in utt.phones if p.label == "oy")
    frame = lambda seg: int(round((seg.start + seg.end) / 2 * default_model.marker_rate))  # noqa: E731
    return markers, frame(b), frame(oy)


def test_the_mouth_closes_when_the_lips_meet(face, boy):
    """At the /b/ of "boy" the lips' inner edges meet (the surface had a hole there: the markers
    sit on the outside of the lips, 11 mm apart at closure); at /oy/ they are apart by the
    aperture beyond the closed distance."""
    from facetraj_app.surface import Mouth
    from facetraj_engine.analysis.lips import closed_lips

    m, neutral, contours, tri = face
    closed = closed_lips(m)
    assert closed.how == "bilabials" and closed.tokens > 50
    assert 8.0 < float(closed.gap(m.upper_lip, m.lower_lip)) < 14.0        # about a lip's thickness
    mouth = Mouth.between(neutral, contours, closed.markers)
    markers, b, oy = boy
    nu = len(mouth.upper)

    def opening(k: int) -> np.ndarray:
        """Each upper inner point's distance to its partner's inner point."""
        inner = mouth.points(markers[k])
        lower_of = {int(o): i for i, o in enumerate(mouth.lower)}
        return np.array([np.linalg.norm(inner[i] - inner[nu + lower_of[int(p)]])
                         for i, p in enumerate(mouth.partner_of_upper)])

    assert opening(b).max() < 1e-6                                         # shut
    centre = list(mouth.upper).index(m.upper_lip)
    gap = np.linalg.norm(markers[oy, m.upper_lip] - markers[oy, m.lower_lip])
    assert opening(oy)[centre] == pytest.approx(gap - float(closed.gap(m.upper_lip, m.lower_lip)),
                                                abs=1e-6)
    assert opening(oy)[centre] > 2.0                                       # open
    # the lips' strips close the surface's mouth: with them no edge is left open between the
    # contours (every contour edge of the lips is shared by two triangles)
    strips = mouth.triangles(len(neutral))
    full = np.vstack([tri, strips])
    edges: dict[tuple[int, int], int] = {}
    for t in full.tolist():
        for a, c in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            edges[(min(a, c), max(a, c))] = edges.get((min(a, c), max(a, c)), 0) + 1
    for lip in contours:
        for a, c in pairwise(lip):
            assert edges.get((min(a, c), max(a, c))) == 2, (a, c)
