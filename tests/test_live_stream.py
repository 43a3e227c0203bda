"""Live mode with phones (issue 27, facetraj_engine.streaming): the streamed recognizer, the phonetic stream
against offline synthesis, the streamed closure step against the offline one, speech and pauses
of a stream, the running voice match; a take's phones; long silence and clipping."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment
from facetraj_engine.labels.provenance import Labels
from facetraj_engine.level import to_full_scale
from facetraj_engine.method.closure import (
    ClosurePlan,
    aperture_functional,
    close_lips,
    closure_moves,
    rest_in_pauses,
    rest_weights,
)
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.speech import filtered_energy_db, silent_frames, speech_mask
from facetraj_engine.streaming.closure import ClosureStream, decided_silence
from facetraj_engine.streaming.live import LiveConfig, LiveStream, live_mode, stream_file
from facetraj_engine.streaming.phones import FrozenPhone, PhoneSnapshot, PhoneTrack
from facetraj_engine.streaming.phonetic import PhoneticSynthesizer, PhoneticTiming
from facetraj_engine.streaming.recognizer import CMN_INIT, RecognizerConfig, RunningCmn, StreamingRecognizer
from facetraj_engine.streaming.speech import SILENT, SPEECH, UNRANGED, SpeechStream

pytest.importorskip("pocketsphinx")

#: real voices, read from ../shared when present (never copied)
ARCTIC = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "arctic_samples"


@pytest.fixture
def arctic_wav() -> Path:
    wav = ARCTIC / "cmu_arctic_us_axb_a0006.wav"
    if not wav.exists():
        pytest.skip(f"no {wav} (the CMU ARCTIC samples beside the repository)")
    return wav


@pytest.fixture(scope="module")
def utterance(default_corpus):
    utt = default_corpus.utterance(default_corpus.info.test[0])
    return utt.audio, utt.sample_rate, utt.phones


def _feed(stream, audio, block):
    parts = [stream.feed(audio[a:a + block]) for a in range(0, len(audio), block)]
    parts.append(stream.flush())
    return np.concatenate([p.pcs for p in parts]), np.concatenate([p.times for p in parts])


# --------------------------------------------------------------------------- recognizer
def test_recognized_phones_do_not_depend_on_the_block_size(utterance):
    audio, rate, _ = utterance
    tracks = []
    for block in (160, 1003, rate):
        rec = StreamingRecognizer(rate)
        for a in range(0, len(audio), block):
            rec.feed(audio[a:a + block])
        rec.flush()
        tracks.append([(p.start, p.end, p.label, p.agree, p.seen) for p in rec.track.phones])
    assert tracks[0] == tracks[1] == tracks[2]
    phones = tracks[0]
    assert phones[0][0] == 0 and all(a[1] == b[0] for a, b in pairwise(phones))
    assert phones[-1][1] == -(-len(audio) * 16000 // rate // 160)     # every 10 ms frame settled
    assert sum(p[2] != "sil" for p in phones) > 10                      # it heard the sentence


def test_settled_phones_lag_the_audio_by_the_settle_age(utterance):
    audio, rate, _ = utterance
    for settle in (0.05, 0.1):
        rec = StreamingRecognizer(rate, RecognizerConfig(settle_s=settle))
        lags = []
        for a in range(0, rate, rate // 100):
            rec.feed(audio[a:a + rate // 100])
            lags.append((a + rate // 100) / rate - rec.track.settled_s)
        # the decoder's front is ~40 ms behind the audio, its hypothesis ~10 ms behind its front
        assert settle + 0.03 <= np.median(lags[30:]) <= settle + 0.07


def test_running_cepstral_mean_is_recovered_from_what_pocketsphinx_reports():
    # frames of cepstra [60, 1, ...] decoded after the mean was set to the initial one
    true = np.array([60.0, 1.0] + [0.0] * 11)
    reported = (500 * CMN_INIT + 20 * true) / 520           # PocketSphinx's sum over its count
    from facetraj_engine.streaming.recognizer import held_sum
    np.testing.assert_allclose(held_sum(reported, CMN_INIT, 20) / 20, true, atol=1e-9)
    plain = RunningCmn(prior_frames=0, speech_share=None)
    plain.add(20 * true, 20)
    np.testing.assert_allclose(plain.mean, true)


def test_frame_cepstra_average_to_the_mean_offline_recognition_removes(utterance):
    from facetraj_engine.evaluation.live_eval import frame_cepstra
    from facetraj_engine.labels.alignment import allphone_decoder

    audio, rate, _ = utterance
    assert rate == 16000
    cepstra = frame_cepstra(audio, rate)
    assert abs(len(cepstra) - len(audio) / rate / 0.01) <= 6          # every 10 ms frame
    decoder = allphone_decoder()                                         # batch CMN, full_utt
    decoder.start_utt()
    decoder.process_raw((np.clip(audio, -1, 1) * 32767).astype("<i2").tobytes(), False, True)
    decoder.end_utt()
    batch = np.array([float(x) for x in decoder.get_cmn(False).split(",")])
    np.testing.assert_allclose(cepstra.mean(axis=0), batch, atol=0.5)


def test_a_prior_of_some_frames_brings_the_running_mean_nearest_the_whole_mean(utterance):
    from facetraj_engine.evaluation.live_eval import frame_cepstra, prior_count_errors
    from facetraj_engine.streaming.recognizer import CMN_PRIOR_FRAMES

    audio, rate, _ = utterance
    errors = prior_count_errors([frame_cepstra(audio, rate)], [0.0, CMN_PRIOR_FRAMES, 1000.0])
    # no prior: the first blocks' mean is the silence's; a rigid one: PocketSphinx's initial mean
    assert errors[CMN_PRIOR_FRAMES] < min(errors[0.0], errors[1000.0])
    assert RecognizerConfig().cmn_prior_frames == RunningCmn().prior == CMN_PRIOR_FRAMES


def test_streamed_phones_agree_with_themselves(utterance):
    from facetraj_engine.evaluation.live_eval import phone_agreement, streamed_phones

    audio, rate, _ = utterance
    phones = streamed_phones(audio, rate)
    assert sum(p.label != "sil" for p in phones) > 10
    assert phone_agreement({"u": (audio, rate)}, offline={"u": phones}) == 1.0


def test_running_mean_weighs_speech_as_a_sentence_does():
    cmn = RunningCmn(prior_frames=0, speech_share=0.8)
    quiet, loud = np.full(13, 30.0), np.full(13, 60.0)
    for _ in range(30):                                      # a long silence first
        cmn.add(5 * quiet, 5)
    for _ in range(3):
        mean = cmn.add(5 * loud, 5)
    assert mean[0] == pytest.approx(0.8 * 60 + 0.2 * 30)     # not the plain mean (~33)


# --------------------------------------------------------------------------- the phonetic stream
class _Known:
    """Every phone known from the start (as if the recognizer were infinitely fast)."""

    def __init__(self, phones, confidence):
        self.track = PhoneTrack()
        for p, c in zip(phones, confidence, strict=True):
            self.track.phones.append(FrozenPhone(int(round(p.start * 100)), int(round(p.end * 100)),
                                                 p.label, int(round(c * 1000)), 1000))
        self.track.frozen = self.track.phones[-1].end
        self.settled_s = self.track.settled_s

    def snapshot(self, since_s=0.0, before=0):
        return self.track.snapshot(since_s, before)


class _Never:
    settled_s = 0.0

    def snapshot(self, since_s=0.0, before=0):
        return PhoneSnapshot([], np.zeros(0), 0.0)


def _frame_aligned(phones, duration):
    """Phones on the recognizer's 10 ms grid, with its arithmetic (as streamed phones are)."""
    grid = [(int(round(p.start * 100)), int(round(p.end * 100)), p.label) for p in phones]
    grid = [g for g in grid if g[1] > g[0]]
    grid[-1] = (grid[-1][0], int(np.ceil(duration * 100)), grid[-1][2])
    return [PhoneSegment(a * 0.01, b * 0.01, lab) for a, b, lab in grid]


def test_phonetic_stream_with_every_phone_known_equals_offline_robust_synthesis(
        default_model, utterance):
    audio, rate, phones = utterance
    phones = _frame_aligned(phones, len(audio) / rate)
    conf = np.linspace(0.3, 1.0, len(phones))
    cfg = live_mode(SynthConfig(closure=False, label_weight_by_voice=False), default_model).config
    assert cfg.mode == "robust"
    offline = synthesize(default_model, audio, rate, phones, cfg,
                         confidence=np.round(conf * 1000) / 1000)
    for block in (160, 4410):
        stream = PhoneticSynthesizer(default_model, rate, cfg, _Known(phones, conf),
                                     PhoneticTiming(wait_s=0.3, batch=3))
        pcs, times = _feed(stream, audio, block)
        np.testing.assert_allclose(times, offline.times)
        np.testing.assert_allclose(pcs, offline.pcs, atol=1e-9)
        assert all(stream.labelled)


def test_frames_without_a_settled_phone_are_acoustic_only(default_model, utterance):
    audio, rate, _ = utterance
    cfg = live_mode(SynthConfig(closure=False), default_model).config
    offline = synthesize(default_model, audio, rate, None, cfg.with_(mode="acoustic"))
    stream = PhoneticSynthesizer(default_model, rate, cfg, _Never())
    pcs, _ = _feed(stream, audio, 160)
    np.testing.assert_allclose(pcs, offline.pcs, atol=1e-9)
    assert not any(stream.labelled)


def test_frames_come_out_within_the_lookahead(default_model, utterance):
    audio, rate, _ = utterance
    stream = LiveStream(default_model, rate)
    block = rate // 100
    late = []
    for a in range(0, len(audio), block):
        frames = stream.feed(audio[a:a + block])
        late += list(stream.received_s - frames.times)
    assert 0.2 < stream.lookahead_s < 0.25
    assert max(late) <= stream.lookahead_s + block / rate + 1e-9
    assert stream.labelled_share > 0.95                       # the recognizer keeps up


# --------------------------------------------------------------------------- the closure step
def test_streamed_closure_with_every_frame_known_is_the_offline_step(default_model):
    rng = np.random.default_rng(5)
    k = default_model.codebook.pcs.shape[1]
    pcs = np.cumsum(rng.standard_normal((120, k)) * 0.3, axis=0)
    times = np.arange(120) / 60
    silent = np.zeros(120, dtype=bool)
    silent[36:57] = True
    plan = ClosurePlan(np.array([[0.30, 0.42], [1.1, 1.2]]), np.array([1.0, 0.6]), silent)
    stats = default_model.closure
    a0, g = aperture_functional(default_model.pca, default_model.upper_lip, default_model.lower_lip)
    offline = rest_in_pauses(close_lips(pcs, times, plan, stats, a0, g, 0.05), plan, stats, 60.0,
                             0.1, 0.05, 3)
    c = closure_moves(a0 + pcs @ g, times, plan.intervals, plan.strengths, stats.closed, 0.05,
                      np.full(120, 119))
    b = rest_weights(silent, 60.0, 0.1, 0.05, ahead=3)
    moved = pcs + c[:, None] * stats.direction[None, :]
    np.testing.assert_allclose(moved + b[:, None] * (stats.rest - moved), offline, atol=1e-9)
    assert b[36:39].max() == 0.0 and b[41:57].min() == 1.0 and b[57:].max() == 0.0
    # held long enough to see each /p b m/ whole, the stream makes the same moves and rests
    stream = ClosureStream(default_model, hold=30)
    out = np.concatenate([stream.feed(pcs[a:a + 7], plan) for a in range(0, 120, 7)] +
                         [stream.feed(np.zeros((0, k)), plan, final=True)])
    a_out, a_off = a0 + out @ g, a0 + offline @ g
    inside = ((times >= 0.30) & (times < 0.42)) | ((times >= 1.1) & (times < 1.2))
    assert a_out[inside].min() == pytest.approx(a_off[inside].min(), abs=1e-9)
    np.testing.assert_allclose(out[40:60], offline[40:60], atol=1e-9)     # the pause alike


def test_causal_intervals_are_the_streams_closures(default_model):
    """The detector's closures (causal intervals): the offline step and a stream that knows each
    frame's own fate only when it shows it make the same face, frame for frame."""
    rng = np.random.default_rng(9)
    k = default_model.codebook.pcs.shape[1]
    pcs = np.cumsum(rng.standard_normal((150, k)) * 0.4, axis=0)
    times = np.arange(150) / 60
    iv = np.array([[0.25, 0.40], [1.0, 1.1], [2.0, 2.3]])
    plan = ClosurePlan(iv, np.ones(3), np.zeros(150, dtype=bool), causal=np.ones(3, dtype=bool))
    stats = default_model.closure
    a0, g = aperture_functional(default_model.pca, default_model.upper_lip, default_model.lower_lip)
    offline = close_lips(pcs, times, plan, stats, a0, g, 0.05)
    stream = ClosureStream(default_model, hold=0)
    out = []
    for a in range(0, 150, 4):      # a closure and its end are known once their frames are shown
        shown = (a + 3) / 60 + 1e-9
        known = iv[iv[:, 0] <= shown].copy()
        known[:, 1] = np.where(known[:, 1] <= shown, known[:, 1], np.inf)
        out.append(stream.feed(pcs[a:a + 4], ClosurePlan(known, np.ones(len(known)),
                                                         causal=np.ones(len(known), dtype=bool))))
    np.testing.assert_allclose(np.concatenate(out), offline, atol=1e-9)
    before = (times >= 0.25 - 0.05) & (times < 0.25)
    np.testing.assert_array_equal(offline[before], pcs[before])        # no taper before it


def test_causal_closure_closes_each_bilabial_and_never_past_closed():
    a = np.array([16.0, 15.0, 14.0, 13.5, 15.0, 12.0, 17.0, 18.0])
    t = np.arange(8) / 10
    c = closure_moves(a, t, np.array([[0.2, 0.5]]), np.array([1.0]), 11.0, 0.15, np.arange(8),
                      clamp=True)
    closed = a + c
    assert closed[2] == pytest.approx(11.0)                    # its first frame closes
    assert closed[2:5].min() == pytest.approx(11.0)
    assert (closed >= np.minimum(a, 11.0) - 1e-12).all()       # nothing pressed past closed


def test_silence_of_a_stream():
    d = [UNRANGED] * 3 + [SPEECH] * 5 + [SILENT] * 4 + [SPEECH] * 2
    silent, leading = decided_silence(d, 0)
    assert silent.tolist() == [True] * 3 + [False] * 5 + [True] * 4 + [False] * 2 and leading
    silent, leading = decided_silence(d, 8)
    assert silent.tolist() == [True] * 4 + [False] * 2 and not leading
    # before the energy is ranged, the recognizer's silence says (live mode with phones)
    silent, _ = decided_silence(d, 0, lambda t: t < 0.02, 60.0)
    assert silent[:3].tolist() == [True, True, False]


# --------------------------------------------------------------------------- speech, voice
def test_speech_stream_filters_the_energy_as_offline(utterance):
    audio, rate, _ = utterance
    audio = to_full_scale(audio)        # a file is streamed at this level (offline: any level)
    times = np.arange(int(np.floor(len(audio) / rate * 60)) + 1) / 60
    offline = filtered_energy_db(audio, rate)
    for block in (160, 997, rate):
        s = SpeechStream(rate, 60.0)
        for a in range(0, len(audio), block):
            s.feed(audio[a:a + block])
        s.flush(len(times))
        np.testing.assert_allclose(s.filtered, offline[-len(s.filtered):], atol=1e-9)
        assert s.known == len(times)
    d = np.array(s.decisions)
    mask = speech_mask(audio, rate, times)
    ranged = d != UNRANGED
    assert ranged.mean() > 0.8 and ((d == SPEECH) == mask)[ranged].mean() > 0.95
    silent, _ = decided_silence(d, 0)
    offline = silent_frames(audio, rate, times)
    assert (silent == offline)[ranged].mean() > 0.95


def test_running_voice_ratio_approaches_the_offline_one(default_model, arctic_wav):
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.method.pipeline import input_voice_ratio

    audio, rate = read_audio(arctic_wav)
    stream = LiveStream(default_model, rate)
    for a in range(0, len(audio), 160):
        stream.feed(audio[a:a + 160])
    stream.flush()
    offline = input_voice_ratio(default_model, audio, rate)
    assert offline > 3.0                                     # not the training voice
    assert stream.voice_ratio == pytest.approx(offline, rel=0.2)
    assert stream.voice_match == 0.0 and stream.label_scale == pytest.approx(stream.voice_ratio)


# --------------------------------------------------------------------------- a take
def test_a_file_through_live_mode_keeps_its_phones(default_model, arctic_wav, tmp_path):
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.io.labelfiles import read_label_file
    from facetraj_engine.io.labelling import write_labels

    audio, rate = read_audio(arctic_wav)
    take = stream_file(default_model, audio, rate, 0.01)
    n = int(np.floor(len(audio) / rate * 60)) + 1
    assert len(take.frames) == n and take.frames.index.tolist() == list(range(n))
    labels = take.labels
    assert isinstance(labels, Labels) and labels.provenance.kind == "recognized"
    assert labels.phones[0].start == 0 and labels.phones[-1].end == pytest.approx(len(audio) / rate)
    assert {"p", "b", "m"} & {p.label for p in labels.phones}
    assert ((labels.confidence > 0) & (labels.confidence <= 1)).all()
    write_labels(tmp_path / "take.TextGrid", labels, len(audio) / rate)
    back = read_label_file(tmp_path / "take.TextGrid", rate, len(audio) / rate)
    assert back.provenance.kind == "recognized" and "streamed" in back.provenance.tool
    assert [p.label for p in back.phones] == [p.label for p in labels.phones]
    np.testing.assert_allclose(back.confidence, labels.confidence, atol=1e-3)
    # the same file again: the same face (the recognizer runs in step with the blocks)
    again = stream_file(default_model, audio, rate, 0.1)
    np.testing.assert_allclose(again.frames.pcs, take.frames.pcs, atol=1e-9)


def test_threaded_recognizer_gives_a_whole_take(default_model, utterance):
    audio, rate, _ = utterance
    stream = LiveStream(default_model, rate, threaded=True)
    n = 0
    for a in range(0, len(audio), 441):
        n += len(stream.feed(audio[a:a + 441]))
    n += len(stream.flush())
    assert n == int(np.floor(len(audio) / rate * 60)) + 1
    assert stream.recognition_error is None
    assert stream.labels(len(audio) / rate).phones[-1].end == pytest.approx(len(audio) / rate)


@pytest.mark.parametrize("kind", ["silence", "clipping"])
def test_a_minute_of_silence_or_clipping_streams_with_bounded_state(default_model, kind):
    rate = 16000
    t = np.arange(60 * rate) / rate
    audio = np.zeros_like(t) if kind == "silence" else np.sign(np.sin(2 * np.pi * 180 * t)) * \
        (1 + 0.5 * np.sin(2 * np.pi * 3 * t))                              # beyond full scale
    stream = LiveStream(default_model, rate, config=LiveConfig(
        recognizer=RecognizerConfig(max_utterance_s=10.0)))
    frames = 0
    for a in range(0, len(audio), rate // 10):
        out = stream.feed(audio[a:a + rate // 10])
        frames += len(out)
        assert np.isfinite(out.markers).all()
    frames += len(stream.flush())
    assert frames == 60 * 60 + 1
    rec = stream.recognizer
    assert rec.restarts >= 4                                  # utterances of at most 10 s
    assert len(rec.track.phones) < 2000


def test_a_device_at_44_1_khz_streams_with_phones(default_model, utterance):
    from facetraj_engine.method.lsf import resample_audio

    audio, rate, _ = utterance
    a44 = resample_audio(audio, rate, 44100)
    take = stream_file(default_model, a44, 44100, 0.01)
    here = stream_file(default_model, audio, rate, 0.01)
    assert len(take.frames) == len(here.frames)
    # 44.1 kHz is resampled to 16 kHz for the recognizer: nearly the same phones, frame by frame
    from facetraj_engine.evaluation.live_eval import frame_labels

    n = int(len(audio) / rate * 100)
    alike = np.mean(frame_labels(take.labels.phones, n) == frame_labels(here.labels.phones, n))
    assert alike > 0.8
