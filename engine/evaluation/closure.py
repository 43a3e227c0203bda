"""Do the lips close? Bilabial closure measured as a phonetician checks it (issue 25).

The lip aperture is the upper-lip centre's y minus the lower-lip centre's y (the model's
``upper_lip`` and ``lower_lip`` markers, head frame, mm). For each /p b m/ segment of the
reference labels, the smallest aperture inside it; a closure counts when that minimum is within
``tol`` (1 mm) of the talker's closed aperture -- for a synthesized face the training talker's
(:attr:`facetraj_engine.method.closure.ClosureStats.closed`). Beside it, so that lips shut all the time
cannot pass: the median over vowels of each vowel's largest aperture, and the median over pauses
(silences over 150 ms) of each pause's median aperture.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..data import PhoneSegment
from ..method.closure import BILABIALS

#: ARPAbet vowels (whose largest aperture shows the mouth still opens).
VOWELS = ("aa", "ae", "ah", "ao", "aw", "ay", "eh", "er", "ey", "ih", "iy", "ow", "oy", "uh", "uw")
#: Pauses: silences longer than this (seconds).
PAUSE_S = 0.15


def lip_aperture(markers: np.ndarray, upper: int, lower: int) -> np.ndarray:
    """``(T,)`` upper-lip y minus lower-lip y of ``(T, M, 3)`` markers (mm, y up).

    >>> m = np.zeros((2, 2, 3)); m[:, 0, 1] = [12.0, 20.0]; m[:, 1, 1] = [1.0, 0.5]
    >>> lip_aperture(m, 0, 1).tolist()
    [11.0, 19.5]
    """
    m = np.asarray(markers, dtype=np.float64)
    return m[:, upper, 1] - m[:, lower, 1]


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
    minimum (``minima``), per vowel its maximum, per pause its median."""

    closed: float
    minima: np.ndarray
    vowel_maxima: np.ndarray
    pause_medians: np.ndarray
    tol: float = 1.0

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

    def to_json(self) -> dict:
        return {"n": self.n, "within": self.within, "median_min": self.median_min,
                "vowel_max": self.vowel_max, "pause": self.pause, "closed": self.closed}

    @classmethod
    def pooled(cls, parts: Sequence[ClosureScore]) -> ClosureScore:
        """Several utterances' scores as one (the same reference)."""
        return cls(parts[0].closed, *(np.concatenate([getattr(p, f) for p in parts])
                                      for f in ("minima", "vowel_maxima", "pause_medians")),
                   parts[0].tol)


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
    >>> (s.n, s.within, s.median_min, s.vowel_max, s.pause)
    (2, 0.5, 11.75, 20.0, 11.0)
    """
    pauses = [s for s in phones if s.label == "sil" and s.end - s.start > PAUSE_S]
    return ClosureScore(float(closed),
                        segment_values(aperture, times, [s for s in phones if s.label in BILABIALS], "min"),
                        segment_values(aperture, times, [s for s in phones if s.label in VOWELS], "max"),
                        segment_values(aperture, times, pauses, "median"), tol)
