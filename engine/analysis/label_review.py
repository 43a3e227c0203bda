"""Where to look first in labels being corrected (issue 56): the segments most worth a look,
ranked, from the labels and the synthesis they gave.

Four reasons, in this order (within each, the worst first):

1. **lips open at /p b m/**: a bilabial whose synthesized lips never come within ``tol`` of
   closed (the closure judge's measure, :mod:`facetraj_engine.evaluation.closure`): the label may
   be misplaced, or the synthesis fails there; worst: farthest from closed;
2. **lips shut at a consonant**: a consonant other than /p b m f v w/ whose synthesized lips are
   within ``tol`` of closed over the middle half of the segment (a /b/ heard where there is
   none, a bilabial begun too early next to it); worst: most of its middle half shut;
3. **lips unlike the talker's** (an utterance with the talker's own face): the phones whose
   synthesized aperture differs most from the talker's (mean over the segment, at least
   ``talker_mm``); worst: the largest difference;
4. **low confidence**: phones of automatic labels whose maker was unsure (confidence under
   ``low``); the /p b m/ first (the lips close there: a false one shuts them where they should
   not be), then the other consonants, then the vowels, each the least sure first.

A phone checked by hand (changed in the editor, or corrected in Praat) is left out: a person has
looked at it. Silence is never listed. Plain arrays in, a list out (``app/review_dock.py`` shows
it and jumps to a segment).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..data import PhoneSegment
from ..evaluation.closure import LABIALS, SILENCES, VOWELS, middle_half, segment_frames
from ..labels.provenance import Labels
from ..method.closure import BILABIALS

#: the reasons, in the order they are listed
REASONS = ("lips open at /p b m/", "lips shut at a consonant", "lips unlike the talker's",
           "low confidence")
#: a phone of automatic labels is doubted below this confidence
LOW_CONFIDENCE = 0.25
#: a phone's synthesized aperture this far from the talker's (mean, mm) is worth a look
TALKER_MM = 3.0


@dataclass(frozen=True)
class ReviewItem:
    """One segment worth a look: its phone index and segment, why (one of :data:`REASONS`), the
    figure behind it in words (``detail``) and as a number to rank by (``score``: larger is
    worse)."""

    index: int
    segment: PhoneSegment
    reason: str
    detail: str
    score: float

    @property
    def rank_key(self) -> tuple[int, float]:
        return REASONS.index(self.reason), -self.score


def review(labels: Labels, times: np.ndarray, aperture: np.ndarray, closed: float,
           talker: np.ndarray | None = None, tol: float = 1.0, low: float = LOW_CONFIDENCE,
           talker_mm: float = TALKER_MM) -> list[ReviewItem]:
    """The segments of ``labels`` worth a look, ranked (see the module): ``aperture`` the
    synthesized lip aperture at ``times`` (upper lip y minus lower lip y, mm), ``closed`` the
    aperture of closed lips, ``talker`` the talker's own aperture at ``times`` (None: none).

    >>> from facetraj_engine.data import Provenance
    >>> segs = [PhoneSegment(0, .3, "sil"), PhoneSegment(.3, .6, "b"), PhoneSegment(.6, .9, "t"),
    ...         PhoneSegment(.9, 1.2, "aa")]
    >>> lab = Labels(segs, source="recognized", scores=10 * np.log([.9, .9, .1, .9]),
    ...              provenance=Provenance("recognized"))
    >>> t = np.arange(12) / 10
    >>> a = np.array([11, 11, 11, 15, 16, 15, 11, 11.2, 11, 18, 20, 18.0])
    >>> [(r.segment.label, r.reason, r.detail) for r in review(lab, t, a, closed=11.0)]
    ... # doctest: +NORMALIZE_WHITESPACE
    [('b', 'lips open at /p b m/', 'the lips stay 4.0 mm from closed'),
     ('t', 'lips shut at a consonant', 'the lips shut over 100 % of its middle'),
     ('t', 'low confidence', 'recognized, confidence 0.10')]
    """
    times = np.asarray(times, dtype=np.float64)
    aperture = np.asarray(aperture, dtype=np.float64)
    hand = labels.hand_checked
    auto = not labels.provenance.hand_checked
    conf = labels.confidence
    items: list[ReviewItem] = []
    for i, seg in enumerate(labels.phones):
        if seg.label in SILENCES or (auto and hand[i]):
            continue
        items += _lips(i, seg, times, aperture, closed, tol)
        if talker is not None:
            items += _talker(i, seg, times, aperture, np.asarray(talker, float), talker_mm)
        if auto and np.isfinite(conf[i]) and conf[i] < low:
            weight = 2.0 if seg.label in BILABIALS else 0.0 if seg.label in VOWELS else 1.0
            items.append(ReviewItem(i, seg, REASONS[3], f"{labels.provenance.kind}, confidence "
                                    f"{conf[i]:.2f}", weight + float(1.0 - conf[i])))
    return sorted(items, key=lambda r: r.rank_key)


def _lips(i: int, seg: PhoneSegment, times: np.ndarray, aperture: np.ndarray, closed: float,
          tol: float) -> list[ReviewItem]:
    """A bilabial whose lips stay open, a non-labial consonant whose lips shut."""
    if seg.label in BILABIALS:
        low = np.nanmin(aperture[segment_frames(seg.start, seg.end, times)], initial=np.inf)
        if np.isfinite(low) and low - closed > tol:
            return [ReviewItem(i, seg, REASONS[0], f"the lips stay {low - closed:.1f} mm from "
                               "closed", float(low - closed))]
    elif seg.label not in LABIALS + VOWELS:
        mid = middle_half(seg)
        values = aperture[segment_frames(mid.start, mid.end, times)]
        shut = float(np.mean(values <= closed + tol)) if values.size else 0.0
        if shut > 0:
            return [ReviewItem(i, seg, REASONS[1], f"the lips shut over {100 * shut:.0f} % of its "
                               "middle", shut)]
    return []


def _talker(i: int, seg: PhoneSegment, times: np.ndarray, aperture: np.ndarray,
            talker: np.ndarray, at_least: float) -> list[ReviewItem]:
    frames = segment_frames(seg.start, seg.end, times)
    diff = aperture[frames] - talker[frames]
    if not np.isfinite(diff).any():
        return []
    mean = float(np.nanmean(diff))
    if abs(mean) < at_least:
        return []
    how = "wider" if mean > 0 else "narrower"
    return [ReviewItem(i, seg, REASONS[2], f"the synthesized lips {abs(mean):.1f} mm {how} than "
                       "the talker's", abs(mean))]


def counts(items: Sequence[ReviewItem]) -> dict[str, int]:
    """How many items of each reason (in :data:`REASONS`' order, the reasons with none left out)."""
    out = {r: sum(1 for x in items if x.reason == r) for r in REASONS}
    return {r: n for r, n in out.items() if n}


__all__ = ["LOW_CONFIDENCE", "REASONS", "TALKER_MM", "ReviewItem", "counts", "review"]
