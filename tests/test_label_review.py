"""Where to look first (engine/analysis/label_review.py): the ranking on hand-made apertures, and
on a real recording with its phones recognized: the recognizer's doubted /p b m/ lead the list,
and the phones corrected by hand leave it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from facetraj_engine.analysis.label_review import REASONS, counts, review
from facetraj_engine.data import PhoneSegment as S
from facetraj_engine.data import Provenance
from facetraj_engine.labels.editing import PHONES, LabelDocument
from facetraj_engine.labels.provenance import Labels

ARCTIC = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "arctic_samples"


def labels(segs, conf, kind="recognized"):
    return Labels([S(*s) for s in segs], source="recognized" if kind == "recognized" else "file",
                  scores=10 * np.log(conf) if kind != "hand-checked" else None,
                  provenance=Provenance(kind))


SEGS = [(0, .3, "sil"), (.3, .6, "m"), (.6, .9, "aa"), (.9, 1.2, "n"), (1.2, 1.5, "b"),
        (1.5, 1.8, "s"), (1.8, 2.1, "sil")]
T = np.arange(21) / 10
#: closed is 11 mm: /m/ closes, /aa/ opens, /n/ shuts half its middle, /b/ stays 5 mm open
APERTURE = np.array([14, 14, 14, 11, 11.1, 12, 18, 20, 18, 13, 11.5, 13, 16, 17, 16, 15, 14, 15,
                     14, 14, 14.0])


def test_the_reasons_in_their_order_each_worst_first():
    lab = labels(SEGS, [.9, .1, .05, .2, .9, .02, .9])
    got = [(r.segment.label, r.reason, round(r.score, 2)) for r in review(lab, T, APERTURE, 11.0)]
    assert got == [
        ("b", REASONS[0], 5.0),                    # lips open at /b/: 16 mm at best
        ("n", REASONS[1], 0.5),                    # middle 0.975-1.125 s: 1 of its 2 frames shut
        ("m", REASONS[3], 2.9),                    # a doubted /m/ before the doubted consonant
        ("s", REASONS[3], 1.98),                   # the consonant, least sure first
        ("n", REASONS[3], 1.8),
        ("aa", REASONS[3], 0.95)]                  # the vowel last
    assert counts(review(lab, T, APERTURE, 11.0)) == {REASONS[0]: 1, REASONS[1]: 1, REASONS[3]: 4}


def test_the_talkers_lips_and_hand_checked_labels():
    lab = labels(SEGS, None, "hand-checked")
    talker = APERTURE.copy()
    talker[12:15] += 6.0                           # the talker's /b/ wider by 6 mm
    items = review(lab, T, APERTURE, 11.0, talker=talker)
    assert [(r.segment.label, r.reason) for r in items] == [
        ("b", REASONS[0]), ("n", REASONS[1]), ("b", REASONS[2])]
    assert items[2].detail == "the synthesized lips 6.0 mm narrower than the talker's"


def test_a_phone_corrected_by_hand_leaves_the_list():
    lab = labels(SEGS, [.9, .1, .05, .2, .9, .02, .9])
    doc = LabelDocument(lab, 2.1, 60.0)
    doc.select(PHONES, 3)
    doc.rename("m")                                 # the /n/ checked by hand: a /m/
    now = doc.labels_now()
    left = [(r.segment.label, r.reason) for r in review(now, T, APERTURE, 11.0)]
    assert ("n", REASONS[1]) not in left and ("n", REASONS[3]) not in left
    assert ("m", REASONS[3]) in left               # the other /m/ is still doubted


@pytest.mark.skipif(not ARCTIC.is_dir(), reason="the ARCTIC recordings are not here")
def test_the_recognizers_doubtful_bilabials_lead_the_list_of_a_real_recording(default_model):
    """axb_a0004 "Lord, but I'm glad": recognized, its false /m/ (0.80 s) and /p/ (1.44 s, the
    /t/ of "to") are the first two; the /n/ of "I'm" (1.10 s) is in the list."""
    from facetraj_engine.evaluation.closure import lip_aperture
    from facetraj_engine.io.label_rule import LabelRequest
    from facetraj_engine.workflow.recording import synthesize_recording

    model = default_model
    done = synthesize_recording(model, ARCTIC / "cmu_arctic_us_axb_a0004.wav", None,
                                LabelRequest(recognize=True))
    res = done.synthesis
    items = review(done.labels, res.times, lip_aperture(res.markers, model.upper_lip, model.lower_lip),
                   model.closure.closed)
    first = [(r.segment.label, round(r.segment.start, 2)) for r in items[:2]]
    assert first == [("m", 0.8), ("p", 1.44)]
    assert ("n", 1.1) in [(r.segment.label, round(r.segment.start, 2)) for r in items]
