"""Lip kinematics and gesture landmarks (engine/evaluation/kinematics.py), hand-checked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from facetraj_engine.data import PhoneSegment
from facetraj_engine.evaluation.kinematics import (
    LANDMARKS,
    Gesture,
    compare_landmarks,
    find_gesture,
    find_gestures,
    gesture_anchors,
    lip_measures,
    mean_abs_timing_error,
    measure_gestures,
    model_lip_measures,
    tangential_velocity,
    write_landmarks_textgrid,
    write_landmarks_tsv,
)

RATE = 60.0


def bell_gesture(rate: float = RATE, close=(0.30, 0.50, 120.0), release=(0.50, 0.75, 80.0),
                 duration: float = 1.2):
    """A lower-lip trajectory whose speed is two raised-sine bells: closing (down) then release
    (up). Returns positions (T, 3), the analytic landmark times and the per-frame true speed."""
    t = np.arange(int(duration * rate) + 1) / rate

    def bell(a, b, amp):
        u = np.clip((t - a) / (b - a), 0, 1)
        speed = amp * np.sin(np.pi * u) ** 2
        # integral of amp sin^2(pi u) dt = amp (b - a) (u / 2 - sin(2 pi u) / (4 pi))
        disp = amp * (b - a) * (u / 2 - np.sin(2 * np.pi * u) / (4 * np.pi))
        return speed, disp

    s1, d1 = bell(*close)
    s2, d2 = bell(*release)
    y = -d1 + d2
    pos = np.stack([np.zeros_like(t), y, np.zeros_like(t)], axis=1)
    u20 = math.asin(math.sqrt(0.2)) / math.pi          # where sin^2 = 0.2
    truth = {
        "onset": close[0] + u20 * (close[1] - close[0]),
        "pvel": 0.5 * (close[0] + close[1]),
        "maxc": close[1],
        "pvel2": 0.5 * (release[0] + release[1]),
        "offset": release[1] - u20 * (release[1] - release[0]),
    }
    return pos, truth, s1 + s2


def test_lip_measures_hand_checked():
    m = np.zeros((2, 4, 3))
    m[:, 0] = [0, 5, 2]        # upper lip
    m[:, 1] = [0, -3, 4]       # lower lip
    m[:, 2] = [20, 0, 0]
    m[:, 3] = [-20, 0, 0]
    m[1, 1] = [0, -7, 6]
    neutral = m[0]
    lm = lip_measures(m, 0, 1, (2, 3), neutral)
    assert lm.aperture == pytest.approx([math.hypot(8, 2), math.hypot(12, 4)])
    assert lm.width == pytest.approx([40, 40])
    assert lm.protrusion == pytest.approx([0.0, 1.0])     # (2 + 6)/2 - (2 + 4)/2
    assert np.isnan(lip_measures(m, 0, 1).width).all()


def test_model_lip_measures(toy_model, toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    m = toy_model.normalise_markers(utt.markers)
    lm = model_lip_measures(toy_model, m)
    ul, ll = toy_model.upper_lip, toy_model.lower_lip
    assert lm.aperture[10] == pytest.approx(np.linalg.norm(m[10, ul] - m[10, ll]))
    assert np.nanmedian(lm.width) > 30       # corners +-25 mm apart in the toy face
    assert abs(np.nanmedian(lm.protrusion)) < 3


def test_tangential_velocity_central_differences():
    t = np.arange(10) / RATE
    x = np.stack([t**2, np.zeros(10), np.zeros(10)], axis=1)
    v = tangential_velocity(x, RATE)
    assert v[1:-1] == pytest.approx(2 * t[1:-1])         # central differences are exact on t^2
    x[4] = np.nan
    v = tangential_velocity(x, RATE)
    assert np.isnan(v[4]) and np.isfinite(v[[3, 5]]).all()


def test_landmarks_on_known_velocity_profile_within_one_frame():
    pos, truth, _ = bell_gesture()
    v = tangential_velocity(pos, RATE)
    g = find_gesture(v, RATE, anchor=0.48)
    for k in LANDMARKS:
        assert abs(getattr(g, k) - truth[k]) < 1 / RATE, (k, getattr(g, k), truth[k])
    assert g.v_pvel == pytest.approx(120, rel=0.05) and g.v_pvel2 == pytest.approx(80, rel=0.05)


def test_landmarks_with_noise_and_light_smoothing():
    pos, truth, _ = bell_gesture()
    rng = np.random.default_rng(1)
    noisy = pos + 0.05 * rng.standard_normal(pos.shape)
    v = tangential_velocity(noisy, RATE, smooth_s=1 / RATE)
    g = find_gestures(v, RATE, [PhoneSegment(0.42, 0.55, "m")])[0]
    assert g.label == "m"
    for k in LANDMARKS:
        assert abs(getattr(g, k) - truth[k]) < 1 / RATE, k


def test_threshold_moves_onset_and_offset_only():
    pos, truth, _ = bell_gesture()
    v = tangential_velocity(pos, RATE)
    g = find_gesture(v, RATE, 0.5, threshold=0.5)
    u50 = 0.25                                        # sin^2(pi u) = 0.5 at u = 1/4
    assert abs(g.onset - (0.30 + u50 * 0.2)) < 1 / RATE
    assert abs(g.offset - (0.75 - u50 * 0.25)) < 1 / RATE
    assert abs(g.maxc - truth["maxc"]) < 1 / RATE


def test_gesture_anchors_and_compare():
    phones = [PhoneSegment(0, 0.2, "sil"), PhoneSegment(0.2, 0.3, "m"), PhoneSegment(0.3, 0.5, "aa"),
              PhoneSegment(0.5, 0.6, "F")]
    assert [s.label for s in gesture_anchors(phones)] == ["m", "F"]
    a = Gesture("m", 0.5, 0.1, 0.2, 0.3, 0.4, 0.5, 100, 90)
    b = Gesture("m", 0.5, 0.12, 0.2, 0.28, 0.43, 0.5, 100, 90)
    pair = compare_landmarks([a], [b])[0]
    assert pair.errors() == pytest.approx({"onset": 0.02, "pvel": 0.0, "maxc": -0.02, "pvel2": 0.03,
                                           "offset": 0.0})
    assert mean_abs_timing_error([pair])["pvel2"] == pytest.approx(0.03)
    with pytest.raises(ValueError):
        compare_landmarks([a], [])


def test_export_tsv_and_textgrid(tmp_path):
    from praatio import textgrid

    a = Gesture("m", 0.5, 0.1, 0.2, 0.3, 0.4, 0.5, 100, 90)
    b = Gesture("m", 0.5, 0.12, 0.2, 0.28, 0.43, float("nan"), 100, 90)
    tsv = write_landmarks_tsv(tmp_path / "lm.tsv", {"original": [a], "synthesized": [b]}, "LL_C")
    lines = tsv.read_text().splitlines()
    head = lines[0].split("\t")
    assert head[:3] == ["source", "marker", "label"] and "d_maxc" in head
    row = dict(zip(head, lines[2].split("\t"), strict=True))
    assert row["source"] == "synthesized" and float(row["d_maxc"]) == pytest.approx(-0.02)
    assert row["offset"] == ""
    tg_path = write_landmarks_textgrid(tmp_path / "lm.TextGrid", {"original": [a], "synthesized": [b]}, 1.0)
    tg = textgrid.openTextgrid(str(tg_path), includeEmptyIntervals=True)
    orig = tg.getTier("original").entries
    assert [p.label for p in orig] == ["onset m", "pvel m", "maxc m", "pvel2 m", "offset m"]
    assert [p.time for p in orig] == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5])
    assert len(tg.getTier("synthesized").entries) == 4      # NaN offset left out
    assert not list(tmp_path.glob(".*part*"))                # atomic writes leave no temp files


def test_measure_gestures_original_vs_shifted_synthesis():
    pos, _truth, _ = bell_gesture()
    orig = np.repeat(pos[:, None], 2, axis=1)
    syn = np.roll(orig, 3, axis=0)                          # synthesized 3 frames late
    syn[:3] = orig[0]
    phones = [PhoneSegment(0, 0.42, "aa"), PhoneSegment(0.42, 0.56, "m"), PhoneSegment(0.56, 1.2, "aa")]
    gm = measure_gestures(syn, orig, 1, RATE, phones)
    assert [g.label for g in gm.original] == ["m"]
    err = gm.pairs()[0].errors()
    for k in LANDMARKS:
        assert err[k] == pytest.approx(3 / RATE, abs=1e-6), k
    assert measure_gestures(syn, None, 1, RATE, phones).pairs() == []
