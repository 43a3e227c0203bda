"""Streaming synthesis (facetraj_engine.streaming) equals offline synthesis; its parts equal their batch
forms; the speaker warp (facetraj_engine.method.speaker)."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.method.lsf import (
    ResampleStream,
    analysis_frames,
    frame_lsf,
    lsf_at,
    preemphasize,
    resample_audio,
)
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.smoothing import TriangularStream, triangular_smooth
from facetraj_engine.method.speaker import choose_warp, warp_lsf
from facetraj_engine.streaming.synthesizer import (
    LIVE_BATCH_FRAMES,
    StreamConfig,
    StreamingSynthesizer,
    stream_synthesize,
)

ACOUSTIC = SynthConfig(mode="acoustic", closure=False)   # the search alone (test_closure_detector: the step)


def _in_blocks(stream, x, sizes):
    out, a, k = [], 0, 0
    while a < len(x):
        b = a + sizes[k % len(sizes)]
        out.append(stream.feed(x[a:b]))
        a, k = b, k + 1
    out.append(stream.flush())
    return np.concatenate(out)


@pytest.mark.parametrize("rate", [44100, 48000, 8000, 22050])
def test_resample_stream_equals_resample_poly(rate):
    x = np.random.default_rng(rate).standard_normal(5003)
    whole = resample_audio(x, rate, 16000)
    for sizes in ([1], [7, 300, 1], [5003]):
        y = _in_blocks(ResampleStream(rate, 16000), x, sizes)
        assert y.shape == whole.shape
        np.testing.assert_allclose(y, whole, atol=1e-12)


def test_resample_stream_same_rate_passes_through():
    x = np.arange(10.0)
    assert _in_blocks(ResampleStream(16000, 16000), x, [3]).tolist() == x.tolist()


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 40])
def test_triangular_stream_equals_offline(n):
    x = np.random.default_rng(n).standard_normal((n, 4))
    for sizes in ([1], [2, 5], [n]):
        y = _in_blocks(TriangularStream(60.0), x, sizes)
        np.testing.assert_allclose(y, triangular_smooth(x, 60.0), atol=1e-12)


def test_triangular_stream_lookahead_is_three_frames_at_60_hz():
    s = TriangularStream(60.0)
    assert s.lookahead == 3
    assert len(s.feed(np.zeros((3, 1)))) == 0          # frame 0 waits for frame 3
    assert len(s.feed(np.zeros((1, 1)))) == 1
    assert len(TriangularStream(60.0, 0.0).feed(np.ones((2, 1)))) == 2   # no smoothing: no delay


def test_preemphasis_in_blocks_equals_whole():
    x = np.random.default_rng(1).standard_normal(100)
    parts = [preemphasize(x[:37], 0.97), preemphasize(x[37:], 0.97, previous=x[36])]
    np.testing.assert_allclose(np.concatenate(parts), preemphasize(x, 0.97), atol=1e-15)
    assert preemphasize(np.array([1.0, 1.0]), 0.97).tolist() == pytest.approx([1.0, 0.03])


def test_frame_lsf_equals_lsf_at():
    x = np.random.default_rng(2).standard_normal(16000)
    times = np.array([0.1, 0.5, 0.9])
    frames = analysis_frames(x, 16000, times, 0.025, 0.97)
    np.testing.assert_allclose(frame_lsf(frames, 18), lsf_at(x, 16000, times), atol=1e-12)


@pytest.fixture(scope="module")
def utterance(default_corpus):
    utt = default_corpus.utterance(default_corpus.info.test[0])
    return utt.audio, utt.sample_rate


def test_streamed_equals_offline_on_a_real_file(default_model, utterance):
    audio, rate = utterance
    offline = synthesize(default_model, audio, rate, None, ACOUSTIC)
    for block in (160, 441, rate):                       # 10 ms, an odd size, 1 s
        streamed = stream_synthesize(default_model, audio, rate, block, ACOUSTIC)
        assert streamed.index.tolist() == list(range(len(offline.times)))
        np.testing.assert_allclose(streamed.times, offline.times)
        np.testing.assert_allclose(streamed.pcs, offline.pcs, atol=1e-9)
        np.testing.assert_allclose(streamed.markers, offline.markers, atol=1e-9)


def test_block_sizes_from_one_sample_give_the_same_frames(default_model, utterance):
    audio, rate = utterance
    audio = audio[: rate * 3 // 4]                      # 0.75 s: one sample at a time is slow
    offline = synthesize(default_model, audio, rate, None, ACOUSTIC)
    for block in (1, 7):
        streamed = stream_synthesize(default_model, audio, rate, block, ACOUSTIC)
        np.testing.assert_allclose(streamed.pcs, offline.pcs, atol=1e-9)


def test_streamed_equals_offline_at_44k_unsmoothed_and_warped(default_model, utterance):
    audio, rate = utterance
    a44 = resample_audio(audio[: rate * 2], rate, 44100)
    cfg = ACOUSTIC.with_(smoothing="none", speaker_warp=0.9)
    offline = synthesize(default_model, a44, 44100, None, cfg)
    streamed = stream_synthesize(default_model, a44, 44100, 1000, cfg)
    assert offline.warp == 0.9
    np.testing.assert_allclose(streamed.pcs, offline.pcs, atol=1e-9)


def test_frames_come_out_after_the_documented_lookahead(default_model):
    stream = StreamingSynthesizer(default_model, StreamConfig(16000, ACOUSTIC))
    assert stream.lookahead_s == pytest.approx(0.0125 + 3 / 60)
    x = np.random.default_rng(3).standard_normal(16000) * 0.1
    got = stream.feed(x[:8000])                         # 0.5 s in
    # frame t is out when 0.5 s >= t / 60 + 0.0625 s: t <= 26
    assert got.index.tolist() == list(range(27))
    rest = stream.feed(x[8000:]).index.tolist() + stream.flush().index.tolist()
    assert rest == list(range(27, 61))                  # 1 s of audio: 61 frames, as offline


@pytest.mark.parametrize("batch", [1, LIVE_BATCH_FRAMES])
def test_frames_wait_for_the_silence_their_rest_reads(default_model, utterance, batch):
    """With the closure step a frame's rest reads the speech or silence of the 3 frames after it,
    each decided at most 68 ms after its time (half the 112 ms median filter, half the energy
    window, half a hop): a stream holds the frame until then, 118 ms, which live mode's batch of
    5 frames waits already (129 ms); its lookahead says so, and no frame comes out later."""
    from facetraj_engine.level import to_full_scale

    audio, rate = utterance
    audio = to_full_scale(audio)
    step = SynthConfig(mode="acoustic")
    stream = StreamingSynthesizer(default_model, StreamConfig(rate, step, batch))
    search = StreamingSynthesizer(default_model, StreamConfig(rate, step.with_(rest=False),
                                                              batch)).lookahead_s
    assert search == pytest.approx(0.0125 + (batch - 1 + 3) / 60)
    assert stream.closure.speech.delay_s == pytest.approx(0.068)
    assert stream.lookahead_s == pytest.approx(max(search, 0.068 + 3 / 60))
    block = rate // 100
    late = []
    for a in range(0, len(audio), block):
        frames = stream.feed(audio[a:a + block])
        late += list(stream.received_s - frames.times)
    assert max(late) <= stream.lookahead_s + block / rate + 1e-9
    if batch == 1:                                      # held beyond what the search needs
        assert max(late) > search + block / rate


def test_stream_refuses_spline_and_a_chosen_warp(default_model):
    with pytest.raises(ValueError, match="triangular"):
        StreamingSynthesizer(default_model, StreamConfig(16000, ACOUSTIC.with_(smoothing="spline")))
    with pytest.raises(ValueError, match="speaker_warp"):
        StreamingSynthesizer(default_model, StreamConfig(16000, ACOUSTIC.with_(speaker_warp=None)))


def test_too_short_stream_gives_no_frames(default_model):
    stream = StreamingSynthesizer(default_model, StreamConfig(16000, ACOUSTIC))
    assert len(stream.feed(np.zeros(100))) == 0
    assert len(stream.flush()) == 0


def test_warp_by_hand():
    # alpha 0.8: knee at 0.8 pi; below it w -> 0.8 w, above the line from (0.8 pi, 0.64 pi)
    # to (pi, pi): 0.9 pi -> 0.64 pi + 0.36 pi * 0.5 = 0.82 pi
    w = np.array([0.5, 1.0, 0.8 * np.pi, 0.9 * np.pi])
    np.testing.assert_allclose(warp_lsf(w, 0.8), [0.4, 0.8, 0.64 * np.pi, 0.82 * np.pi])
    # alpha 1.25: knee at 0.64 pi -> 0.8 pi; 0.82 pi -> 0.8 pi + 0.2 pi * 0.5 = 0.9 pi
    np.testing.assert_allclose(warp_lsf(np.array([1.0, 0.82 * np.pi]), 1.25),
                               [1.25, 0.9 * np.pi])
    ascending = warp_lsf(np.linspace(0.1, 3.1, 18), 1.2)
    assert np.all(np.diff(ascending) > 0) and ascending[-1] < np.pi
    assert warp_lsf(w, 1.0).tolist() == w.tolist()


def test_choose_warp_undoes_a_known_warp(default_model):
    cb = default_model.codebook.lsf
    frames = cb[np.random.default_rng(4).choice(len(cb), 300, replace=False)]
    assert choose_warp(frames, cb) == 1.0
    shorter = warp_lsf(frames, 1.15)                    # formants 15 % higher
    assert choose_warp(shorter, cb) == pytest.approx(1 / 1.15, abs=0.021)


def test_synthesize_chooses_the_warp_per_utterance(default_model, utterance):
    audio, rate = utterance
    res = synthesize(default_model, audio, rate, None, ACOUSTIC.with_(speaker_warp=None))
    assert 0.9 <= res.warp <= 1.1                       # the training voice needs about none


def test_batched_frames_are_the_same_frames_at_most_a_batch_later(default_model):
    x = np.random.default_rng(5).standard_normal(16000) * 0.1
    one = StreamingSynthesizer(default_model, StreamConfig(16000, ACOUSTIC))
    three = StreamingSynthesizer(default_model, StreamConfig(16000, ACOUSTIC, batch_frames=3))
    assert three.lookahead_s == pytest.approx(one.lookahead_s + 2 / 60)
    early = one.feed(x[:8000]).index.tolist()           # frames 0..26 (see above)
    late = three.feed(x[:8000]).index.tolist()
    assert late == early[:len(late)] and len(early) - 2 <= len(late) <= len(early)
    rest_one = np.concatenate([one.feed(x[8000:]).pcs, one.flush().pcs])
    rest_three = np.concatenate([three.feed(x[8000:]).pcs, three.flush().pcs])
    np.testing.assert_array_equal(three.raw_pcs, one.raw_pcs)
    assert len(rest_three) == len(rest_one) + len(early) - len(late)
    with pytest.raises(ValueError, match="batch_frames"):
        StreamConfig(16000, ACOUSTIC, batch_frames=0)
