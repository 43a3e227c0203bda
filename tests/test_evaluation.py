"""Speech/silence detection and correlation measures (paper section 3)."""

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.evaluation.scores import (
    EvalConfig,
    evaluate,
    moving_coordinates,
    pearson,
    speech_mask,
    trajectory_correlations,
)


def _speech_like(rate=16000):
    x = np.zeros(rate * 2)
    rng = np.random.default_rng(0)
    x[8000:24000] = 0.3 * rng.standard_normal(16000)       # speech 0.5 - 1.5 s
    x[15200:16000] = 0.0                                     # a 50 ms stop closure inside it
    x += 1e-4 * rng.standard_normal(len(x))
    return x


def test_speech_mask_keeps_stop_closures():
    x = _speech_like()
    t = np.array([0.2, 0.7, 0.975, 1.2, 1.8])
    mask = speech_mask(x, 16000, t)
    assert mask.tolist() == [False, True, True, True, False]
    # without the 112 ms median filter the closure would be called silence
    assert not speech_mask(x, 16000, np.array([0.975]), EvalConfig(median_s=0.004))[0]


def test_pearson_hand_example():
    assert pearson(np.array([1.0, 2, 3]), np.array([2.0, 4, 6])) == pytest.approx(1.0)
    assert pearson(np.array([1.0, 2, 3]), np.array([3.0, 2, 1])) == pytest.approx(-1.0)
    # x = [1 2 3 4], y = [1 3 2 4]: cov 1.25*4/4, r = 0.8
    assert pearson(np.array([1.0, 2, 3, 4]), np.array([1.0, 3, 2, 4])) == pytest.approx(0.8)
    assert np.isnan(pearson(np.ones(5), np.arange(5.0)))


def test_moving_coordinates_and_correlations(toy_model):
    coords = moving_coordinates(toy_model, 0.1)
    std = toy_model.coord_std
    assert np.all(std[coords] >= 0.1 * std.max())
    fixed_coords = {3 * i + a for i in toy_model.fixed for a in range(3)}
    assert not fixed_coords & set(coords.tolist())     # forehead / nose bridge never count
    rng = np.random.default_rng(1)
    t = 120
    orig = np.repeat(toy_model.neutral_face()[None], t, axis=0) + rng.standard_normal((t, 12, 3))
    synth = orig.copy()
    synth[:, toy_model.upper_lip, 1] = -orig[:, toy_model.upper_lip, 1]
    mask = np.ones(t, bool)
    mask[:10] = False
    c = trajectory_correlations(orig, synth, mask, toy_model)
    assert c["lower_lip"] == pytest.approx(1.0)
    assert c["upper_lip"] == pytest.approx(-1.0)
    n = len(coords)
    up_y = 3 * toy_model.upper_lip + 1
    expected = (n - 1 + (-1.0)) / n if up_y in coords else 1.0
    assert c["whole_face"] == pytest.approx(expected)


def test_evaluate_in_two_processes_equals_serial(toy_model, toy_corpus):
    """Utterances scored in 2 worker processes: the same scores, in the same order."""
    configs = [SynthConfig(), SynthConfig(mode="acoustic")]
    serial = evaluate(toy_model, toy_corpus, ("train", "test"), configs, ("triangular", "spline"))
    seen = []
    parallel = evaluate(toy_model, toy_corpus, ("train", "test"), configs,
                        ("triangular", "spline"), progress=lambda f, m: seen.append(f), workers=2)
    assert len(serial.scores) == 2 * 2 * (len(toy_corpus.info.train) + len(toy_corpus.info.test))
    assert parallel.scores == serial.scores        # dataclass equality: every float bit-equal
    assert parallel.table() == serial.table()
    assert seen[-1] == 1.0 and seen == sorted(seen)


@pytest.mark.parametrize("k, n", [(1, 500), (3, 500), (29, 500), (29, 1024 * 3 + 5),
                                  (3, 1024), (29, 20)])
def test_median_filter_equals_scipy_medfilt(k, n):
    """scipy's values, in one chunk of windows and in several (a last part chunk)."""
    from scipy.signal import medfilt

    from facetraj_engine.method.speech import median_filter

    x = np.random.default_rng(k).standard_normal(n) * 20 - 40      # an energy contour in dB
    np.testing.assert_array_equal(median_filter(x, k), medfilt(x, k))


def test_median_filter_with_nan_is_nan_where_the_window_holds_it():
    from facetraj_engine.method.speech import median_filter

    x = np.arange(9, dtype=float)
    x[4] = np.nan
    out = median_filter(x, 3)
    assert np.isnan(out[3:6]).all() and out[[1, 2, 6, 7]].tolist() == [1.0, 2.0, 6.0, 7.0]


@pytest.mark.parametrize("rate, n", [(16000, 48000), (16000, 5), (44100, 44100 * 2 + 7),
                                     (8000, 8001), (22050, 1), (16000, 16000 * 20 + 13),
                                     (16000, 64 * 2048 - 200)])
def test_short_time_energy_equals_the_sum_over_windowed_frames(rate, n):
    """The block-product energy equals each frame's windowed sum of squares (the definition),
    in one chunk of blocks and in several (20 s; a chunk's last blocks half signal, half
    padding)."""
    from facetraj_engine.method.speech import short_time_energy_db

    x = np.random.default_rng(n).standard_normal(n) * 0.1
    win, hop = int(round(0.02 * rate)), int(round(0.004 * rate))
    pad = np.concatenate([np.zeros(win // 2), x, np.zeros(win)])
    count = n // hop + 1
    frames = pad[(np.arange(count) * hop)[:, None] + np.arange(win)] * np.hamming(win)
    want = 10 * np.log10((frames ** 2).sum(axis=1) / win + 1e-12)
    got, times = short_time_energy_db(x, rate)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    np.testing.assert_allclose(times, np.arange(count) * hop / rate)
