"""The robust mode (issue 16, facetraj_engine.method.selection): each new equation on a hand-checked example, the
fast kernels against plain loops, the mode rule, and the model file keeping its new parts."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import edited_model_file

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment, Provenance
from facetraj_engine.method.kernels import use_kernels
from facetraj_engine.method.model import Model
from facetraj_engine.method.modes import choose_mode
from facetraj_engine.method.pipeline import frame_confidence, synthesize
from facetraj_engine.method.selection import (
    candidate_union,
    context_distances,
    context_frames,
    label_penalty,
    mean_normalise,
    robust_frames,
    weight_costs,
)
from facetraj_engine.method.synthesis import gamma_grid, perceptual_weights, weight_frames


def test_mean_normalise_hand_checked():
    # mean of the two rows is [0.5, 1.1]; the target mean [0.5, 1.0] moves the second LSF by -0.1
    w = np.array([[0.4, 1.0], [0.6, 1.2]])
    out = mean_normalise(w, np.array([0.5, 1.0]))
    np.testing.assert_allclose(out, [[0.4, 0.9], [0.6, 1.1]])
    # the mean over the masked frames only: frame 0 alone, mean [0.4, 1.0] -> shift [+0.1, 0]
    out = mean_normalise(w, np.array([0.5, 1.0]), mask=np.array([True, False]))
    np.testing.assert_allclose(out, [[0.5, 1.0], [0.7, 1.2]])


def test_context_frames_clamped():
    w = np.array([[1.0], [2.0], [3.0], [4.0]])
    got = context_frames(w, np.array([-2, 2]))[..., 0]
    assert got.tolist() == [[1.0, 3.0], [1.0, 4.0], [1.0, 4.0], [2.0, 4.0]]


def test_context_distance_hand_checked():
    # centre: w = [0.5, 0.6], h = [1/min(0.5, 0.1), 1/min(0.1, pi-0.6)] = [10, 10];
    # L = [0.6, 0.7]: d = 10 * 0.1 + 10 * 0.1 = 2.0.
    # context (one offset): w_o = [1.0, 2.0], h_o = [1/min(1, 1), 1/min(1, pi-2)] = [1, 1/(pi-2)];
    # L_o = [1.5, 2.0]: d_o = 1 * 0.5 + 0 = 0.5; rho = 2, O = 1: total 2.0 + 2 * 0.5 = 3.0
    w = np.array([[0.5, 0.6]])
    cand = np.array([[[0.6, 0.7]]])
    wc = np.array([[[1.0, 2.0]]])
    cc = np.array([[[[1.5, 2.0]]]])
    assert context_distances(w, None, cand, None, 2.0)[0, 0] == pytest.approx(2.0)
    assert context_distances(w, wc, cand, cc, 2.0)[0, 0] == pytest.approx(3.0)
    assert context_distances(w, wc, cand, cc, 0.0)[0, 0] == pytest.approx(2.0)


def test_context_distance_against_loops():
    rng = np.random.default_rng(0)
    t, i, o, p = 4, 5, 2, 6
    w = np.sort(rng.uniform(0.1, 3.0, (t, p)), axis=1)
    wc = np.sort(rng.uniform(0.1, 3.0, (t, o, p)), axis=2)
    cand = np.sort(rng.uniform(0.1, 3.0, (t, i, p)), axis=2)
    cctx = np.sort(rng.uniform(0.1, 3.0, (t, i, o, p)), axis=3)
    rho = 0.7
    got = context_distances(w, wc, cand, cctx, rho)
    for a in range(t):
        h = perceptual_weights(w[a])
        for b in range(i):
            ref = sum(h[k] * abs(w[a, k] - cand[a, b, k]) for k in range(p))
            for q in range(o):
                hq = perceptual_weights(wc[a, q])
                ref += rho / o * sum(hq[k] * abs(wc[a, q, k] - cctx[a, b, q, k]) for k in range(p))
            assert got[a, b] == pytest.approx(ref)


def test_candidate_union_and_penalty_hand_checked():
    cand, from_labels, valid = candidate_union(np.array([[3, 4], [5, 6]]), np.array([[4, 7], [8, 9]]))
    assert cand.tolist() == [[3, 4, 4, 7], [5, 6, 8, 9]]
    assert from_labels.tolist() == [[True, True, True, False], [True, True, False, False]]
    assert valid.tolist() == [[True, True, False, True], [True, True, True, True]]
    # kappa = 4, confidences 0.25 and 1: 1.0 and 4.0 on the codewords eq 4 did not choose
    pen = label_penalty(from_labels, np.array([0.25, 1.0]), 4.0)
    assert pen.tolist() == [[0, 0, 0, 1.0], [0, 0, 4.0, 4.0]]


def test_frame_confidence():
    segs = [PhoneSegment(0.0, 0.1, "sil"), PhoneSegment(0.1, 0.3, "p"), PhoneSegment(0.3, 0.4, "sil")]
    times = np.array([0.0, 0.05, 0.15, 0.25, 0.35])
    assert frame_confidence(segs, None, times).tolist() == [1, 1, 1, 1, 1]
    assert frame_confidence(segs, [0.2, 2.0, np.nan], times).tolist() == [0.2, 0.2, 1.0, 1.0, 0.5]
    with pytest.raises(ValueError, match="2 label confidences for 3 phones"):
        frame_confidence(segs, [0.2, 0.3], times)


def test_weight_costs_is_eqs_6_to_8_on_eq5(toy_model):
    """With eq 5's distance as the cost, weight_costs reproduces the paper's weight_frames."""
    cb = toy_model.codebook
    rng = np.random.default_rng(1)
    w = cb.lsf[rng.choice(len(cb.lsf), 6)] + 0.01
    cand = rng.choice(len(cb.lsf), (6, 9))
    gam = gamma_grid()
    # the numpy reference: where one codeword dominates, two gammas' errors are equal to
    # rounding and the compiled kernel's sums may pick the other (the PCs equal to rounding)
    with use_kernels("numpy"):
        ref = weight_frames(w, cand, cb.lsf, cb.pcs, gam)
    d = context_distances(w, None, cb.lsf[cand], None, 0.0)
    got = weight_costs(w, cand, d, cb.lsf, cb.pcs, gam)
    np.testing.assert_allclose(got.pcs, ref.pcs)
    np.testing.assert_allclose(got.gamma, ref.gamma)
    np.testing.assert_allclose(got.weights, ref.weights)


def test_robust_frames_limits(toy_model):
    """A huge label weight with confident labels leaves only eq 4's codewords (the paper's mode);
    repeats get no weight; zero confidence lets the acoustic candidates in."""
    cb = toy_model.codebook
    rng = np.random.default_rng(2)
    w = cb.lsf[rng.choice(len(cb.lsf), 5)] + 0.005
    phon = rng.choice(len(cb.lsf), (5, 10))
    near = rng.choice(len(cb.lsf), (5, 8))
    near[:, 0] = phon[:, 3]                                      # a repeat in every frame
    gam = gamma_grid()
    ref = weight_frames(w, phon, cb.lsf, cb.pcs, gam)
    got = robust_frames(w, phon, near, np.ones(5), cb.lsf, cb.pcs, gam, kappa=1e6)
    np.testing.assert_allclose(got.pcs, ref.pcs, atol=1e-9)
    assert np.all(got.weights[:, 10] == 0)                       # the repeat does not count
    np.testing.assert_allclose(got.weights.sum(axis=1), 1.0)
    open_ = robust_frames(w, phon, near, np.zeros(5), cb.lsf, cb.pcs, gam, kappa=1e6)
    assert np.all(open_.label_cost == 0)
    assert open_.weights[:, 11:].sum() > 0


def test_mode_rule():
    segs = [PhoneSegment(0.0, 0.2, "sil")]
    aligned, recognized = Provenance("aligned"), Provenance("recognized")
    assert choose_mode(SynthConfig(), segs).mode == "phonetic"
    assert choose_mode(SynthConfig(), segs, Provenance()).mode == "phonetic"
    assert choose_mode(SynthConfig(), segs, aligned).mode == "robust"
    assert choose_mode(SynthConfig(), segs, recognized).mode == "robust"
    assert choose_mode(SynthConfig(), segs, recognized, explicit=True).mode == "phonetic"
    assert choose_mode(SynthConfig(mode="robust"), None).mode == "acoustic"
    assert choose_mode(SynthConfig(mode="acoustic"), segs, aligned, explicit=True).mode == "acoustic"
    assert choose_mode(SynthConfig(mode="robust"), segs, explicit=True).mode == "robust"
    # the robust mode takes the model's cross-validated settings, but not those the user set
    tuned = {"settings": {"label_weight": 2.0, "n_context_phones": 6}}
    got = choose_mode(SynthConfig(), segs, aligned, tuned=tuned, keep=("n_context_phones",))
    assert (got.config.label_weight, got.config.n_context_phones) == (2.0, 3)
    assert "cross-validated" in got.reason and "aligned" in got.reason
    assert choose_mode(SynthConfig(), segs, tuned=tuned).config.label_weight == 16.0


def test_robust_synthesis_and_model_file(toy_model, toy_corpus, tmp_path):
    assert toy_model.codebook.lsf_context.shape == (*toy_model.codebook.lsf.shape[:1], 2,
                                                    toy_model.codebook.lsf.shape[1])
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    cfg = SynthConfig(mode="robust", robust_candidates=16)
    conf = np.linspace(0.1, 1.0, len(utt.phones))
    res = synthesize(toy_model, utt.audio, utt.sample_rate, utt.phones, cfg, n_frames=utt.n_frames,
                     confidence=conf)
    assert res.frames.candidates.shape == (utt.n_frames, 15 + 16)
    assert np.isfinite(res.markers).all()
    np.testing.assert_allclose(res.frames.confidence, conf[res.frame_segment])
    # saved and loaded: context and tuned settings kept; an older file without them still loads
    toy_model.tuned = {"settings": {"label_weight": 2.0}}
    try:
        path = toy_model.save(tmp_path / "m.npz")
    finally:
        toy_model.tuned = {}
    back = Model.load(path)
    assert back.tuned == {"settings": {"label_weight": 2.0}}
    np.testing.assert_array_equal(back.codebook.lsf_context, toy_model.codebook.lsf_context)
    old = Model.load(edited_model_file(path, tmp_path / "old.npz", cb_lsf_context=None))
    assert old.codebook.lsf_context is None
    res_old = synthesize(old, utt.audio, utt.sample_rate, utt.phones, cfg, n_frames=utt.n_frames)
    assert np.isfinite(res_old.markers).all()
