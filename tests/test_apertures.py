"""The Measure numbers (facetraj_engine.analysis.apertures) and the error view's phone ranking,
on hand-made trajectories with known answers and on the default corpus's /b/ of "boy"."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from facetraj_engine.analysis.apertures import (
    APERTURE_COLUMNS,
    aperture,
    frame_labels,
    phone_apertures,
    readout_at,
    write_phone_apertures_csv,
)
from facetraj_engine.analysis.errors import (
    MIN_CORRELATION_FRAMES,
    SegmentError,
    UtteranceAnalysis,
    UtteranceError,
    phone_errors,
)
from facetraj_engine.data import PhoneSegment

RATE = 60.0


def lips(upper_y: np.ndarray, lower_y: np.ndarray) -> np.ndarray:
    """Two markers (upper, lower lip centre) at x = z = 0 with these heights."""
    m = np.zeros((len(upper_y), 2, 3))
    m[:, 0, 1], m[:, 1, 1] = upper_y, lower_y
    return m


def test_readout_at_the_cursor_in_mm():
    t = np.arange(30) / RATE
    syn = lips(np.full(30, 6.0), np.linspace(-8.0, -4.0, 30))
    org = lips(np.full(30, 6.5), np.full(30, -6.0))
    phones = [PhoneSegment(0.0, 0.2, "b"), PhoneSegment(0.2, 0.5, "oy")]
    words = [PhoneSegment(0.0, 0.5, "boy")]
    r = readout_at(0.25, t, syn, 0, 1, org, phones, words)
    k = 15                                                   # 0.25 s at 60 Hz
    assert (r.frame, r.phone, r.word) == (k, "oy", "boy")
    assert r.upper_y == 6.0 and r.lower_y == pytest.approx(syn[k, 1, 1])
    assert r.aperture == pytest.approx(6.0 - syn[k, 1, 1])
    assert r.original_aperture == pytest.approx(12.5) and r.has_original
    assert r.difference == pytest.approx(r.aperture - 12.5)
    alone = readout_at(0.25, t, syn, 0, 1)                    # no original: NaN, said so
    assert not alone.has_original and np.isnan(alone.difference)
    assert readout_at(9.0, t, syn, 0, 1, phones=phones).phone == ""     # past the labels


def test_phone_apertures_at_minimum_and_midpoint():
    t = np.arange(24) / RATE                                  # 0.4 s
    upper = np.full(24, 6.0)
    lower = np.full(24, -10.0)
    lower[4:9] = [-8, -6, -5.5, -6, -8]                        # a closure, least at frame 6
    syn, org = lips(upper, lower), lips(upper + 0.5, lower)
    phones = [PhoneSegment(0.0, 0.05, "sil"), PhoneSegment(0.05, 0.21, "b"),
              PhoneSegment(0.21, 0.4, "oy")]
    rows = phone_apertures(t, syn, 0, 1, phones, [PhoneSegment(0.05, 0.4, "boy")], org)
    assert [r.phone for r in rows] == ["b", "oy"]              # silence left out
    b = rows[0]
    assert b.word == "boy" and b.frames == 10                 # frames 3 .. 12
    assert b.min_synthesized == pytest.approx(11.5) and b.min_time == pytest.approx(6 / RATE)
    assert b.min_original == pytest.approx(12.0) and b.min_error == pytest.approx(-0.5)
    assert b.mid_synthesized == pytest.approx(14.0)           # 0.13 s: frame 8 (-8 mm)
    assert b.mid_error == pytest.approx(-0.5)
    alone = phone_apertures(t, syn, 0, 1, phones)
    assert np.isnan(alone[0].min_original) and np.isnan(alone[0].mid_error)


def test_phone_apertures_csv(tmp_path):
    t = np.arange(12) / RATE
    rows = phone_apertures(t, lips(np.full(12, 5.0), np.full(12, -7.0)), 0, 1,
                           [PhoneSegment(0.0, 0.2, "m")])
    out = write_phone_apertures_csv(tmp_path / "apertures.csv", rows)
    back = list(csv.DictReader(out.open()))
    assert list(back[0]) == list(APERTURE_COLUMNS)
    assert back[0]["phone"] == "m" and float(back[0]["min_synthesized_mm"]) == 12.0
    assert back[0]["min_original_mm"] == "nan"


def test_aperture_is_the_kinematics_panels_aperture(default_model, default_corpus):
    from facetraj_engine.evaluation.kinematics import model_lip_measures

    markers = default_model.normalise_markers(default_corpus.utterance("s002").markers)
    np.testing.assert_array_equal(aperture(markers, default_model.upper_lip, default_model.lower_lip),
                                  model_lip_measures(default_model, markers).aperture)


def test_frame_labels_and_aperture_with_gaps():
    labels = frame_labels([PhoneSegment(0.0, 0.1, "p"), PhoneSegment(0.2, 0.3, "aa")],
                          np.array([0.0, 0.15, 0.25, 0.35]))
    assert labels == ["p", "", "aa", ""]
    m = lips(np.array([5.0, np.nan]), np.array([-5.0, -5.0]))
    assert aperture(m, 0, 1)[0] == 10.0 and np.isnan(aperture(m, 0, 1)[1])


def _analysis(name: str, labels: list[str], orig: np.ndarray, syn: np.ndarray) -> UtteranceAnalysis:
    """An analysis of lip y tracks ``(T, 2)`` (upper, lower) original and synthesized."""
    lips_y = np.stack([orig, syn], axis=1)
    err = np.abs(orig - syn)
    summary = UtteranceError(name, "test", 1.0, 1.0, 1.0, 0.0, "", 0.0, 0.0)
    return UtteranceAnalysis(summary, np.arange(len(labels)) / RATE, err,
                             [SegmentError(name, lab, 0, 1, 0.0) for lab in sorted(set(labels))],
                             labels, lips_y)


def test_phones_are_ranked_by_rms_error_and_short_ones_get_no_correlation():
    """The review's case: an /m/ of 14 frames (a held closure: r near 0 over a few frames, the
    lips within 0.7 mm) ranked worst by correlation; ranked by RMS error in mm it comes after a
    /v/ whose lips are 2 mm off, and its correlation is not given."""
    rng = np.random.default_rng(3)
    n_m, n_v = 14, 60
    m_orig = np.column_stack([5 + 0.05 * rng.standard_normal(n_m), -6 + 0.05 * rng.standard_normal(n_m)])
    m_syn = m_orig + 0.7 * np.array([[1.0, -1.0]]) / np.sqrt(2) + 0.05 * rng.standard_normal((n_m, 2))
    v = np.sin(np.linspace(0, 3, n_v))[:, None] * [2.0, 4.0]
    v_syn = v + np.array([2.0, -2.0])
    a = _analysis("u", ["m"] * n_m + ["v"] * n_v, np.vstack([m_orig, v]), np.vstack([m_syn, v_syn]))
    ranked = phone_errors([a])
    assert [p.phone for p in ranked] == ["v", "m"]
    m, v_err = ranked[1], ranked[0]
    assert m.rms == pytest.approx(np.sqrt(np.mean((m_orig - m_syn) ** 2)))
    assert m.rms < 1.0 < v_err.rms == pytest.approx(2.0)
    assert m.frames == n_m < MIN_CORRELATION_FRAMES and np.isnan(m.correlation)
    assert v_err.frames == n_v and v_err.correlation == pytest.approx(1.0)


def test_the_b_of_boy_on_the_default_corpus(default_model, default_corpus):
    """s002 "The boy enjoyed the noisy toy.": at the /b/ of "boy" the original lips close (their
    aperture within 1 mm of the talker's closed aperture) and the table's /b/ row says so."""
    from facetraj_engine.analysis.lips import closed_lips
    from facetraj_engine.method.pipeline import synthesize

    model, utt = default_model, default_corpus.utterance("s002")
    res = synthesize(model, utt.audio, utt.sample_rate, utt.phones, n_frames=utt.n_frames)
    org = model.normalise_markers(utt.markers)
    rows = phone_apertures(res.times, res.markers, model.upper_lip, model.lower_lip, utt.phones,
                           utt.words, org)
    b = next(r for r in rows if r.phone == "b")
    assert b.word.lower() == "boy"
    closed = float(closed_lips(model).gap(model.upper_lip, model.lower_lip))
    assert abs(b.min_original - closed) < 1.0
    assert 0 < b.min_synthesized < 20 and b.min_error == pytest.approx(b.min_synthesized - b.min_original)
