"""Synthesis split between frame threads (facetraj_engine.threads): the same result as one thread, to
rounding (BLAS's matrix products may add a row's terms in another order for another number of
rows), in every mode that splits its frames; the thread-count rule; the evaluation on one thread."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.threads import (
    THREADS_ENV,
    frame_spans,
    frame_threads,
    limit_frame_threads,
    map_spans,
)


def _long_input(corpus, seconds: float):
    """Test-split speech joined end to end (with its labels), ``seconds`` long."""
    from benchmarks.common import concatenate_input

    return concatenate_input([corpus.utterance(u) for u in corpus.info.test[:6]], seconds)


SHORT = 120          # frames: 2 s


@pytest.fixture
def short_spans(monkeypatch):
    """Spans of 2 s, so that a few seconds of speech split between threads."""
    from facetraj_engine import threads

    monkeypatch.setattr(threads, "MIN_FRAMES_PER_THREAD", SHORT)


@pytest.mark.parametrize("mode", ["phonetic", "acoustic"])
def test_threads_give_the_same_synthesis(default_model, default_corpus, mode, short_spans):
    """Three threads (three spans of frames of at least 2 s) against one: the
    same candidates, gammas and weights; LSFs and face points equal to rounding."""
    audio, rate, phones = _long_input(default_corpus, 7.0)
    labels = phones if mode == "phonetic" else None
    n_frames = int(7.0 * default_model.marker_rate) + 1
    assert len(frame_spans(n_frames, 3)) == 3
    with limit_frame_threads(1):
        one = synthesize(default_model, audio, rate, labels, SynthConfig(mode=mode))
    with limit_frame_threads(3):
        three = synthesize(default_model, audio, rate, labels, SynthConfig(mode=mode))
    np.testing.assert_allclose(three.lsf, one.lsf, rtol=0, atol=1e-13)
    np.testing.assert_array_equal(three.frames.candidates, one.frames.candidates)
    np.testing.assert_array_equal(three.frames.gamma, one.frames.gamma)
    np.testing.assert_allclose(three.frames.weights, one.frames.weights, rtol=0, atol=1e-12)
    np.testing.assert_allclose(three.markers, one.markers, rtol=0, atol=1e-9)       # mm


def test_the_whole_codebook_stays_one_shared_row(default_model, default_corpus, short_spans):
    """Acoustic-only over every codeword (the paper's search) in two spans: the candidates stay a
    broadcast row (not 5L indices per frame), and the result is one thread's."""
    audio, rate, _ = _long_input(default_corpus, 4.5)
    cfg = SynthConfig(mode="acoustic", acoustic_prefilter=None)
    with limit_frame_threads(1):
        one = synthesize(default_model, audio, rate, None, cfg)
    with limit_frame_threads(2):
        two = synthesize(default_model, audio, rate, None, cfg)
    assert two.frames.candidates.strides[0] == 0
    assert two.frames.candidates.shape == (len(two.times), default_model.codebook.lsf.shape[0])
    np.testing.assert_allclose(two.raw_pcs, one.raw_pcs, rtol=0, atol=1e-9)


def test_thread_count_rule(monkeypatch, short_spans):
    monkeypatch.setenv(THREADS_ENV, "3")
    assert frame_threads() == 3
    with limit_frame_threads(1):
        assert frame_threads() == 1
        assert frame_spans(10 * SHORT) == [(0, 10 * SHORT)]
    assert frame_threads() == 3
    monkeypatch.setenv(THREADS_ENV, "zero")          # not a positive integer: the cores
    assert frame_threads() >= 1
    spans = frame_spans(5 * SHORT - 1, 8)
    assert len(spans) == 4 and spans[0][0] == 0 and spans[-1][1] == 5 * SHORT - 1
    assert all(b - a >= SHORT for a, b in spans)


def test_an_error_in_a_span_reaches_the_caller(short_spans):
    def fail_late(a: int, b: int) -> int:
        if a > 0:
            raise ValueError(f"frames {a}-{b}")
        return b

    with pytest.raises(ValueError, match="frames 120-240"):
        map_spans(fail_late, 2 * SHORT, 2)


def test_evaluation_synthesizes_on_one_frame_thread(default_model, default_corpus, monkeypatch):
    """evaluate() scores are independent of its worker processes to the bit: each utterance is
    synthesized on one frame thread, whatever the process would use."""
    from facetraj_engine.evaluation.scores import evaluate
    from facetraj_engine.method import search

    seen = []
    real = search.frame_threads

    def spy() -> int:
        seen.append(real())
        return seen[-1]

    monkeypatch.setattr(search, "frame_threads", spy)
    monkeypatch.setenv(THREADS_ENV, "2")
    info = default_corpus.info
    sub = type(info)(**{**info.__dict__, "train": info.train[:2], "test": info.test[:2]})
    corpus = type(default_corpus)(default_corpus.root, sub)
    evaluate(default_model, corpus, ("train", "test"), [SynthConfig()], ("triangular",))
    assert seen and set(seen) == {1}


def _blas_threads() -> int:
    from threadpoolctl import threadpool_info

    return max(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")


def test_synthesis_runs_blas_on_one_thread_and_gives_it_back(default_model, default_corpus,
                                                             monkeypatch):
    """While synthesize() runs, BLAS runs on one thread (its idle threads would spin beside the
    frame threads, facetraj_engine.threads.above_blas); after it, on as many as before."""
    from threadpoolctl import threadpool_limits

    from facetraj_engine.method import pipeline

    seen = []
    real = pipeline.smooth

    def spy(*args, **kwargs):
        seen.append(_blas_threads())
        return real(*args, **kwargs)

    monkeypatch.setattr(pipeline, "smooth", spy)
    utt = default_corpus.utterance(default_corpus.info.test[0])
    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        if before < 2:
            pytest.skip("BLAS runs on one thread on this machine")
        synthesize(default_model, utt.audio, utt.sample_rate, config=SynthConfig(mode="acoustic"))
        assert (before, seen, _blas_threads()) == (2, [1], 2)


def test_input_lsf_is_synthesis_own_whatever_the_callers_blas(default_model, default_corpus):
    """LSFs a caller analyses (``Model.input_lsf``, to pass as ``lsf=``) are the ones synthesis
    analyses, to the bit, with BLAS on two threads around the call: the LSF analysis runs BLAS
    on one thread itself (its matrix products add terms in another order on two)."""
    from threadpoolctl import threadpool_limits

    utt = default_corpus.utterance(default_corpus.info.test[0])
    res = synthesize(default_model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(),
                     n_frames=utt.n_frames)
    with threadpool_limits(limits=2, user_api="blas"):
        if _blas_threads() < 2:
            pytest.skip("BLAS runs on one thread on this machine")
        w = default_model.input_lsf(utt.audio, utt.sample_rate, res.times)
        assert _blas_threads() == 2
    np.testing.assert_array_equal(w, res.lsf)
    again = synthesize(default_model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(),
                       n_frames=utt.n_frames, lsf=w)
    np.testing.assert_array_equal(again.markers, res.markers)
