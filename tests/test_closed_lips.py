"""Synthesized closures judged by the talker's own lips (issue 46,
``facetraj_engine.evaluation.closed_lips``): the talker's closed value and the frame counts by hand
against what ``evaluate`` (``facetraj eval``) and the error view report."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.analysis.errors import error_report
from facetraj_engine.config import EvalConfig, SynthConfig
from facetraj_engine.evaluation.closure import lip_aperture, segment_values
from facetraj_engine.evaluation.scores import evaluate, speech_mask
from facetraj_engine.method.pipeline import synthesize


def test_eval_counts_the_talkers_closed_frames_by_hand(default_model, default_corpus):
    """Three held-out sentences: the closed value is the median of the original lips' minima at
    their /p b m/; a frame is closed within 1 mm of it; precision and recall pooled over frames."""
    model = default_model
    ids = list(default_corpus.info.test[:3])
    small = default_corpus.without([u for u in default_corpus.info.ids if u not in ids])
    res = evaluate(model, small, ("test",), [SynthConfig()], ("triangular",))
    minima, orig_ap, syn_ap = [], [], []
    for u in ids:
        utt = default_corpus.utterance(u)
        original = model.normalise_markers(utt.markers)
        a = lip_aperture(original, model.upper_lip, model.lower_lip)
        bil = [s for s in utt.phones if s.label in ("p", "b", "m")]
        minima += list(segment_values(a, utt.frame_times(), bil, "min"))
        syn = synthesize(model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(),
                         n_frames=utt.n_frames)
        mask = speech_mask(utt.audio, utt.sample_rate, utt.frame_times()) & \
            np.isfinite(original).all(axis=(1, 2))
        orig_ap.append(a[mask])
        syn_ap.append(lip_aperture(syn.markers, model.upper_lip, model.lower_lip)[mask])
    closed = float(np.median(minima))
    assert res.talker.closed == pytest.approx(closed, abs=1e-5) and res.talker.bilabials == len(minima)
    o, s = np.concatenate(orig_ap) <= closed + 1.0, np.concatenate(syn_ap) <= closed + 1.0
    row = res.mean("test", "triangular")
    assert o.sum() > 0 and s.sum() > 0
    assert row["closure_precision"] == pytest.approx((o & s).sum() / s.sum(), abs=0.02)
    assert row["closure_recall"] == pytest.approx((o & s).sum() / o.sum(), abs=0.02)
    per = res.to_json()["utterances"]
    assert sum(r["closed_frames"] for r in per) == pytest.approx(o.sum(), abs=3)
    assert res.to_json()["talker_closed"]["bilabials"] == len(minima)
    # the error view's numbers are the same judgement
    rep = error_report(model, small, ("test",), SynthConfig(), EvalConfig())
    assert rep.talker.closed == pytest.approx(res.talker.closed)
    assert rep.closures.recall == pytest.approx(row["closure_recall"], abs=0.02)


def test_without_labelled_bilabials_the_lowest_percentile_is_closed(default_model, default_corpus):
    """A corpus whose labels hold no /p b m/ (every one renamed): the talker's closed value is the
    1st percentile of its speech frames' aperture."""
    from facetraj_engine.evaluation.closed_lips import TalkerLips, talker_closed

    a = np.concatenate([np.full(90, 15.0), np.linspace(8.0, 9.0, 10)]).astype(np.float32)
    got = talker_closed([TalkerLips(np.zeros(0), a, [])])
    assert got.bilabials == 0 and got.closed == pytest.approx(np.percentile(a, 1.0))
    assert "1st percentile of its 100 speech frames" in got.describe()
