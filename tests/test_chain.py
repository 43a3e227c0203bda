"""The chain over frames (facetraj_engine.method.chain): forward-backward against every path enumerated,
beta = 0 is eq 8, and the robust mode with it on real synthesis."""

from __future__ import annotations

import itertools

import numpy as np

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import Provenance
from facetraj_engine.method.chain import chain_marginals, chain_pcs, join_log_potentials, join_scale
from facetraj_engine.method.pipeline import synthesize


def brute_marginals(log_target: np.ndarray, log_join: np.ndarray) -> np.ndarray:
    """The reference: every path's probability, summed per frame and candidate."""
    n, m = log_target.shape
    q = np.zeros((n, m))
    for path in itertools.product(range(m), repeat=n):
        lp = sum(log_target[t, i] for t, i in enumerate(path))
        lp += sum(log_join[t - 1, path[t - 1], path[t]] for t in range(1, n))
        for t, i in enumerate(path):
            q[t, i] += np.exp(lp)
    return q / q.sum(axis=1, keepdims=True)


def test_forward_backward_equals_every_path_summed():
    rng = np.random.default_rng(7)
    for n, m in ((1, 3), (2, 2), (4, 3), (5, 4)):
        lt = np.log(rng.dirichlet(np.ones(m), size=n))
        lt[rng.random((n, m)) < 0.15] = -np.inf          # entries that do not count
        lt[:, 0] = np.maximum(lt[:, 0], np.log(0.1))     # every frame keeps one
        lj = -rng.gamma(1.0, 2.0, size=(max(n - 1, 0), m, m))
        np.testing.assert_allclose(chain_marginals(lt, lj), brute_marginals(lt, lj), atol=1e-12)


def test_beta_zero_is_eq8_and_the_join_pulls_towards_continuity():
    rng = np.random.default_rng(3)
    cb_pcs = rng.normal(size=(12, 4))
    cands = rng.integers(0, 12, size=(6, 5))
    w = rng.dirichlet(np.ones(5), size=6)
    np.testing.assert_allclose(chain_pcs(w, cands, cb_pcs, 0.0, 1.0),
                               np.einsum("ti,tik->tk", w, cb_pcs[cands]))
    smooth = chain_pcs(w, cands, cb_pcs, 5.0, 1.0)
    assert np.abs(np.diff(smooth, axis=0)).sum() < np.abs(np.diff(chain_pcs(w, cands, cb_pcs, 0.0, 1.0),
                                                                  axis=0)).sum()
    lj = join_log_potentials(cb_pcs[cands], 2.0, 0.5)
    i, j = 1, 3
    assert np.isclose(lj[0, i, j], -2.0 * np.sum((cb_pcs[cands[0, i]] - cb_pcs[cands[1, j]]) ** 2) / 0.5)


def test_join_scale_of_the_default_model(default_model):
    cb = default_model.codebook
    s2 = join_scale(cb.pcs, cb.token_start, cb.token_end, cb.n_per_phone, default_model.marker_rate)
    assert s2 == default_model.join_scale and 1.0 < s2 < 100.0


def test_robust_synthesis_with_the_chain(default_model, default_corpus):
    utt = default_corpus.utterance(default_corpus.info.test[0])
    aligned = Provenance("aligned")
    conf = np.full(len(utt.phones), 0.5)
    runs = {b: synthesize(default_model, utt.audio, utt.sample_rate, utt.phones,
                          SynthConfig(mode="robust", chain_beta=b, closure=False),
                          n_frames=utt.n_frames, confidence=conf, provenance=aligned)
            for b in (0.0, 0.1, 2.0)}
    steps = {b: np.abs(np.diff(r.raw_pcs, axis=0)).mean() for b, r in runs.items()}
    assert steps[2.0] < steps[0.1] < steps[0.0]          # raw eq 8 steps shrink with beta
    np.testing.assert_allclose(runs[0.0].raw_pcs, np.einsum(
        "ti,tik->tk", runs[0.0].frames.weights, default_model.codebook.pcs[runs[0.0].frames.candidates]),
        atol=1e-9)
