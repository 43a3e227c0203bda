"""What synthesis computes once (issue 48). The closure detector reads its frame energies from
the input's LSF analysis instead of framing the audio a second time: the same energies (to the
bit at the analysis rate; by a constant that its relative energy cancels where the input is
resampled), the same synthesis to the bit, and the second framing gone. The voice match reads
each frame's nearest codeword from the acoustic-only search instead of searching the index
again: the same voice match to the bit."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import Provenance
from facetraj_engine.level import unit_exponent
from facetraj_engine.method import closure_detector, pipeline, voice_match
from facetraj_engine.method.closure_detector import frame_energy_db, input_energy_db, relative_energy
from facetraj_engine.method.lsf import lsf_at, lsf_frames_at, resample_audio
from facetraj_engine.method.model import analysed_frames
from facetraj_engine.method.pipeline import detector_may_run, input_voice_ratio, synthesize
from facetraj_engine.method.search import finds_voice_nearest

ACOUSTIC = SynthConfig(mode="acoustic", closure_detector=True)      # the detector asked for


@pytest.fixture(scope="module")
def held_out(default_corpus):
    return [default_corpus.utterance(u) for u in default_corpus.info.test[:6]]


def _resampled(x: np.ndarray, rate: int, to: int) -> np.ndarray:
    from scipy.signal import resample_poly

    return resample_poly(x, to // np.gcd(to, rate), rate // np.gcd(to, rate))


def test_the_lsf_analysis_gives_the_detectors_energies(default_model, held_out):
    """At the analysis rate the energies of the LSFs' own frames are the detector's, bit for
    bit, and the LSFs are those of lsf_at; resampled (44.1 kHz), the frames may be scaled by
    another power of two: the energies move by a constant, the relative energy by rounding."""
    config = default_model.config
    for u in held_out:
        times = np.arange(u.n_frames) / default_model.marker_rate
        lsf, energy = analysed_frames(config, u.audio, u.sample_rate, times, 2, frame_energy_db)
        assert u.sample_rate == config.audio_rate
        np.testing.assert_array_equal(energy, input_energy_db(config, u.audio, u.sample_rate, times))
        np.testing.assert_array_equal(lsf, default_model.input_lsf(u.audio, u.sample_rate, times, 1))
    u = held_out[0]
    times = np.arange(u.n_frames) / default_model.marker_rate
    x44 = _resampled(u.audio, u.sample_rate, 44100)
    offsets = []
    for gain in (1.0, *(0.5 / np.abs(x44).max() * f for f in (0.9999, 0.99995, 1.00005))):
        x = x44 * gain                # peaks about 0.5: the resampled one may cross it
        lsf, energy = lsf_frames_at(x, 44100, times, config.lpc_order, config.window_s,
                                    config.audio_rate, config.preemphasis, per_frame=frame_energy_db)
        own = input_energy_db(config, x, 44100, times)
        offset = energy - own
        assert np.ptp(offset) < 1e-9
        assert abs(offset[0] / (20 * np.log10(2)) - round(offset[0] / (20 * np.log10(2)))) < 1e-9
        np.testing.assert_allclose(relative_energy(energy), relative_energy(own), rtol=0,
                                   atol=1e-9)
        np.testing.assert_array_equal(lsf, lsf_at(x, 44100, times, config.lpc_order,
                                                  config.window_s, config.audio_rate,
                                                  config.preemphasis))
        offsets.append(round(float(offset[0]), 6))
    assert 0.0 in offsets and round(20 * np.log10(2), 6) in np.abs(offsets)   # both cases met


def test_no_per_frame_figure_when_not_asked(default_model, held_out):
    u = held_out[0]
    times = np.arange(u.n_frames) / default_model.marker_rate
    lsf, nothing = analysed_frames(default_model.config, u.audio, u.sample_rate, times)
    assert nothing is None and lsf.shape == (u.n_frames, default_model.config.lpc_order)


def _framed_again(*args):
    raise AssertionError("the detector framed the audio a second time")


@pytest.mark.parametrize("case", ["acoustic", "recognized", "resampled", "rescaled"])
def test_synthesis_frames_the_audio_once_and_gives_the_same_face(default_model, held_out,
                                                                  monkeypatch, case):
    """With the energies shared, the detector never frames the audio again, and the synthesis
    is the one of a detector framing it itself: every array equal to the bit (the closures,
    their probabilities, the markers); resampled from a peak just under 1/2 (the LSFs' frames
    then twice the detector's own), the probabilities equal to rounding, the rest to the bit."""
    config, provenance = ACOUSTIC, None
    if case == "recognized":
        config, provenance = SynthConfig(mode="robust", closure_second_opinion=True), \
            Provenance("recognized")
    for u in held_out[:3]:
        audio, rate = u.audio, u.sample_rate
        if case in ("resampled", "rescaled"):
            audio, rate = _resampled(audio, rate, 44100), 44100
        if case == "rescaled":
            audio = audio * (0.5 / np.abs(audio).max() * 0.99995)
            if u is held_out[0]:                  # this one's 16 kHz peak is over 1/2
                assert unit_exponent(audio) == 1
                assert unit_exponent(resample_audio(audio, rate, 16000)) == 0
        phones = u.phones if provenance else None
        with monkeypatch.context() as m:              # the detector frames the audio itself
            m.setattr(pipeline, "detector_may_run", lambda *a: False)
            own = synthesize(default_model, audio, rate, phones, config, provenance=provenance)
        with monkeypatch.context() as m:              # the detector may not frame it again
            m.setattr(closure_detector, "input_energy_db", _framed_again)
            shared = synthesize(default_model, audio, rate, phones, config, provenance=provenance)
        assert own.closure.probability is not None
        np.testing.assert_allclose(shared.closure.probability, own.closure.probability, rtol=0,
                                   atol=1e-12 if case == "rescaled" else 0.0)
        np.testing.assert_array_equal(shared.closure.intervals, own.closure.intervals)
        np.testing.assert_array_equal(shared.markers, own.markers)
        assert len(shared.closure.intervals) > 0


def test_when_the_detector_may_run(default_model):
    """Without labels when the detector is asked for, or beside recognized ones when its second
    opinion is (both off by default, issue 46); never with the closure step off, nor for a model
    without one (its analysis then computes no energies)."""
    recognized, hand = Provenance("recognized"), Provenance("hand-checked")
    second = SynthConfig(closure_second_opinion=True)
    assert detector_may_run(default_model, ACOUSTIC, None)
    assert not detector_may_run(default_model, SynthConfig(mode="acoustic"), None)    # default
    assert detector_may_run(default_model, second.with_(mode="robust"), recognized)
    assert detector_may_run(default_model, second.with_(mode="phonetic"), recognized)
    assert not detector_may_run(default_model, SynthConfig(mode="robust"), recognized)  # default
    assert not detector_may_run(default_model, second.with_(mode="phonetic"), hand)
    assert not detector_may_run(default_model, second.with_(mode="robust"), None)
    assert not detector_may_run(default_model, ACOUSTIC.with_(closure=False), None)
    assert not detector_may_run(default_model, ACOUSTIC.with_(closure_detector=False), None)
    assert not detector_may_run(dataclasses.replace(default_model, detector=None), ACOUSTIC, None)


def test_the_voice_match_reads_the_acoustic_search(default_model, held_out, monkeypatch):
    """Acoustic-only, the voice match's nearest codewords come from the search (the index is not
    searched again) and the figure is the one of its own search, to the bit; on another voice
    too (a held-out sentence played slower: its formants lower)."""
    searched = []
    real = voice_match.indexed_distances

    def spy(w, cb_lsf, index, near=None):
        searched.append(near is None)
        return real(w, cb_lsf, index, near)

    monkeypatch.setattr(voice_match, "indexed_distances", spy)
    for u in held_out[:3]:
        for audio in (u.audio, _resampled(u.audio, u.sample_rate, 18000)):
            searched.clear()
            res = synthesize(default_model, audio, u.sample_rate, None, ACOUSTIC, voice=True)
            assert searched == [False]
            times = np.arange(len(res.times)) / default_model.marker_rate
            lsf = default_model.input_lsf(audio, u.sample_rate, times)
            assert res.voice_ratio == input_voice_ratio(default_model, audio, u.sample_rate,
                                                        times, lsf)
            assert searched[-1] and np.isfinite(res.voice_ratio)


def test_the_voice_match_searches_itself_when_the_search_probes_otherwise(default_model,
                                                                          held_out):
    """An acoustic search that opens other cells than the voice match's (``acoustic_probe``
    2, or the whole codebook) leaves the voice match to its own search: the same figure."""
    u = held_out[0]
    want = synthesize(default_model, u.audio, u.sample_rate, None, ACOUSTIC, voice=True).voice_ratio
    assert finds_voice_nearest(default_model, ACOUSTIC)
    for config in (ACOUSTIC.with_(acoustic_probe=2), ACOUSTIC.with_(acoustic_probe=None)):
        assert not finds_voice_nearest(default_model, config)
        res = synthesize(default_model, u.audio, u.sample_rate, None, config, voice=True)
        assert res.voice_ratio == want
