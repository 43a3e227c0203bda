"""The bilabial-closure detector (``facetraj_engine.method.closure_detector``, issue 40): its
features by hand, its regression, the closures it finds without phones on held-out sentences, on
their second voice and on real voices, the stream equal to offline, and model files with and
without it."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from conftest import edited_model_file

from facetraj.paths import shared_path
from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment, Provenance
from facetraj_engine.evaluation.closure import (
    ClosureScore,
    DetectorScore,
    closure_score,
    detector_score,
    lip_aperture,
)
from facetraj_engine.evaluation.second_voice import second_voice
from facetraj_engine.method.closure_detector import (
    ClosureDetector,
    DetectorSpec,
    Logistic,
    closure_runs,
    detector_features,
    fit_logistic,
    input_probability,
)
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.streaming.detector import DetectorStream
from facetraj_engine.streaming.front import LsfFront
from facetraj_engine.streaming.live import LiveConfig, stream_file

ACOUSTIC = SynthConfig(mode="acoustic", closure_detector=True)
ARCTIC = shared_path("data/arctic_samples")


# --------------------------------------------------------------------------- by hand
def test_features_of_three_frames_by_hand():
    """Energies 0, -40, 0 dB (a closure between two vowels), the lowest LSF 2, 0.5, 1 rad, the
    training voice's mean log LSF 0 worth one frame, the frames one either side."""
    spec = DetectorSpec(back=2, n_lsf=1, prior_frames=1.0, offsets=(-1, 0, 1))
    lsf = np.array([[2.0, 3.0], [0.5, 3.0], [1.0, 3.0]])
    x = detector_features(lsf, np.array([0.0, -40.0, 0.0]), spec, np.array([0.0]))
    ln2 = np.log(2.0)
    # dips 0, -30 (the floor), 0; gates 1, 0, 1; running means ln2/2, ln2/2, ln2/3
    rows = [[0.0, ln2 / 2], [-30.0, 0.0], [0.0, -ln2 / 3]]
    expected = [rows[0] + rows[0] + rows[1], rows[0] + rows[1] + rows[2], rows[1] + rows[2] + rows[2]]
    np.testing.assert_allclose(x, expected, atol=1e-12)


def test_the_search_counts_by_the_voice_match():
    """An acoustic part at p = 1/2 and a search part at p = 3/4 (logit ln 3): the training voice
    gets the search's, another voice the acoustic one's, halfway a voice between them."""
    acoustic = Logistic(np.zeros(1), np.ones(1), np.array([1.0]), 0.0)
    search = Logistic(np.zeros(2), np.ones(2), np.array([0.0, 1.0]), 0.0)
    det = ClosureDetector(DetectorSpec(n_lsf=1, offsets=(0,)), np.zeros(1), acoustic, search)
    x, xs = np.zeros((1, 1)), np.full((1, 1), np.log(3.0))
    got = [det.probability(x, xs, m)[0] for m in (0.0, 1.0, 0.5, float("nan"))]
    np.testing.assert_allclose(got, [0.5, 0.75, 0.625, 0.5])


def test_logistic_regression_recovers_the_model_that_made_the_data():
    rng = np.random.default_rng(3)
    x = rng.standard_normal((20000, 3))
    truth, bias = np.array([1.5, -2.0, 0.0]), -1.0
    y = rng.random(20000) < 1.0 / (1.0 + np.exp(-(x @ truth + bias)))
    beta, b = fit_logistic(x, y, ridge=0.0)
    np.testing.assert_allclose(beta, truth, atol=0.08)
    assert b == pytest.approx(bias, abs=0.06)
    shrunk, _ = fit_logistic(x, y, ridge=20000.0)                 # the penalty pulls towards 0
    assert np.all(np.abs(shrunk) < np.abs(beta) + 1e-9) and abs(shrunk[0]) < 0.7 * abs(beta[0])


def test_closures_are_runs_of_two_frames_or_more():
    p = np.array([0.2, 0.9, 0.1, 0.5, 0.6, 0.7, 0.0, 0.8, 0.8])
    t = np.arange(9) / 10
    assert closure_runs(p, t, 0.5).tolist() == [[0.3, 0.6], [0.7, 0.9]]
    assert closure_runs(p, t, 0.5, open_end=True)[-1, 1] == np.inf         # still going on
    assert closure_runs(p, t, 0.95).shape == (0, 2)


# --------------------------------------------------------------------------- what it finds
def _pooled(model, items, config=ACOUSTIC):
    scores, found = [], []
    for audio, rate, phones, n in items:
        res = synthesize(model, audio, rate, None, config, n_frames=n)
        a = lip_aperture(res.markers, model.upper_lip, model.lower_lip)
        scores.append(closure_score(a, res.times, phones, model.closure.closed))
        found.append(detector_score(res.closure.intervals, res.times, phones))
    return ClosureScore.pooled(scores), DetectorScore.pooled(found)


@pytest.fixture(scope="module")
def held_out(default_corpus):
    return [default_corpus.utterance(u) for u in default_corpus.info.test[:30]]


def test_without_phones_the_lips_close_at_the_held_out_bilabials(default_model, held_out):
    """The training voice's held-out sentences, acoustic-only with the detector (measured on the
    first 30: 94 % within 1 mm, 32 of 35 found, 55 % of the closures at a /p b m/: before the voice
    is measured, half a second of speech, the acoustic part alone decides); without it 14 %."""
    items = [(u.audio, u.sample_rate, u.phones, u.n_frames) for u in held_out]
    score, found = _pooled(default_model, items)
    assert score.n >= 30 and score.within >= 0.9
    assert found.recall >= 0.9 and found.precision >= 0.5
    assert score.vowels_shut <= 0.01 and score.vowel_max >= 18.0
    before, _ = _pooled(default_model, items, SynthConfig(mode="acoustic"))    # the default: off
    assert before.within <= 0.3 and before.consonants_shut <= score.consonants_shut


def test_on_a_voice_it_was_not_trained_on(default_model, held_out):
    """The second voice of the same sentences (formants x 1.1-1.2, pitch x 1.7; voice match 0:
    the acoustic part alone; measured on the first 15: 59 % within 1 mm, 37 % of the closures at
    a /p b m/, no vowel shut)."""
    items = [(second_voice(u.audio, u.sample_rate), u.sample_rate, u.phones, u.n_frames)
             for u in held_out[:15]]
    score, found = _pooled(default_model, items)
    assert score.within >= 0.4 and found.precision >= 0.3
    assert score.vowels_shut <= 0.02


@pytest.mark.skipif(not ARCTIC.is_dir(), reason=f"no {ARCTIC} (the CMU ARCTIC samples)")
def test_on_real_voices(default_model):
    """The six CMU ARCTIC sentences, held out, with the detector asked for (issue 46 measured:
    5 of 13 /p b m/ within 1 mm, 1 of 74 vowels shut, 6 of 81 other consonants, the median vowel
    maximum 19.0 mm: the detector, trained on a synthetic voice, is not precise enough on real
    ones to be on by default, docs/algorithm.md)."""
    from facetraj_engine.evaluation.closure_eval import arctic_references

    items = [(a, r, ref, None) for a, r, ref in arctic_references(ARCTIC).values()]
    score, _ = _pooled(default_model, items)
    assert score.n == 13 and score.within >= 0.3
    assert score.vowels_shut <= 0.03 and score.vowel_max >= 17.0
    off, _ = _pooled(default_model, items, SynthConfig(mode="acoustic"))
    # without the detector nothing closes the lips; the rest in pauses shuts at most the /t/ of
    # "twentieth time" (150 ms of silence with the /θ/ before it: a pause to the rule)
    assert off.within == 0.0 and off.consonants_shut <= 1 / 81 + 1e-12


def test_beside_recognized_phones_only_where_the_voice_matches(default_model, held_out):
    """With labels the detector is a second opinion only beside recognized ones, when asked for
    (off by default: on real talkers' lips it lowered the correlation, issue 46), and only as far
    as the voice matches the training voice."""
    u = held_out[0]
    cfg = SynthConfig(mode="robust", closure_second_opinion=True)
    exact = synthesize(default_model, u.audio, u.sample_rate, u.phones, cfg)
    assert exact.closure.probability is None                 # hand-checked: not asked
    res = synthesize(default_model, u.audio, u.sample_rate, u.phones, cfg,
                     provenance=Provenance("recognized"))
    labelled = sum(s.label in ("p", "b", "m") for s in u.phones)
    assert res.voice_match == 1.0 and res.closure.probability is not None
    # the training voice's recognized /p b m/ are trusted 1 - match = 0: only the detector's
    assert len(res.closure.intervals) >= labelled >= 1 and np.all(res.closure.strengths == 1.0)
    by_default = synthesize(default_model, u.audio, u.sample_rate, u.phones,
                            SynthConfig(mode="robust"), provenance=Provenance("recognized"))
    assert by_default.closure.probability is None and np.all(by_default.closure.strengths == 0.0)
    other = synthesize(default_model, second_voice(u.audio, u.sample_rate), u.sample_rate,
                       u.phones, cfg, provenance=Provenance("recognized"))
    assert other.voice_match == 0.0 and other.closure.probability is None
    assert len(other.closure.intervals) == labelled
    off = synthesize(default_model, u.audio, u.sample_rate, None,
                     ACOUSTIC.with_(closure_detector=False))
    assert off.closure.probability is None and len(off.closure.intervals) == 0


# --------------------------------------------------------------------------- streamed
def _unmatched(model: Model) -> Model:
    """The model without its training voice's distance: every voice match unknown (0)."""
    return dataclasses.replace(model, voice_distance=float("nan"))


@pytest.mark.parametrize("block", [7, 160, 441, 16000])
def test_the_stream_gives_the_offline_probabilities(default_model, held_out, block):
    u = held_out[1]
    audio, rate = u.audio, u.sample_rate
    res = synthesize(default_model, audio, rate, None, ACOUSTIC)
    from facetraj_engine.method.closure_search import search_rows

    search = search_rows(default_model, res.frames)
    for match in (0.0, 1.0):
        offline = input_probability(default_model.detector, default_model.config, audio, rate,
                                    res.times, search=search, match=match)
        front, det = LsfFront(default_model, rate), DetectorStream(default_model.detector, 60.0)
        out, done = [], 0
        for a in range(0, len(audio), block):
            c = front.feed(audio[a:a + block])
            if c > done:
                w, e = front.lsf_energy(done, c)
                out.append(det.feed(w, e, search[done:c], match))
                done = c
        w, e = front.lsf_energy(done, front.flush())
        out += [det.feed(w, e, search[done:], match), det.flush(match)]
        np.testing.assert_allclose(np.concatenate(out), offline, atol=1e-9)


def test_live_acoustic_only_is_offline_acoustic_only(default_model, held_out):
    """``facetraj live --acoustic-only --closure-detector`` against ``synth --mode acoustic
    --closure-detector`` (issue 46): the detector's closures and the rest in pauses are defined
    as a stream can make them, so the streamed face is the offline one, frame for frame (a model
    whose voice match is unknown, so that the running match and the whole recording's agree)."""
    model = _unmatched(default_model)
    u = held_out[2]
    take = stream_file(model, u.audio, u.sample_rate, 0.01, ACOUSTIC, LiveConfig(phones=False))
    res = synthesize(model, u.audio, u.sample_rate, None, ACOUSTIC)
    np.testing.assert_allclose(take.stream.closure_probability, res.closure.probability, atol=1e-9)
    assert len(res.closure.intervals) >= 2
    np.testing.assert_allclose(take.frames.markers, res.markers, atol=1e-6)


# --------------------------------------------------------------------------- model files
def test_the_detector_survives_its_model_file(default_model, tmp_path):
    loaded = Model.load(default_model.save(tmp_path / "m.npz")).detector
    det = default_model.detector
    assert loaded.spec == det.spec and loaded.search is not None
    for part in ("acoustic", "search"):
        a, b = getattr(loaded, part), getattr(det, part)
        assert a.bias == b.bias and all(np.array_equal(getattr(a, f), getattr(b, f))
                                        for f in ("mean", "scale", "weights"))


def test_an_older_model_file_without_the_detector_synthesizes_as_before(default_model, held_out,
                                                                         tmp_path):
    """A model file written before the detector: it loads, its acoustic-only synthesis closes no
    lips (the face still rests in pauses), exactly as the new model with the detector off."""
    path = default_model.save(tmp_path / "m.npz")
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
        old = {k: None for k in z.files if k.startswith(("cd_", "cs_"))}
    meta.pop("closure_detector")
    older = Model.load(edited_model_file(path, tmp_path / "old.npz", meta=np.array(json.dumps(meta)),
                                         **old))
    assert older.detector is None
    u = held_out[0]
    res = synthesize(older, u.audio, u.sample_rate, None, ACOUSTIC)
    assert len(res.closure.intervals) == 0 and res.closure.silent.any()
    same = synthesize(default_model, u.audio, u.sample_rate, None,
                      ACOUSTIC.with_(closure_detector=False))
    assert np.array_equal(res.markers, same.markers)
    take = stream_file(older, u.audio, u.sample_rate, 0.01, ACOUSTIC, LiveConfig(phones=False))
    assert take.stream.closure_probability is None and len(take.frames) == len(res.times)


def test_a_corpus_without_bilabials_trains_no_detector(toy_corpus):
    from facetraj_engine.method.training import train

    model = train(toy_corpus, label_map={"m": "n"})
    assert model.detector is None and "n" in model.phones and "m" not in model.phones


def test_an_lpc_order_under_eight_trains_a_detector_on_its_lsfs(toy_corpus, tmp_path):
    """``facetraj train --lpc-order 3`` (a fuzz run's traceback, issue 46): the detector places
    the formants with the 3 LSFs there are, survives its model file and finds closures."""
    from facetraj_engine.config import TrainConfig
    from facetraj_engine.method.training import train

    model = Model.load(train(toy_corpus, config=TrainConfig(lpc_order=3)).save(tmp_path / "m3.npz"))
    det = model.detector
    assert det.spec.n_lsf == 3 and det.lsf_mean.shape == (3,)
    assert det.acoustic.weights.shape == (len(det.spec.offsets) * 4,)
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    res = synthesize(model, utt.audio, utt.sample_rate, None, ACOUSTIC, n_frames=utt.n_frames)
    assert res.closure.probability.shape == (utt.n_frames,)
    assert np.all((res.closure.probability >= 0) & (res.closure.probability <= 1))


def test_the_toy_corpus_detector_finds_its_nasal(toy_model, toy_corpus):
    """The toy corpus's /m/ (a murmur at a quarter of the vowels' level between them): the
    detector of its training sentences finds them in its test sentences (measured: 12 of 12;
    10 of its 21 closures, each closed from its second frame as a stream closes it, fall on the
    vowel after an /m/, 10 of 63 vowels)."""
    found, vowels = [], 0
    for utt_id in toy_corpus.info.test:
        utt = toy_corpus.utterance(utt_id)
        res = synthesize(toy_model, utt.audio, utt.sample_rate, None, ACOUSTIC, n_frames=utt.n_frames)
        found.append(detector_score(res.closure.intervals, res.times, utt.phones))
        vowels += sum(s.label in ("aa", "iy", "uw") for s in utt.phones)
    score = DetectorScore.pooled(found)
    assert score.n >= 5 and score.recall >= 0.8 and score.false_vowel <= 0.2 * vowels


def test_detector_score_on_a_segment_shorter_than_a_frame():
    t = np.arange(6) / 60
    segs = [PhoneSegment(0, 0.03, "aa"), PhoneSegment(0.03, 0.035, "p"), PhoneSegment(0.035, 0.1, "aa")]
    s = detector_score(np.array([[2 / 60, 3 / 60]]), t, segs)     # the nearest frame of /p/: 2
    assert (s.found, s.n, s.false) == (1, 1, 0)


@pytest.mark.parametrize("detector", [False, True])
def test_live_acoustic_only_equals_offline_on_every_test_sentence(default_model, default_corpus,
                                                                  detector):
    """Issue 46's aim: ``live --from-file --acoustic-only`` against ``synth --mode acoustic``,
    the lip aperture's correlation over every frame at least 0.99 on s001 and every test sentence
    of the default corpus, with and without the detector (measured: at least 0.9945, mean
    0.9998; what differs is the speech/silence decision at a take's first word, a frame apart)."""
    cfg = SynthConfig(mode="acoustic", closure_detector=detector)
    model = default_model
    worst = 1.0
    for utt_id in ["s001", *default_corpus.info.test]:
        u = default_corpus.utterance(utt_id)
        take = stream_file(model, u.audio, u.sample_rate, 0.01, cfg, LiveConfig(phones=False))
        offline = synthesize(model, u.audio, u.sample_rate, None, cfg, n_frames=u.n_frames)
        a = lip_aperture(take.frames.markers, model.upper_lip, model.lower_lip)
        b = lip_aperture(offline.markers, model.upper_lip, model.lower_lip)
        assert len(a) == len(b)
        worst = min(worst, float(np.corrcoef(a, b)[0, 1]))
    assert worst >= 0.99


@pytest.mark.skipif(not ARCTIC.is_dir(), reason=f"no {ARCTIC} (the CMU ARCTIC samples)")
def test_live_acoustic_only_equals_offline_on_real_voices(default_model):
    """The six ARCTIC sentences (real voices, the detector asked for): three streamed faces are
    the offline ones; two differ where the first word begins, the stream's speech/silence
    decision a frame from offline's (measured: aperture r 0.980 and 0.988), and one at the
    150 ms silence of /θ t/ in "twentieth time" (``aew_a0003``), which offline rests as a pause
    and the stream, whose levels so far make 4 of its 9 frames silent, does not (0.909)."""
    from facetraj_engine.io.audio import read_audio

    cfg = SynthConfig(mode="acoustic", closure_detector=True)
    rs = []
    for wav in sorted(ARCTIC.glob("*.wav")):
        audio, rate = read_audio(wav)
        take = stream_file(default_model, audio, rate, 0.01, cfg, LiveConfig(phones=False))
        offline = synthesize(default_model, audio, rate, None, cfg)
        a = lip_aperture(take.frames.markers, default_model.upper_lip, default_model.lower_lip)
        b = lip_aperture(offline.markers, default_model.upper_lip, default_model.lower_lip)
        rs.append(float(np.corrcoef(a, b)[0, 1]))
    assert len(rs) == 6 and sum(r > 0.9999 for r in rs) >= 3 and min(rs) >= 0.9
