"""Do the lips close? Bilabial closure measured as a phonetician checks it (issue 25).

The lip aperture is the upper-lip centre's y minus the lower-lip centre's y (the model's
``upper_lip`` and ``lower_lip`` markers, head frame, mm). For each /p b m/ segment of the
reference labels, the smallest aperture inside it; a closure counts when that minimum is within
``tol`` (1 mm) of the talker's closed aperture -- for a synthesized face the training talker's
(:attr:`facetraj_engine.method.closure.ClosureStats.closed`). Beside it, so that lips shut all the time
cannot pass: the median over vowels of each vowel's largest aperture, and the median over pauses
(silences over 150 ms) of each pause's median aperture; and where lips shut with no /p b m/ there
(issue 40): the share of vowels whose largest aperture is within ``tol`` of closed (shut
throughout), and of the non-labial consonants (not /p b m f v w/) whose smallest aperture over
the middle half of the segment is (issue 46: the lips have no business closing there, and the
middle half leaves out the tapers a true closure next door may reach into).

The bilabial-closure detector's own score (:func:`detector_score`): the /p b m/ its closures
reach, and its closures that reach none (false closures), by what they fall on.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..data import PhoneSegment
from ..method.closure import BILABIALS

#: ARPAbet vowels (whose largest aperture shows the mouth still opens).
VOWELS = ("aa", "ae", "ah", "ao", "aw", "ay", "eh", "er", "ey", "ih", "iy", "ow", "oy", "uh", "uw")
#: Pauses: silences longer than this (seconds).
PAUSE_S = 0.15
#: Silence labels (neither vowels nor consonants).
SILENCES = ("sil", "sp")
#: The consonants whose lips may close or nearly close (bilabials, labiodentals, /w/): left out of
#: "other consonants shut".
LABIALS = (*BILABIALS, "f", "v", "w")


def lip_aperture(markers: np.ndarray, upper: int, lower: int) -> np.ndarray:
    """``(T,)`` upper-lip y minus lower-lip y of ``(T, M, 3)`` markers (mm, y up).

    >>> m = np.zeros((2, 2, 3)); m[:, 0, 1] = [12.0, 20.0]; m[:, 1, 1] = [1.0, 0.5]
    >>> lip_aperture(m, 0, 1).tolist()
    [11.0, 19.5]
    """
    m = np.asarray(markers, dtype=np.float64)
    return m[:, upper, 1] - m[:, lower, 1]


def middle_half(segment: PhoneSegment) -> PhoneSegment:
    """The middle half of ``segment`` (a quarter of its length off each end).

    >>> middle_half(PhoneSegment(1.0, 1.4, "n"))
    PhoneSegment(start=1.1, end=1.3, label='n')
    """
    quarter = 0.25 * (segment.end - segment.start)
    return PhoneSegment(round(segment.start + quarter, 12), round(segment.end - quarter, 12),
                        segment.label)


def segment_frames(start: float, end: float, times: np.ndarray) -> np.ndarray:
    """The frames whose time lies in ``[start, end)``; a segment shorter than a frame gets the
    frame nearest its centre.

    >>> t = np.arange(6) / 60
    >>> segment_frames(0.02, 0.06, t).tolist(), segment_frames(0.02, 0.03, t).tolist()
    ([2, 3], [2])
    """
    times = np.asarray(times, dtype=np.float64)
    idx = np.flatnonzero((times >= start) & (times < end))
    return idx if idx.size else np.array([int(np.argmin(np.abs(times - 0.5 * (start + end))))])


def segment_values(aperture: np.ndarray, times: np.ndarray, segments: Sequence[PhoneSegment],
                   how: str) -> np.ndarray:
    """Per segment the ``min``, ``max`` or ``median`` aperture of its frames (NaN frames left
    out; NaN for a segment without a seen frame).

    >>> a = np.array([5.0, 3.0, 4.0, 9.0]); t = np.arange(4) / 10
    >>> segs = [PhoneSegment(0, .25, "b"), PhoneSegment(.25, .4, "aa")]
    >>> segment_values(a, t, segs, "min").tolist(), segment_values(a, t, segs, "max").tolist()
    ([3.0, 9.0], [5.0, 9.0])
    """
    f = {"min": np.nanmin, "max": np.nanmax, "median": np.nanmedian}[how]
    out = []
    for s in segments:
        a = aperture[segment_frames(s.start, s.end, times)]
        out.append(float(f(a)) if np.isfinite(a).any() else float("nan"))
    return np.asarray(out, dtype=np.float64)


@dataclass(frozen=True)
class ClosureScore:
    """The closure of one or more utterances against the ``closed`` aperture: per /p b m/ its
    minimum (``minima``), per vowel its maximum, per pause its median, per non-labial consonant
    its minimum over the segment's middle half."""

    closed: float
    minima: np.ndarray
    vowel_maxima: np.ndarray
    pause_medians: np.ndarray
    tol: float = 1.0
    consonant_minima: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def n(self) -> int:
        return int(np.isfinite(self.minima).sum())

    @property
    def within(self) -> float:
        """The share of /p b m/ whose minimum is within ``tol`` of closed."""
        m = self.minima[np.isfinite(self.minima)]
        return float(np.mean(np.abs(m - self.closed) <= self.tol)) if m.size else float("nan")

    @property
    def median_min(self) -> float:
        return _median(self.minima)

    @property
    def vowel_max(self) -> float:
        return _median(self.vowel_maxima)

    @property
    def pause(self) -> float:
        return _median(self.pause_medians)

    @property
    def vowels_shut(self) -> float:
        """The share of vowels whose largest aperture is within ``tol`` of closed."""
        return _share(self.vowel_maxima <= self.closed + self.tol, self.vowel_maxima)

    @property
    def consonants_shut(self) -> float:
        """The share of the non-labial consonants whose smallest aperture over the middle half of
        the segment is within ``tol`` of closed."""
        return _share(self.consonant_minima <= self.closed + self.tol, self.consonant_minima)

    def to_json(self) -> dict:
        return {"n": self.n, "within": self.within, "median_min": self.median_min,
                "vowel_max": self.vowel_max, "pause": self.pause, "closed": self.closed,
                "vowels": int(np.isfinite(self.vowel_maxima).sum()), "vowels_shut": self.vowels_shut,
                "consonants": int(np.isfinite(self.consonant_minima).sum()),
                "consonants_shut": self.consonants_shut}

    @classmethod
    def pooled(cls, parts: Sequence[ClosureScore]) -> ClosureScore:
        """Several utterances' scores as one (the same reference)."""
        return cls(parts[0].closed, *(np.concatenate([getattr(p, f) for p in parts])
                                      for f in ("minima", "vowel_maxima", "pause_medians")),
                   parts[0].tol, np.concatenate([p.consonant_minima for p in parts]))


def _share(hit: np.ndarray, values: np.ndarray) -> float:
    """The share of ``hit`` among the finite ``values`` (NaN when there are none)."""
    ok = np.isfinite(values)
    return float(np.mean(hit[ok])) if ok.any() else float("nan")


def _median(x: np.ndarray) -> float:
    x = np.asarray(x, dtype=np.float64)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size else float("nan")


def closure_score(aperture: np.ndarray, times: np.ndarray, phones: Sequence[PhoneSegment],
                  closed: float, tol: float = 1.0) -> ClosureScore:
    """The closure of one utterance: its ``aperture`` at ``times`` measured at the segments of
    the reference ``phones`` (exact labels, or aligned from the transcript).

    >>> t = np.arange(12) / 10
    >>> a = np.array([11, 11, 11, 15, 12.5, 15, 19, 20, 18, 11.2, 11.5, 11])
    >>> segs = [PhoneSegment(0, .3, "sil"), PhoneSegment(.3, .6, "b"), PhoneSegment(.6, .9, "aa"),
    ...         PhoneSegment(.9, 1.2, "m")]
    >>> s = closure_score(a, t, segs, closed=11.0)
    >>> (s.n, s.within, s.median_min, s.vowel_max, s.pause, s.vowels_shut)
    (2, 0.5, 11.75, 20.0, 11.0, 0.0)
    """
    pauses = [s for s in phones if s.label == "sil" and s.end - s.start > PAUSE_S]
    others = [middle_half(s) for s in phones if s.label not in LABIALS + VOWELS + SILENCES]
    return ClosureScore(float(closed),
                        segment_values(aperture, times, [s for s in phones if s.label in BILABIALS], "min"),
                        segment_values(aperture, times, [s for s in phones if s.label in VOWELS], "max"),
                        segment_values(aperture, times, pauses, "median"), tol,
                        segment_values(aperture, times, others, "min"))


# --------------------------------------------------------------------------- the detector's own
@dataclass(frozen=True)
class DetectorScore:
    """Closures (``[start, end)`` intervals: the detector's) against reference labels: the
    /p b m/ they reach (``found`` of ``n``), how many there were (``closures``), and those that
    reach none (false closures) by what most of their frames are: a vowel, another consonant,
    silence; over ``seconds`` of input."""

    found: int
    n: int
    closures: int
    false_vowel: int
    false_consonant: int
    false_silence: int
    seconds: float

    @property
    def false(self) -> int:
        return self.false_vowel + self.false_consonant + self.false_silence

    @property
    def recall(self) -> float:
        return self.found / self.n if self.n else float("nan")

    @property
    def precision(self) -> float:
        """The share of closures that reach a /p b m/."""
        return (self.closures - self.false) / self.closures if self.closures else float("nan")

    @property
    def false_per_minute(self) -> float:
        return 60.0 * self.false / self.seconds if self.seconds > 0 else float("nan")

    def to_json(self) -> dict:
        return {"found": self.found, "n": self.n, "closures": self.closures,
                "false_vowel": self.false_vowel, "false_consonant": self.false_consonant,
                "false_silence": self.false_silence, "seconds": self.seconds,
                "recall": self.recall, "precision": self.precision,
                "false_per_minute": self.false_per_minute}

    @classmethod
    def pooled(cls, parts: Sequence[DetectorScore]) -> DetectorScore:
        return cls(*(sum(getattr(p, f) for p in parts) for f in
                     ("found", "n", "closures", "false_vowel", "false_consonant", "false_silence",
                      "seconds")))


def detector_score(intervals: np.ndarray, times: np.ndarray,
                   phones: Sequence[PhoneSegment]) -> DetectorScore:
    """The closures ``intervals`` ``(J, 2)`` of one utterance (frames at ``times``) against its
    reference ``phones``: a /p b m/ is found when a closure holds one of its frames; a closure
    holding no /p b m/ frame is false, and falls on the kind of phone most of its frames are.

    >>> t = np.arange(10) / 10
    >>> segs = [PhoneSegment(0, .2, "sil"), PhoneSegment(.2, .4, "b"), PhoneSegment(.4, .7, "aa"),
    ...         PhoneSegment(.7, .8, "t"), PhoneSegment(.8, 1.0, "m")]
    >>> s = detector_score(np.array([[0.3, 0.5], [0.5, 0.7], [0.7, 0.8]]), t, segs)
    >>> (s.found, s.n, s.closures, s.false_vowel, s.false_consonant, s.false_silence)
    (1, 2, 3, 1, 1, 0)
    """
    times = np.asarray(times, dtype=np.float64)
    label = np.full(len(times), "sil", dtype=object)
    for s in phones:
        label[segment_frames(s.start, s.end, times)] = s.label
    closed = np.zeros(len(times), dtype=bool)
    kinds = {"vowel": 0, "consonant": 0, "silence": 0}
    for t0, t1 in np.asarray(intervals, dtype=np.float64).reshape(-1, 2):
        idx = segment_frames(t0, t1, times)
        closed[idx] = True
        held = label[idx]
        if np.isin(held, BILABIALS).any():
            continue
        counts = {"vowel": np.isin(held, VOWELS).sum(), "silence": np.isin(held, SILENCES).sum()}
        counts["consonant"] = len(held) - counts["vowel"] - counts["silence"]
        kinds[max(counts, key=lambda k: (counts[k], k == "consonant"))] += 1
    bil = [segment_frames(s.start, s.end, times) for s in phones if s.label in BILABIALS]
    seconds = float(len(times) * (times[1] - times[0])) if len(times) > 1 else 0.0
    return DetectorScore(sum(bool(closed[i].any()) for i in bil), len(bil), len(intervals),
                         kinds["vowel"], kinds["consonant"], kinds["silence"], seconds)
