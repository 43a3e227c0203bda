"""The closure step's per-interval work (``facetraj_engine.method.closure``): each interval touches
only its own frames, with results equal to the bit to the formula over every frame; the rest in
pauses read from the frames before each and the few after it, equal to the rule written frame by
frame; and on the real voices, the silence a recording ends in rests as a pause does, in every
search, offline and live."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.method.closure import (
    ClosurePlan,
    ClosureStats,
    bump,
    close_lips,
    frame_rest,
    rest_ahead_frames,
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


def _rest_every_frame(pcs, plan, stats, rate, min_s, taper_s, ahead=0):
    """The rest rule frame by frame: on a silent frame t, the silence seen -- counted back to the
    last speech frame (or to the input's start: long already), and on over the next ``ahead``
    frames while they are silent (from the plan's ``end`` on, every frame is; beyond the decided
    ones, none) -- against ``min_s`` and the taper; none on a speech frame."""
    def silent(k):
        if plan.end is not None and k >= plan.end:
            return True
        return k < len(plan.silent) and bool(plan.silent[k])

    b = np.zeros(len(pcs))
    for t in range(len(pcs)):
        if not silent(t):
            continue
        k, length = t, 0
        while k >= 0 and silent(k):
            length, k = length + 1, k - 1
        if k < 0:
            b[t] = 1.0
            continue
        k = t + 1
        while k <= t + ahead and silent(k):
            length, k = length + 1, k + 1
        if taper_s > 0:
            x = min(max((length / rate - min_s) / taper_s, 0.0), 1.0)
            b[t] = 0.5 * (1 - np.cos(np.pi * x))
        else:
            b[t] = float(length / rate > min_s)
    return pcs + b[:, None] * (stats.rest[None, :] - pcs)


def _plan(rng, duration: float, n: int, ended: bool = False) -> ClosurePlan:
    """Random intervals: some shorter than a frame, some at the input's ends or beyond, some
    overlapping; silences of 1-5 frames and 10 or more (``ended``: the input ends after the
    last decided frame)."""
    starts = rng.uniform(-0.05, duration, n)
    lengths = np.where(rng.random(n) < 0.3, rng.uniform(0, 0.01, n), rng.uniform(0.02, 0.3, n))
    intervals = np.column_stack([starts, starts + lengths])
    count = int(duration * 60) + 1
    silent = np.repeat(rng.random(count // 10 + 1) < 0.4, 10)[:count]
    silent[rng.integers(0, count, count // 12)] = True            # short silences too
    silent[-1] = True
    return ClosurePlan(intervals, rng.uniform(0, 1, n), silent, end=count if ended else None)


@pytest.mark.parametrize("ahead,ended", [(0, False), (3, False), (3, True), (7, True)])
@pytest.mark.parametrize("taper_s", [0.0, 0.016, 0.05, 0.3])
@pytest.mark.parametrize("seed", range(4))
def test_closure_step_equals_the_formula_over_every_frame(seed: int, taper_s: float, ahead: int,
                                                          ended: bool) -> None:
    rng = np.random.default_rng(seed)
    times = np.arange(600) / 60.0
    k = 6
    pcs = rng.standard_normal((len(times), k)) * 5
    stats = ClosureStats(-3.0, rng.standard_normal(k), rng.standard_normal(k))
    g = rng.standard_normal(k)
    plan = _plan(rng, times[-1], 40, ended)
    got = close_lips(pcs, times, plan, stats, 0.5, g, taper_s)
    assert np.array_equal(got, _close_lips_every_frame(pcs, times, plan, stats, 0.5, g, taper_s))
    assert not np.array_equal(got, pcs)                       # the intervals moved the lips
    rested = rest_in_pauses(pcs, plan, stats, 60.0, 0.1, taper_s, ahead)
    np.testing.assert_allclose(rested, _rest_every_frame(pcs, plan, stats, 60.0, 0.1, taper_s, ahead),
                               rtol=0, atol=1e-12)
    assert not np.array_equal(rested, pcs)


def test_rest_reads_only_the_frames_before_each_and_its_lookahead():
    """A frame's rest weight does not change with what comes more than ``ahead`` frames after
    it (a stream shows it once those are decided), a silence the input starts with rests from
    its first frame, and no speech frame rests."""
    rng = np.random.default_rng(3)
    silent = np.repeat(rng.random(40) < 0.5, 7)
    silent[rng.integers(0, len(silent), 30)] ^= True
    for ahead in (0, 3):
        whole = rest_weights(silent, 60.0, 0.1, 0.05, ahead=ahead)
        for t in range(1, len(silent) - ahead, 13):
            part = rest_weights(silent[:t + ahead], 60.0, 0.1, 0.05, ahead=ahead)
            assert np.array_equal(part[:t], whole[:t])
        assert whole[~silent].max() == 0.0 and whole.max() == 1.0
    starts_silent = np.array([True] * 5 + [False] * 5)
    assert rest_weights(starts_silent, 60.0, 0.1, 0.05, ahead=3).tolist() == [1.0] * 5 + [0.0] * 5
    assert rest_weights(starts_silent, 60.0, 0.1, 0.05, leading=False, ahead=3).max() == 0.0


def test_the_default_rest_by_hand():
    """The defaults at 60 Hz (pause over 100 ms, 50 ms taper, 3 frames read ahead): after a
    speech frame, a silence's frames see themselves and the 3 after them: 4, 5, 6 frames (up to
    100 ms: no pause), then 7 (117 ms: x = 1/3, 0.25), 8 (0.75), 9 (150 ms: at rest), so the
    face rests from the 6th silent frame (100 ms after the last speech frame) on. A silence of
    3-6 frames (50-100 ms: a stop closure) between speech frames never rests."""
    c = SynthConfig()
    assert (c.rest_pause_s, c.rest_taper_s, rest_ahead_frames(c.rest_lookahead_s, 60.0)) == \
        (0.1, 0.05, 3)
    pause = np.array([False] * 5 + [True] * 12 + [False])
    w = rest_weights(pause, 60.0, 0.1, 0.05, ahead=3)
    assert w.round(6).tolist() == [0.0] * 5 + [0.0, 0.0, 0.0, 0.25, 0.75] + [1.0] * 7 + [0.0]
    for n in range(1, 7):
        closure = np.array([False] * 5 + [True] * n + [False] * 5)
        assert rest_weights(closure, 60.0, 0.1, 0.05, ahead=3).max() == 0.0, n
    seven = np.array([False] * 5 + [True] * 7 + [False] * 5)
    assert rest_weights(seven, 60.0, 0.1, 0.05, ahead=3).max() == pytest.approx(0.25)


def test_a_silence_the_input_ends_in_rests_as_a_pause_that_goes_on():
    """Outside the input is silence: the silence a recording ends in rests, frame for frame, as
    the same silence does when more silence follows it, however short it is; before its end is
    known (a stream), the frames after the decided ones are not silent; a recording that ends in
    speech ends as it would with speech after it."""
    for n in (1, 3, 6, 12):
        ends = np.array([False] * 8 + [True] * n)
        on = np.concatenate([ends, [True] * 10])
        w = rest_weights(ends, 60.0, 0.1, 0.05, ahead=3, ended=True)
        assert np.array_equal(w, rest_weights(on, 60.0, 0.1, 0.05, ahead=3)[:len(ends)]), n
        undecided = rest_weights(ends, 60.0, 0.1, 0.05, ahead=3)
        assert np.array_equal(undecided, rest_weights(np.concatenate([ends, [False] * 3]), 60.0,
                                                      0.1, 0.05, ahead=3)[:len(ends)])
    six = rest_weights(np.array([False] * 8 + [True] * 6), 60.0, 0.1, 0.05, ahead=3, ended=True)
    assert six[-3:].round(6).tolist() == [0.25, 0.75, 1.0]       # at rest 100 ms after speech
    assert six[:-3].max() == 0.0
    speech_end = np.array([True] * 4 + [False] * 4)
    assert np.array_equal(rest_weights(speech_end, 60.0, 0.1, 0.05, ahead=3, ended=True),
                          rest_weights(np.concatenate([speech_end, [False] * 3]), 60.0, 0.1,
                                       0.05, ahead=3)[:8])
    plan = ClosurePlan(np.zeros((0, 2)), np.zeros(0), np.array([False] * 8 + [True] * 6), end=14)
    assert np.array_equal(frame_rest(plan, 14, 60.0, 0.1, 0.05, ahead=3), six)
    assert frame_rest(plan, 3, 60.0, 0.1, 0.05, first=11, ahead=3).round(6).tolist() == \
        [0.25, 0.75, 1.0]                                           # a stream's last frames
    assert frame_rest(replace(plan, end=None), 14, 60.0, 0.1, 0.05, ahead=3).max() == 0.0


#: Every search a recording gets, with the labels it gets: (offline or live, settings, labels:
#: aligned from the recording's ``.txt``, recognized, or none).
SEARCHES = {
    "phonetic, aligned": ("offline", SynthConfig(mode="phonetic"), "aligned"),
    "phonetic, recognized": ("offline", SynthConfig(mode="phonetic"), "recognized"),
    "robust, aligned": ("offline", SynthConfig(mode="robust"), "aligned"),
    "robust, recognized": ("offline", SynthConfig(mode="robust"), "recognized"),
    "acoustic-only": ("offline", SynthConfig(mode="acoustic"), None),
    "acoustic-only, detector": ("offline", SynthConfig(mode="acoustic", closure_detector=True), None),
    "live, aligned": ("live", SynthConfig(), "aligned"),
    "live, recognized": ("live", SynthConfig(), "recognized"),
    "live, acoustic-only": ("live", SynthConfig(), None),
    "live, acoustic-only, detector": ("live", SynthConfig(closure_detector=True), None),
}


@pytest.mark.parametrize("search", list(SEARCHES))
def test_arctic_files_rest_in_the_silences_they_begin_and_end_in(default_model, search):
    """The real voices (six CMU ARCTIC sentences), as ``facetraj synth`` makes them and as live
    mode streams them (``facetraj live --from-file``: blocks of 10 ms): every frame from 100 ms
    after the last speech frame (by energy, as the evaluation's) to the end is within 1 mm of
    the rest face's lip aperture, and offline the first frame is at it. Three end in 150-200 ms of
    silence (18 frames checked), two in 100 ms (their last frame), one in speech."""
    from facetraj.paths import shared_path
    from facetraj_engine.evaluation.closure import lip_aperture
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.io.label_rule import LabelRequest, resolve_labels
    from facetraj_engine.method.closure import aperture_functional
    from facetraj_engine.method.speech import speech_mask
    from facetraj_engine.streaming.live import LiveConfig, stream_file
    from facetraj_engine.workflow.recording import synthesize_recording

    folder = shared_path("data/arctic_samples")
    if not folder.is_dir():
        pytest.skip(f"no {folder} (the CMU ARCTIC samples)")
    how, config, labels = SEARCHES[search]
    m = default_model
    a0, g = aperture_functional(m.pca, m.upper_lip, m.lower_lip)
    rest = a0 + m.closure.rest @ g
    checked = 0
    for wav in sorted(folder.glob("*.wav")):
        audio, rate = read_audio(wav)
        request = LabelRequest(transcript=wav.with_suffix(".txt") if labels == "aligned" else None,
                               recognize=labels == "recognized")
        if how == "offline":
            res = synthesize_recording(m, wav, config, request, explicit=True, audio=(audio, rate))
            markers, times = res.synthesis.markers, res.synthesis.times
            assert res.labels is None or res.labels.provenance.kind == labels, wav.name
        else:
            known = resolve_labels(wav, audio, rate, request).labels if labels == "aligned" else None
            take = stream_file(m, audio, rate, 0.01, config, LiveConfig(phones=labels is not None),
                               labels=known)
            markers, times = take.frames.markers, take.frames.times
        a = lip_aperture(markers, m.upper_lip, m.lower_lip)
        if how == "offline":   # a stream's first frames follow its own first decisions
            assert a[0] == pytest.approx(rest, abs=1e-6), wav.name
        last = times[np.flatnonzero(speech_mask(audio, rate, times))[-1]]
        after = times >= last + 0.1 - 1e-9
        checked += int(after.sum())
        worst = np.abs(a[after] - rest).max(initial=0.0)
        assert worst <= 1.0, f"{wav.name}: {worst:.2f} mm from the rest aperture {rest:.2f} mm " \
                             f"after {last + 0.1:.3f} s ({search})"
    assert checked == 20
