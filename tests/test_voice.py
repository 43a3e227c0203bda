"""The second voice (facetraj_engine.evaluation.second_voice) and acoustic-only synthesis from it with and
without speaker normalisation (facetraj_engine.evaluation.voice_eval, issue 13)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.signal import lfilter

from facetraj_engine.errors import InputError
from facetraj_engine.evaluation.scores import METRICS
from facetraj_engine.evaluation.second_voice import (
    VoiceSpec,
    all_pole_filter,
    f0_track,
    formant_map,
    formant_tracks,
    frame_lpc,
    inverse_filter,
    second_voice,
    voice_ratios,
)
from facetraj_engine.evaluation.voice_eval import (
    NORMALISATIONS,
    VOICES,
    condition,
    evaluate_voices,
    format_markdown,
    read_voice_eval,
    write_voice_eval,
)
from facetraj_engine.method.speaker import warp_grid

RATE = 16000


def resonator(f: float, bw: float = 80.0) -> np.ndarray:
    """The denominator of a two-pole resonance at ``f`` Hz."""
    r = math.exp(-math.pi * bw / RATE)
    return np.array([1.0, -2 * r * math.cos(2 * math.pi * f / RATE), r * r])


def two_formant_vowel(f0: float = 100.0, formants=(500.0, 1500.0), seconds: float = 1.0,
                      silence: float = 0.0) -> np.ndarray:
    """A pulse train at ``f0`` through two resonances, between ``silence`` seconds of zeros."""
    n = int(seconds * RATE)
    x = np.zeros(n)
    x[::int(round(RATE / f0))] = 1.0
    for f in formants:
        x = lfilter([1.0], resonator(f), x)
    x = 0.3 * x / np.abs(x).max()
    pad = np.zeros(int(silence * RATE))
    return np.concatenate([pad, x, pad])


def median_formants(x: np.ndarray) -> np.ndarray:
    tracks = formant_tracks(x, RATE, n=2, order=12, max_bandwidth=1000.0)[10:-10]
    return np.nanmedian(tracks, axis=0)


def test_formant_map_hand_values():
    spec = VoiceSpec()
    # k = 1.10 up to 500 Hz, 1.15 halfway to 1500 Hz, 1.20 from 1500 Hz to 5000 Hz
    got = formant_map(np.array([0.0, 300.0, 1000.0, 2500.0, 5000.0, 6500.0, 8000.0]), spec, 8000.0)
    np.testing.assert_allclose(got, [0.0, 330.0, 1150.0, 3000.0, 6000.0, 7000.0, 8000.0])
    assert np.all(np.diff(formant_map(np.linspace(0, 8000, 801), spec, 8000.0)) > 0)


def test_formants_move_by_the_stated_factors():
    """The 500 / 1500 Hz vowel comes out as the same vowel synthesized at 550 / 1800 Hz (k = 1.10
    and 1.20), both measured the same way (LPC formants of a 100 Hz voice are biased upwards a
    little, the same for both)."""
    x = two_formant_vowel()
    y = second_voice(x, RATE, VoiceSpec(f0_factor=1.0), order=10)
    target = two_formant_vowel(formants=(550.0, 1800.0))
    np.testing.assert_allclose(median_formants(x), [500.0, 1500.0], rtol=0.08)
    np.testing.assert_allclose(median_formants(y), median_formants(target), rtol=0.02)
    assert median_formants(y)[0] > 1.08 * median_formants(x)[0]
    assert len(y) == len(x)


def test_pitch_moves_and_formants_follow_with_a_higher_voice():
    x = two_formant_vowel(f0=100.0)
    y = second_voice(x, RATE, VoiceSpec(f0_factor=1.6))
    ratios = voice_ratios(x, y, RATE)
    assert ratios["F0"] == pytest.approx(1.6, rel=0.03)
    assert ratios["same_length"] == 1.0 and len(y) == len(x)
    assert np.all(np.isfinite(y)) and ratios["peak"] < 1.0
    assert np.nanmedian(f0_track(y, RATE)) == pytest.approx(160.0, rel=0.03)


def test_silence_stays_silence_and_length_is_kept():
    x = two_formant_vowel(seconds=0.5, silence=0.2)
    y = second_voice(x, RATE)
    assert len(y) == len(x)
    quiet = int(0.15 * RATE)                 # further than half an analysis window from speech
    assert np.all(y[:quiet] == 0.0) and np.all(y[-quiet:] == 0.0)
    speech = slice(int(0.25 * RATE), int(0.65 * RATE))
    rms = np.sqrt(np.mean(y[speech] ** 2)) / np.sqrt(np.mean(x[speech] ** 2))
    assert rms == pytest.approx(1.0, rel=0.1)          # the original's level


def test_identity_voice_gives_back_the_input():
    x = two_formant_vowel(seconds=0.5) + 0.01 * np.random.default_rng(0).normal(size=8000)
    y = second_voice(x, RATE, VoiceSpec(((1000.0, 1.0),), f0_factor=1.0))
    assert np.corrcoef(x, y)[0, 1] > 0.999


def test_inverse_and_all_pole_filter_undo_each_other():
    x = two_formant_vowel(seconds=0.3) + 0.01 * np.random.default_rng(1).normal(size=4800)
    a = frame_lpc(x, RATE, 18, 80, 400)
    np.testing.assert_allclose(all_pole_filter(inverse_filter(x, a, 80), a, 80), x, atol=1e-8)


@pytest.mark.parametrize("audio, problem", [
    (np.array([]), "0 samples"), (np.array([0.1]), "1 sample;"),
    (np.array([0.0, np.nan, 0.2]), "not a finite number"),
    (np.array([0.0, np.inf, -np.inf]), "2 samples that are not a finite number"),
    (np.zeros((10, 2)), "one channel"),
])
def test_bad_audio_is_a_clear_input_error(audio, problem):
    with pytest.raises(InputError, match=problem):
        second_voice(audio, RATE)
    with pytest.raises(InputError, match=problem):
        formant_tracks(audio, RATE)


def test_bad_rate_is_an_input_error():
    with pytest.raises(InputError, match="sample rate"):
        second_voice(np.zeros(100), 0)


@pytest.fixture(scope="module")
def toy_voice_eval(toy_corpus, toy_model):
    return evaluate_voices(toy_corpus, toy_model, max_test=2)


def test_evaluation_on_the_toy_corpus(toy_voice_eval):
    res = toy_voice_eval
    assert set(res.scores) == {condition(v, n) for v in VOICES for n in NORMALISATIONS}
    for name, rows in res.scores.items():
        assert len(rows) == 2 and {r.mode for r in rows} == {name}
        assert all(r.split == "test" and r.smoothing == "triangular" for r in rows)
        for m in METRICS:
            mean, sd = res.summary(name)[m]
            assert -1 <= mean <= 1 and math.isfinite(sd)
    grid = set(warp_grid().tolist())
    assert set(res.warps[condition("second", "none")].values()) == {1.0}
    assert set(res.warps[condition("second", "utterance")].values()) <= grid
    assert set(res.voice["speaker_warps"].values()) <= grid
    assert res.voice["ratios"]["same_length"] == 1.0
    assert all(math.isfinite(res.voice["ratios"][k]) for k in ("F1", "F2", "F0", "peak"))


def test_file_round_trip_and_report_section(toy_voice_eval, tmp_path):
    from facetraj_engine.report.markdown import second_voice_section

    assert read_voice_eval(tmp_path / "absent.json") is None
    back = read_voice_eval(write_voice_eval(tmp_path / "voice_eval.json", toy_voice_eval))
    assert back.summary("second/utterance") == toy_voice_eval.summary("second/utterance")
    assert back.warps == toy_voice_eval.warps and back.voice == toy_voice_eval.voice
    text = format_markdown(back)
    assert text.count("| second |") == 3 and text.count("| training |") == 3
    assert "**What it says.**" in text and "**Warps chosen**" in text
    lines = second_voice_section(SimpleNamespace(voice_eval=back))
    assert lines[0] == "## Beyond the paper: a voice other than the training voice"
    assert second_voice_section(SimpleNamespace(voice_eval=None)) == []
