"""Marker gap filling, head-motion removal (Kabsch), PCA, codebook placement, smoothing."""

import numpy as np
import pytest

from facetraj_engine.data import PhoneSegment
from facetraj_engine.errors import InputError
from facetraj_engine.labels.phoneset import map_labels, normalise_label
from facetraj_engine.method.codebook import codeword_times, interpolate_frames
from facetraj_engine.method.context import context_ids
from facetraj_engine.method.markers import fill_gaps, kabsch, reference_pose, remove_head_motion
from facetraj_engine.method.pca import fit_pca
from facetraj_engine.method.smoothing import smooth, spline_smooth, triangular_smooth, triangular_window


def _rotation(rng):
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    return q * np.sign(np.linalg.det(q))


# ---------------------------------------------------------------- gaps
def test_fill_short_gap_and_keep_long_gap():
    rate = 60.0
    m = np.zeros((40, 2, 3))
    m[:, 0, 1] = np.arange(40.0)
    m[:, 1, 1] = np.arange(40.0) * 2
    m[5:8, 0] = np.nan          # 3 frames = 50 ms: filled
    m[10:20, 1] = np.nan        # 10 frames = 167 ms: left NaN, frames invalid
    filled, valid = fill_gaps(m, rate, 0.1)
    np.testing.assert_allclose(filled[5:8, 0, 1], [5, 6, 7])
    assert np.isnan(filled[10:20, 1]).all()
    assert valid.tolist() == [not (10 <= t < 20) for t in range(40)]


def test_gap_exactly_at_limit_is_filled():
    m = np.zeros((20, 1, 3))
    m[:, 0, 0] = np.arange(20.0)
    m[4:10, 0] = np.nan          # 6 frames = 100 ms at 60 Hz
    filled, valid = fill_gaps(m, 60.0, 0.1)
    assert valid.all()
    np.testing.assert_allclose(filled[4:10, 0, 0], np.arange(4, 10))


# ---------------------------------------------------------------- head motion
def test_kabsch_recovers_rigid_motion():
    rng = np.random.default_rng(0)
    pts = rng.standard_normal((6, 3)) * 30
    rot = _rotation(rng)
    moved = pts @ rot.T + np.array([5.0, -3.0, 12.0])
    r, t = kabsch(moved, pts)
    np.testing.assert_allclose(moved @ r.T + t, pts, atol=1e-9)


def test_head_motion_removed_lips_kept():
    rng = np.random.default_rng(1)
    neutral = rng.standard_normal((8, 3)) * 40
    fixed = np.arange(4)
    n_frames = 50
    faces = np.repeat(neutral[None], n_frames, axis=0)
    lip = 3.0 * np.sin(np.arange(n_frames) / 5.0)
    faces[:, 6, 1] += lip                 # a lip moves, non-rigidly
    moved = np.empty_like(faces)
    for t in range(n_frames):
        rot = _rotation(np.random.default_rng(100 + t)) if t % 7 else np.eye(3)
        moved[t] = faces[t] @ rot.T + rng.standard_normal(3) * 10
    out = remove_head_motion(moved, fixed, neutral[fixed])
    np.testing.assert_allclose(out, faces, atol=1e-8)
    ref = reference_pose(moved, fixed)
    # the Procrustes mean is the neutral pose up to one rigid motion
    r, t = kabsch(ref, neutral[fixed])
    np.testing.assert_allclose(ref @ r.T + t, neutral[fixed], atol=1e-8)


def test_frames_without_fixed_markers_become_nan():
    m = np.ones((3, 5, 3)) + np.arange(15).reshape(1, 5, 3)
    m[1, 0] = np.nan
    out = remove_head_motion(m, np.array([0, 1, 2]), m[0, :3])
    assert np.isnan(out[1]).all() and np.isfinite(out[[0, 2]]).all()


# ---------------------------------------------------------------- PCA
def test_pca_exact_reconstruction_with_all_components():
    rng = np.random.default_rng(2)
    x = rng.standard_normal((100, 12)) @ rng.standard_normal((12, 12))
    p = fit_pca(x, n_components=12)
    np.testing.assert_allclose(p.inverse(p.transform(x)), x, atol=1e-9)
    assert p.explained_ratio.sum() == pytest.approx(1.0)
    assert np.all(np.diff(p.variances) <= 1e-12)


def test_pca_variance_rule():
    rng = np.random.default_rng(3)
    scales = np.array([10.0, 5.0, 1.0, 0.1, 0.01])
    x = rng.standard_normal((5000, 5)) * scales
    p = fit_pca(x, n_components=None, variance_target=0.99)
    # variances 100, 25, 1, .01, .0001: two components reach 125/126 = 99.2 %
    assert p.n_components == 2
    assert fit_pca(x, n_components=3).n_components == 3


# ---------------------------------------------------------------- codebook / context
def test_codeword_placement():
    t = codeword_times(np.array([1.0]), np.array([1.5]), 5, "centres")
    np.testing.assert_allclose(t, [[1.05, 1.15, 1.25, 1.35, 1.45]])
    t = codeword_times(np.array([1.0]), np.array([1.5]), 5, "edges")
    np.testing.assert_allclose(t, [[1.0, 1.125, 1.25, 1.375, 1.5]])


def test_interpolate_frames():
    v = np.array([[0.0], [6.0], [12.0]])
    np.testing.assert_allclose(interpolate_frames(v, 60.0, np.array([0.0, 0.5 / 60, 2 / 60])),
                               [[0.0], [3.0], [12.0]])


def test_context_phones_whenever():
    # the paper's Figure 3: /eh/ in "whenever" is /w eh n eh v axr f/ with C = 3
    seq = ["w", "eh", "n", "eh", "v", "axr", "f"]
    ids = {p: i for i, p in enumerate(dict.fromkeys(["sil", *seq]))}
    ctx = context_ids([ids[p] for p in seq], 3, ids["sil"])
    inv = {i: p for p, i in ids.items()}
    assert [inv[i] for i in ctx[3]] == ["w", "eh", "n", "eh", "v", "axr", "f"]
    assert [inv[i] for i in ctx[0]] == ["sil", "sil", "sil", "w", "eh", "n", "eh"]


def test_label_normalising_and_mapping(caplog):
    assert normalise_label("AH0") == "ah" and normalise_label("h#") == "sil"
    segs = [PhoneSegment(0, 1, "AX"), PhoneSegment(1, 2, "T")]
    out = map_labels(segs, ["ah", "t", "sil"])
    assert [s.label for s in out] == ["ah", "t"]
    assert "not in the model" in caplog.text
    with pytest.raises(InputError, match="'zz'.*known phones: ah sil t"):
        map_labels([PhoneSegment(0, 1, "zz")], ["ah", "t", "sil"], path="x.TextGrid")
    with pytest.raises(InputError):
        map_labels(segs, ["ah", "t", "sil"], strict=True)
    assert map_labels([PhoneSegment(0, 1, "@")], ["ah", "sil"], {"@": "ah"})[0].label == "ah"


# ---------------------------------------------------------------- smoothing
def test_triangular_window_100ms_at_60hz():
    np.testing.assert_allclose(triangular_window(60.0, 0.1) * 16, [1, 2, 3, 4, 3, 2, 1])


def test_triangular_is_zero_phase_and_keeps_constants():
    x = np.zeros((61, 2))
    x[30] = 16.0
    y = triangular_smooth(x, 60.0)
    np.testing.assert_allclose(y[27:34, 0], [1, 2, 3, 4, 3, 2, 1])
    assert np.argmax(y[:, 0]) == 30
    np.testing.assert_allclose(triangular_smooth(np.full((20, 3), 7.0), 60.0), 7.0)


def test_spline_smooths_and_keeps_slow_signals():
    t = np.arange(240) / 60.0
    slow = np.sin(2 * np.pi * 0.5 * t)[:, None]
    noisy = slow + 0.3 * np.random.default_rng(4).standard_normal(slow.shape)
    out = spline_smooth(noisy, 60.0, 0.1)
    assert np.abs(out - slow).std() < 0.5 * np.abs(noisy - slow).std()
    np.testing.assert_allclose(spline_smooth(np.full((50, 1), 2.0), 60.0), 2.0)
    with pytest.raises(ValueError):
        smooth(slow, 60.0, "cubic")
    np.testing.assert_array_equal(smooth(slow, 60.0, "none"), slow)


def test_planar_head_motion_with_two_fixed_points():
    # midsagittal data (x = 0): two reference coils fix an in-plane rotation and translation
    rng = np.random.default_rng(5)
    neutral = np.zeros((4, 3))
    neutral[:, 1:] = rng.standard_normal((4, 2)) * 30
    faces = np.repeat(neutral[None], 20, axis=0)
    faces[:, 3, 1] += np.linspace(0, 5, 20)            # a lip moving down-up, non-rigid
    moved = faces.copy()
    for t in range(20):
        a = 0.05 * np.sin(t)
        rot = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
        moved[t] = faces[t] @ rot.T + np.array([0.0, t * 0.3, -t * 0.2])
    out = remove_head_motion(moved, np.array([0, 1]), neutral[:2])
    np.testing.assert_allclose(out, faces, atol=1e-9)
    assert not out[..., 0].any()
