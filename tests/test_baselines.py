"""The viseme-lookup and ridge baselines of the results report (issue 7), checked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.evaluation.baselines import (
    Baselines,
    FrameData,
    evaluate_baselines,
    fit_baselines,
    fit_ridge,
    fit_ridge_baseline,
    fit_viseme,
    frame_data,
    stack_context,
)


def test_stack_context_by_hand():
    x = np.array([[1.0, 10], [2, 20], [3, 30]])
    s = stack_context(x, 1)
    assert s.shape == (3, 6)
    # frame 0: [x(-1)=x(0), x(0), x(1)], edges repeated
    assert s[0].tolist() == [1, 10, 1, 10, 2, 20]
    assert s[1].tolist() == [1, 10, 2, 20, 3, 30]
    assert s[2].tolist() == [2, 20, 3, 30, 3, 30]
    assert stack_context(x, 0).tolist() == x.tolist()


def test_ridge_by_hand():
    # x = 0, 1, 2; y = 2x. Standardised x = (x - 1) / sqrt(2/3), so Xs'Xs = 3 and Xs'yc = 2 sqrt(6).
    x = np.array([[0.0], [1.0], [2.0]])
    y = 2 * x
    exact = fit_ridge(x, y, 0.0)
    assert exact.predict(np.array([[5.0]]))[0, 0] == pytest.approx(10.0)
    # lam = 3 = Xs'Xs halves the slope about the means: predictions 1, 2, 3
    half = fit_ridge(x, y, 3.0)
    assert half.predict(x).ravel() == pytest.approx([1.0, 2.0, 3.0])
    assert half.coef[0, 0] == pytest.approx(2 * np.sqrt(6) / 6)
    assert half.y_mean.tolist() == [2.0]
    # a huge penalty predicts the mean; a constant feature gets no weight and no division by 0
    assert fit_ridge(x, y, 1e12).predict(x).ravel() == pytest.approx([2.0, 2.0, 2.0])
    xc = np.hstack([x, np.ones((3, 1))])
    r = fit_ridge(xc, y, 0.0)
    assert r.coef[1, 0] == pytest.approx(0.0)
    assert r.predict(xc).ravel() == pytest.approx(y.ravel())


def test_ridge_two_outputs_recovers_linear_map():
    rng = np.random.default_rng(0)
    x = rng.standard_normal((200, 3))
    w = np.array([[1.0, -2.0], [0.5, 0.0], [0.0, 3.0]])
    y = x @ w + np.array([4.0, -1.0])
    r = fit_ridge(x, y, 0.0)
    assert np.allclose(r.predict(x), y)
    assert np.allclose(r.coef / r.x_scale[:, None], w)     # back on the raw feature scale


def test_viseme_by_hand():
    pcs = np.array([[1.0, 0], [3, 2], [10, 10], [np.nan, np.nan], [6, 0]])
    phone = np.array([0, 0, 1, 1, -1])
    v = fit_viseme(pcs, phone, 3)
    assert v.table[0].tolist() == [2.0, 1.0]          # mean of rows 0-1
    assert v.table[1].tolist() == [10.0, 10.0]        # the NaN row is left out
    assert np.isnan(v.table[2]).all()                 # phone 2 never seen
    assert v.fallback.tolist() == [5.0, 3.0]          # all finite rows, labelled or not
    pred = v.predict(np.array([1, 0, 2, -1, 7]))
    assert pred.tolist() == [[10, 10], [2, 1], [5, 3], [5, 3], [5, 3]]


def _frames(name: str, lsf: np.ndarray, pcs: np.ndarray, phone: np.ndarray) -> FrameData:
    n = len(lsf)
    return FrameData(name, lsf, pcs, phone, np.zeros((n, 1, 3)), np.ones(n, bool))


def test_ridge_baseline_chooses_lambda_on_training_only():
    rng = np.random.default_rng(1)
    frames = []
    for k in range(10):
        lsf = rng.standard_normal((50, 2))
        prev = lsf[np.maximum(np.arange(50) - 1, 0), 1]           # frame t-1, edge repeated
        pcs = (lsf[:, 0] + 0.5 * prev)[:, None]
        frames.append(_frames(f"u{k}", lsf, pcs, np.zeros(50, int)))
    r = fit_ridge_baseline(frames, k=1, lambdas=(1e-6, 10.0))
    assert r.lam == pytest.approx(1e-6 * 500)          # the small penalty fits better, refit on all
    x = stack_context(frames[0].lsf, 1)
    assert np.allclose(r.predict(x), frames[0].pcs, atol=1e-3)


def test_baselines_on_toy_corpus(toy_model, toy_corpus):
    utts = {sp: [toy_corpus.utterance(u) for u in getattr(toy_corpus.info, sp)[:4]]
            for sp in ("train", "test")}
    frames = {sp: [frame_data(toy_model, u) for u in us] for sp, us in utts.items()}
    fd = frames["train"][0]
    assert fd.lsf.shape == (utts["train"][0].n_frames, toy_model.config.lpc_order)
    assert fd.pcs.shape[1] == toy_model.pca.n_components
    assert (fd.phone >= 0).all() and fd.speech.any() and not fd.speech.all()
    base = fit_baselines(toy_model, frames["train"])
    assert isinstance(base, Baselines)
    scores = evaluate_baselines(toy_model, base, frames, smoothings=("triangular",))
    assert len(scores) == 2 * 4 * 2                   # splits x utterances x baselines
    for s in scores:
        assert s.mode in ("viseme", "ridge") and s.n_context_phones == 0
        assert -1 <= s.whole_face <= 1 and s.speech_frames > 0
    # the toy's faces follow its phones: the viseme lookup must track them well
    vis = [s.whole_face for s in scores if s.mode == "viseme" and s.split == "test"]
    assert np.mean(vis) > 0.8


def test_baselines_fitted_an_utterance_at_a_time_equal_the_fit_of_every_frame(toy_model,
                                                                              toy_corpus):
    """The report streams the training utterances into the fit (issue 41): the viseme table and
    its fallback are the bits of the lookup of every frame at once; the ridge regression from the
    merged moments is the closed form on every frame at once to rounding."""
    frames = [frame_data(toy_model, toy_corpus.utterance(u), keep_original=False)
              for u in toy_corpus.info.train]
    assert frames[0].original.size == 0
    pcs = np.concatenate([fd.pcs for fd in frames])
    phone = np.concatenate([fd.phone for fd in frames])
    streamed = fit_baselines(toy_model, iter(frames), len(frames))
    whole = fit_viseme(pcs, phone, len(toy_model.phones))
    np.testing.assert_array_equal(streamed.viseme.table, whole.table)
    np.testing.assert_array_equal(streamed.viseme.fallback, whole.fallback)
    ok = np.isfinite(pcs).all(axis=1)
    x = np.concatenate([stack_context(fd.lsf, 5) for fd in frames])[ok]
    y = pcs[ok]
    scale = np.where(x.std(axis=0) > 0, x.std(axis=0), 1.0)
    xs = (x - x.mean(axis=0)) / scale
    lam = streamed.ridge.lam
    coef = np.linalg.solve(xs.T @ xs + lam * np.eye(xs.shape[1]), xs.T @ (y - y.mean(axis=0)))
    np.testing.assert_allclose(streamed.ridge.coef, coef, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(streamed.ridge.predict(x), xs @ coef + y.mean(axis=0), atol=1e-9)
