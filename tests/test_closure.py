"""The closure step's per-interval work (``facetraj_engine.method.closure``): each interval touches
only its own frames, with results equal to the bit to the formula over every frame; the rest in
pauses (issue 46) read from the frames before each, equal to the rule written frame by frame."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.method.closure import (
    ClosurePlan,
    ClosureStats,
    bump,
    close_lips,
    rest_in_pauses,
    rest_weights,
)


def _close_lips_every_frame(pcs, times, plan, stats, a0, g, taper_s):
    """The step as its docstring states it, every interval's bump over the whole input."""
    a = a0 + pcs @ g
    c = np.zeros(len(pcs))
    for (t0, t1), s in zip(plan.intervals, plan.strengths, strict=True):
        idx = np.flatnonzero((times >= t0) & (times < t1))
        if idx.size == 0:
            idx = np.array([int(np.argmin(np.abs(times - 0.5 * (t0 + t1))))])
        move = s * min(0.0, stats.closed - float(a[idx].min()))
        if move < 0:
            c = np.minimum(c, move * bump(times, t0, t1, taper_s))
    return pcs + c[:, None] * stats.direction[None, :]


def _rest_every_frame(pcs, plan, stats, rate, min_s, taper_s):
    """The rest rule frame by frame: the silence through t, counted back to the last speech frame,
    or to the input's start (long already); none on a speech frame."""
    b = np.zeros(len(pcs))
    for t in range(len(pcs)):
        k, length = t, 0
        while k >= 0 and plan.silent[k]:
            length, k = length + 1, k - 1
        if not length:
            continue
        if k < 0:
            b[t] = 1.0
        elif taper_s > 0:
            x = min(max((length / rate - min_s) / taper_s, 0.0), 1.0)
            b[t] = 0.5 * (1 - np.cos(np.pi * x))
        else:
            b[t] = float(length / rate > min_s)
    return pcs + b[:, None] * (stats.rest[None, :] - pcs)


def _plan(rng, duration: float, n: int) -> ClosurePlan:
    """Random intervals: some shorter than a frame, some at the input's ends or beyond, some
    overlapping."""
    starts = rng.uniform(-0.05, duration, n)
    lengths = np.where(rng.random(n) < 0.3, rng.uniform(0, 0.01, n), rng.uniform(0.02, 0.3, n))
    intervals = np.column_stack([starts, starts + lengths])
    silent = np.repeat(rng.random(int(duration * 6) + 1) < 0.4, 10)[:int(duration * 60) + 1]
    return ClosurePlan(intervals, rng.uniform(0, 1, n), silent)


@pytest.mark.parametrize("taper_s", [0.0, 0.016, 0.05, 0.3])
@pytest.mark.parametrize("seed", range(4))
def test_closure_step_equals_the_formula_over_every_frame(seed: int, taper_s: float) -> None:
    rng = np.random.default_rng(seed)
    times = np.arange(600) / 60.0
    k = 6
    pcs = rng.standard_normal((len(times), k)) * 5
    stats = ClosureStats(-3.0, rng.standard_normal(k), rng.standard_normal(k))
    g = rng.standard_normal(k)
    plan = _plan(rng, times[-1], 40)
    got = close_lips(pcs, times, plan, stats, 0.5, g, taper_s)
    assert np.array_equal(got, _close_lips_every_frame(pcs, times, plan, stats, 0.5, g, taper_s))
    assert not np.array_equal(got, pcs)                       # the intervals moved the lips
    rested = rest_in_pauses(pcs, plan, stats, 60.0, 0.15, taper_s)
    np.testing.assert_allclose(rested, _rest_every_frame(pcs, plan, stats, 60.0, 0.15, taper_s),
                               rtol=0, atol=1e-12)
    assert not np.array_equal(rested, pcs)


def test_rest_reads_only_the_frames_before_each():
    """A frame's rest weight does not change with what comes after it (a stream shows it before
    it knows more), a silence the input starts with rests from its first frame, and no speech
    frame rests."""
    rng = np.random.default_rng(3)
    silent = np.repeat(rng.random(40) < 0.5, 7)
    whole = rest_weights(silent, 60.0, 0.15, 0.05)
    for t in range(1, len(silent), 13):
        part = rest_weights(silent[:t], 60.0, 0.15, 0.05)
        assert np.array_equal(part, whole[:t])
    starts_silent = np.array([True] * 5 + [False] * 5)
    assert rest_weights(starts_silent, 60.0, 0.15, 0.05).tolist() == [1.0] * 5 + [0.0] * 5
    assert rest_weights(starts_silent, 60.0, 0.15, 0.05, leading=False).max() == 0.0
    assert whole[~silent].max() == 0.0


def test_a_silence_the_input_ends_in_reaches_the_rest_face_at_its_last_frame():
    """Issue 49 (defect 7): a silence shorter than a pause at the input's end still rests: its
    last ``end_frames`` rise to the rest face, the last at it; a pause's own weights stay, a
    speech frame at the end stays, and a silence in the middle is untouched."""
    ends_silent = np.array([True] * 20 + [False] * 30 + [True] * 6)
    w = rest_weights(ends_silent, 60.0, 0.15, 0.05, end_frames=3)
    plain = rest_weights(ends_silent, 60.0, 0.15, 0.05)
    assert plain[-6:].max() == 0.0                         # 100 ms: no pause by itself
    assert w[-1] == 1.0 and 0.0 < w[-3] < w[-2] < 1.0 and w[-4] == 0.0
    assert np.array_equal(w[:-3], plain[:-3])
    one = rest_weights(np.array([False] * 10 + [True]), 60.0, 0.15, 0.05, end_frames=3)
    assert one.tolist() == [0.0] * 10 + [1.0]              # one silent frame: at rest
    ends_in_speech = ends_silent.copy()
    ends_in_speech[-1] = False
    assert np.array_equal(rest_weights(ends_in_speech, 60.0, 0.15, 0.05, end_frames=3),
                          rest_weights(ends_in_speech, 60.0, 0.15, 0.05))


def test_arctic_files_rest_in_the_silences_they_begin_and_end_in(default_model):
    """Issue 49 (defect 7) on the real voices: every ARCTIC sample's first frame, and the last
    of each that ends in silence (100-200 ms of it), is at the rest face's lip aperture (the
    acoustic search: the rule reads the silence, not the search; a stream's ends equal these,
    tests/test_closure_detector.py)."""
    from facetraj.paths import shared_path
    from facetraj_engine.config import SynthConfig
    from facetraj_engine.evaluation.closure import lip_aperture
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.method.closure import aperture_functional
    from facetraj_engine.method.pipeline import synthesize
    from facetraj_engine.method.speech import speech_mask

    folder = shared_path("data/arctic_samples")
    if not folder.is_dir():
        pytest.skip(f"no {folder} (the CMU ARCTIC samples)")
    m = default_model
    a0, g = aperture_functional(m.pca, m.upper_lip, m.lower_lip)
    rest = a0 + m.closure.rest @ g
    ended_silent = 0
    for wav in sorted(folder.glob("*.wav")):
        audio, rate = read_audio(wav)
        res = synthesize(m, audio, rate, config=SynthConfig(mode="acoustic"))
        a = lip_aperture(res.markers, m.upper_lip, m.lower_lip)
        assert a[0] == pytest.approx(rest, abs=1e-6), wav.name
        if not speech_mask(audio, rate, res.times)[-1]:
            ended_silent += 1
            assert a[-1] == pytest.approx(rest, abs=1e-6), wav.name
            assert a[-2] > a[-1] + 1.0, wav.name             # risen to it, not there before
    assert ended_silent == 5
