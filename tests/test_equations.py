"""Every equation of the paper with a small hand-checked example (sections 2.2 and 2.3)."""

import numpy as np
import pytest

from facetraj_engine.method.similarity import (
    context_similarity,
    context_weights,
    distance_scale,
    format_table1,
    phone_distances,
    phone_means,
    similarity_matrix,
    top_contexts,
    top_similar,
)
from facetraj_engine.method.synthesis import (
    approximate_lsf,
    codebook_weights,
    gamma_grid,
    lsf_distances,
    nearest_codewords,
    perceptual_weights,
    weight_frames,
)


# ---------------------------------------------------------------- eq 1-3
def test_eq1_phone_means():
    pcs = np.array([[1.0, 0.0], [3.0, 2.0], [10.0, 10.0], [0.0, 4.0]])
    phone = np.array([0, 0, 1, 2])
    m = phone_means(pcs, phone, 4)
    np.testing.assert_allclose(m[:3], [[2.0, 1.0], [10.0, 10.0], [0.0, 4.0]])
    assert np.isnan(m[3]).all()  # a phone with no token


def test_eq2_distances():
    m = np.array([[0.0, 0.0], [3.0, 4.0], [0.0, 1.0]])
    d = phone_distances(m)
    np.testing.assert_allclose(d, [[0, 5, 1], [5, 0, np.sqrt(18)], [1, np.sqrt(18), 0]])


def test_eq3_similarity_values():
    d = np.array([[0.0, 0.05, 0.5], [0.05, 0.0, 0.2], [0.5, 0.2, 0.0]])
    s = similarity_matrix(d, nu=10.0)
    np.testing.assert_allclose(s[0, 1], np.exp(-0.5))      # 0.6065
    np.testing.assert_allclose(s[0, 2], np.exp(-5.0))      # 0.0067
    np.testing.assert_allclose(np.diag(s), 1.0)
    assert np.all((s > 0) & (s <= 1))


def test_eq3_with_max_normalisation():
    d = np.array([[0.0, 2.0, 8.0], [2.0, 0.0, 4.0], [8.0, 4.0, 0.0]])
    scale = distance_scale(d, "max")
    assert scale == 8.0
    s = similarity_matrix(d, nu=10.0, scale=scale)
    np.testing.assert_allclose(s[0, 1], np.exp(-10 * 0.25))
    assert distance_scale(d, "median") == 4.0 and distance_scale(d, "none") == 1.0


def test_table1_layout():
    s = np.array([[1.0, 0.78, 0.58, 0.1], [0.78, 1.0, 0.81, 0.2], [0.58, 0.81, 1.0, 0.3],
                  [0.1, 0.2, 0.3, 1.0]])
    rows = top_similar(s, ["b", "p", "m", "sil"], k=2)
    assert [r.phone for r in rows] == ["b", "p", "m"]          # silence left out
    assert rows[0].neighbours == (("p", 0.78), ("m", 0.58))
    text = format_table1(rows)
    assert text.splitlines()[1].split() == ["b", "p", "0.78", "m", "0.58"]


# ---------------------------------------------------------------- eq 4
def test_eq4_hand_example():
    # phones 0..2; C = 2, xi = 20
    s = np.array([[1.0, 0.5, 0.1], [0.5, 1.0, 0.2], [0.1, 0.2, 1.0]])
    query = np.array([0, 1, 2, 1, 0])          # l2 l1 c r1 r2
    cb = np.array([[0, 1, 2, 1, 0],            # identical
                   [2, 2, 2, 2, 2],            # centre match only
                   [0, 1, 1, 1, 0]])           # context match, centre differs
    n = context_similarity(query, cb, s, xi=20.0)
    exp_identical = 1 + (1 + 1) / 20 + (1 + 1) / 400
    exp_centre = 1 + (0.2 + 0.2) / 20 + (0.1 + 0.1) / 400
    exp_context = 0.2 + (1 + 1) / 20 + (1 + 1) / 400
    np.testing.assert_allclose(n, [exp_identical, exp_centre, exp_context])
    # xi > 10: a centre match always outranks any context-only match (the paper's argument)
    assert n[1] > n[2]


def test_eq4_weights_and_reduced_context():
    np.testing.assert_allclose(context_weights(2, 20.0), [1 / 400, 1 / 20, 1, 1 / 20, 1 / 400])
    s = np.eye(3)
    q = np.array([1, 0, 2, 0, 1])
    cb = np.array([[0, 0, 2, 0, 0]])
    # with C = 1 only l1 and r1 count: 1 + (1 + 1)/20
    assert context_similarity(q, cb, s, 20.0, context=1)[0] == pytest.approx(1.1)
    assert context_similarity(q, cb, s, 20.0, context=2)[0] == pytest.approx(1.1)
    assert context_similarity(q, cb, s, 20.0, context=0)[0] == pytest.approx(1.0)


def test_top_n_context_phones():
    n = np.array([[0.5, 2.0, 1.0, 2.0]])
    assert top_contexts(n, 3).tolist() == [[1, 3, 2]]   # ties keep the lower index first


# ---------------------------------------------------------------- eq 5
def test_eq5_perceptual_weights():
    w = np.array([0.5, 0.6, 2.0])
    # neighbours: 0 | 0.5 0.6 2.0 | pi ; nearest gaps 0.1, 0.1, min(1.4, pi - 2)
    np.testing.assert_allclose(perceptual_weights(w), [10.0, 10.0, 1 / (np.pi - 2.0)])


def test_eq5_distances():
    w = np.array([0.5, 0.6, 2.0])
    cw = np.array([[0.5, 0.6, 2.0], [0.6, 0.6, 2.0], [0.5, 0.6, 2.5]])
    d = lsf_distances(w, cw)
    np.testing.assert_allclose(d, [0.0, 10 * 0.1, 0.5 / (np.pi - 2.0)])


# ---------------------------------------------------------------- eq 6-8
def test_eq6_weights():
    d = np.array([0.0, np.log(3.0)])
    np.testing.assert_allclose(codebook_weights(d, 1.0), [0.75, 0.25])
    np.testing.assert_allclose(codebook_weights(d, 2.0), [0.9, 0.1])
    # numerically stable for huge distances
    v = codebook_weights(np.array([1e4, 1e4 + 1.0]), 2.0)
    assert np.all(np.isfinite(v)) and v.sum() == pytest.approx(1.0)


def test_eq7_approximation():
    v = np.array([0.75, 0.25])
    cw = np.array([[0.4, 1.0], [0.8, 2.0]])
    np.testing.assert_allclose(approximate_lsf(v, cw), [0.5, 1.25])


def test_gamma_search_and_eq8():
    # two codewords; the input lies 1/4 of the way from codeword 0 to codeword 1
    cb_lsf = np.array([[0.4, 1.0, 2.0], [0.6, 1.0, 2.0]])
    cb_pcs = np.array([[0.0], [10.0]])
    w = np.array([[0.45, 1.0, 2.0]])
    gammas = gamma_grid(0.2, 2.0, 10)
    fw = weight_frames(w, np.array([[0, 1]]), cb_lsf, cb_pcs, gammas)
    # brute force the criterion by hand
    h = perceptual_weights(w[0])
    d = lsf_distances(w[0], cb_lsf, h)
    errs = [np.sum(h * np.abs(approximate_lsf(codebook_weights(d, g), cb_lsf) - w[0]))
            for g in gammas]
    g_best = gammas[int(np.argmin(errs))]
    assert fw.gamma[0] == pytest.approx(g_best)
    v = codebook_weights(d, g_best)
    np.testing.assert_allclose(fw.weights[0], v)
    np.testing.assert_allclose(fw.pcs[0], v @ cb_pcs)            # eq 8
    assert fw.weights[0].sum() == pytest.approx(1.0)
    assert 0 < fw.pcs[0, 0] < 5  # nearer to codeword 0


def test_gamma_grid_range():
    g = gamma_grid()
    assert g[0] == pytest.approx(0.2) and g[-1] == pytest.approx(2.0) and len(g) == 10


def test_nearest_codeword_prefilter():
    cb = np.array([[0.1, 0.2], [1.0, 2.0], [0.11, 0.21], [2.0, 3.0]])
    w = np.array([[0.1, 0.2]])
    idx = nearest_codewords(w, cb, 2)
    assert sorted(idx[0].tolist()) == [0, 2]
    assert nearest_codewords(w, cb, None).shape == (1, 4)


def test_grid_weights_equal_eq6_for_every_gamma():
    """The fast kernel of eq 6 on an evenly spaced gamma grid (two exponentials per codeword)
    against the reference softmax, for each gamma; an uneven grid takes the reference path."""
    from facetraj_engine.method.synthesis import codebook_weights, gamma_grid, grid_weights

    rng = np.random.default_rng(13)
    d = rng.gamma(2.0, 20.0, size=(50, 128))           # eq 5 distances of 128 candidates
    g = gamma_grid(0.2, 2.0, 10)
    fast = grid_weights(d, g)
    for j, gamma in enumerate(g):
        np.testing.assert_allclose(fast[:, j], codebook_weights(d, gamma), rtol=1e-12, atol=1e-300)
    uneven = np.array([0.2, 0.5, 2.0])
    np.testing.assert_array_equal(grid_weights(d, uneven), codebook_weights(d[:, None, :], uneven))


@pytest.mark.parametrize("count", [1, 3, 12])
def test_pruned_eq4_search_equals_scoring_every_context(count):
    """top_context_phones (pruned by the centre bound, all queries at once) returns exactly
    the full eq 4 ranking: the same contexts, scores and lower-index-first ties; phone 4 has
    fewer than 12 contexts at its best centre similarity (the unpruned path)."""
    from facetraj_engine.method.similarity import context_similarity, top_context_phones, top_contexts

    rng = np.random.default_rng(count)
    n_phones, context = 6, 3
    s = np.round(rng.uniform(0.0, 0.9, (n_phones, n_phones)), 1)   # rounded: ties happen
    s = (s + s.T) / 2
    np.fill_diagonal(s, 1.0)
    codebook = rng.integers(0, n_phones, (300, 2 * context + 1))
    codebook[codebook[:, context] == 4, context] = 5
    codebook[:5, context] = 4                                           # 5 contexts of phone 4
    query = rng.integers(0, n_phones, (40, 2 * context + 1))
    for c in (context, 1):
        top, scores = top_context_phones(query, codebook, s, 20.0, c, count)
        n = context_similarity(query, codebook, s, 20.0, c)
        ref = top_contexts(n, count)
        np.testing.assert_array_equal(top, ref)
        np.testing.assert_array_equal(scores, np.take_along_axis(n, ref, axis=1))
