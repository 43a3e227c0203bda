"""The closure step on a stream (live mode, issue 27): lips that close at the settled /p b m/,
and a face that rests in pauses, as far as a frame's emission time lets them be known.

Offline (:mod:`facetraj_engine.method.closure`), the lips at /p b m/ segment j move by
``c_j = s_j min(0, closed - m_j)`` along the closing direction, ``m_j`` the smallest aperture of
the segment's frames, flat over the segment with raised-cosine tapers outside it; and the face
blends to the rest face inside pauses. A stream emits frame t before the frames after it are
known. Here ``m_j`` is the smallest aperture of the segment's frames *known when frame t is
emitted* (those up to ``seen[t]``), or frame t's own when none is: frames inside the segment reach
the closed aperture at its first frame and wherever the aperture falls below what came before;
frames before it (the first taper) close towards it from their own aperture. With every frame
known, the moves are the offline ones (tested). A /p b m/ or a pause still going on when a frame is
emitted has no end yet (its end is infinity).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..method.closure import ClosurePlan, ClosureStats, aperture_functional, bump
from ..method.model import Model
from ..method.speech import speech_runs
from .speech import SILENT, UNRANGED


def closure_moves(aperture: np.ndarray, times: np.ndarray, intervals: np.ndarray,
                  strengths: np.ndarray, closed: float, taper_s: float, seen: np.ndarray,
                  at: np.ndarray | None = None, clamp: bool = False) -> np.ndarray:
    """Per frame t, the aperture move ``c(t)`` (mm, at most 0) of
    :func:`facetraj_engine.method.closure.close_lips`, each segment's minimum taken over its frames up to
    ``seen[t]`` (frame t's own aperture when none of them is): the move the step makes when frame
    t is emitted. ``at``: the frames to compute (default all); the result is one move per frame
    of ``at``. With ``clamp``, no frame is moved past the closed aperture (offline a frame can be,
    where a taper after a segment meets a frame already closer than the segment's minimum).

    >>> a = np.array([15.0, 14.0, 13.0, 16.0, 15.0]); t = np.arange(5) / 10
    >>> iv, s = np.array([[0.1, 0.3]]), np.array([1.0])
    >>> closure_moves(a, t, iv, s, 11.0, 0.15, np.arange(5)).round(9).tolist()    # causal
    [-1.0, -3.0, -2.0, -2.0, -0.5]
    >>> closure_moves(a, t, iv, s, 11.0, 0.15, np.full(5, 4)).round(9).tolist()   # offline
    [-0.5, -2.0, -2.0, -2.0, -0.5]
    """
    a = np.asarray(aperture, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    seen = np.asarray(seen)
    at = np.arange(len(a)) if at is None else np.asarray(at)
    c = np.zeros(len(at))
    for (t0, t1), s in zip(intervals, strengths, strict=True):
        idx = np.flatnonzero((times >= t0) & (times < t1))
        if idx.size == 0:                                # shorter than a frame: its nearest one
            idx = np.array([int(np.argmin(np.abs(times - 0.5 * (t0 + min(t1, times[-1])))))])
        w = bump(times[at], t0, t1, taper_s)
        for k in np.flatnonzero(w > 0):
            t = at[k]
            known = idx[idx <= seen[t]]
            m = float(a[known].min()) if known.size else float(a[t])
            c[k] = min(c[k], s * min(0.0, closed - m) * w[k])
    return c if not clamp else np.maximum(c, np.minimum(0.0, closed - a[at]))


def rest_weights(times: np.ndarray, pauses: np.ndarray, taper_s: float) -> np.ndarray:
    """Per frame, how far the face rests (:func:`facetraj_engine.method.closure.rest_in_pauses`'s
    weight): 1 inside a pause, raised-cosine tapers inside it, 0 outside; a pause without an end
    (``inf``) has no closing taper.

    >>> rest_weights(np.arange(7) / 10, np.array([[0.1, np.inf]]), 0.2).round(9).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0]
    """
    b = np.zeros(len(times))
    for t0, t1 in pauses:
        b = np.maximum(b, bump(times, t0, t1, taper_s, inside=True))
    return b


def pause_runs(decisions: np.ndarray, times: np.ndarray, min_s: float) -> np.ndarray:
    """``(J, 2)`` pauses among the frames decided so far (:mod:`facetraj_engine.streaming.speech`): runs
    of silent frames longer than ``min_s`` as :func:`facetraj_engine.method.speech.pauses` finds them; a
    run reaching the last decided frame has not ended (``inf``) and counts once it is longer than
    ``min_s``.

    >>> d = np.array([0, 0, 0, 1, 0, 0, 0, 0])
    >>> pause_runs(d, np.arange(8) / 10, 0.25).tolist()
    [[0.0, 0.30000000000000004], [0.4, inf]]
    """
    silent = np.asarray(decisions) == SILENT
    runs = speech_runs(silent, times, 0.0)
    if len(runs) and silent[-1]:
        runs[-1, 1] = np.inf
    length = np.where(np.isfinite(runs[:, 1]), runs[:, 1] - runs[:, 0],
                      times[-1] - runs[:, 0] if len(times) else 0.0)
    return runs[length > min_s]


def decided_pauses(decisions: Sequence[int], first: int, rate: float, min_s: float,
                   unranged_silent: Callable[[np.ndarray], np.ndarray] | None = None
                   ) -> np.ndarray:
    """:func:`pause_runs` among the decisions from frame ``first`` on (``rate`` frames a second);
    a frame whose energy is not ranged yet counts as silent where ``unranged_silent(times)`` says
    so (the recognizer's silence), else as speech (nothing rests).

    >>> decided_pauses([SILENT] * 3 + [UNRANGED] * 3, 1, 10.0, 0.1).tolist()
    [[0.1, 0.30000000000000004]]
    >>> decided_pauses([UNRANGED] * 4, 0, 10.0, 0.1, lambda t: t < 1).tolist()
    [[0.0, inf]]
    """
    dec = np.asarray(decisions[first:])
    if not len(dec):
        return np.zeros((0, 2))
    times = np.arange(first, first + len(dec)) / rate
    silent = unranged_silent(times) if unranged_silent is not None else False
    return pause_runs(np.where((dec == UNRANGED) & silent, SILENT, dec), times, min_s)


class ClosureStream:
    """Smoothed PCs in (:meth:`feed`, with what is known of the /p b m/ and pauses then), the
    closure step applied out; frames are held ``hold`` frames so that the minimum of a /p b m/ can
    see that far ahead (0: none held). The last ``KEEP_S`` of PCs are kept for the minima."""

    KEEP_S = 2.0

    def __init__(self, model: Model, hold: int = 0, closure_taper_s: float = 0.05,
                 rest_taper_s: float = 0.05):
        if model.closure is None:
            raise ValueError("the model has no closure statistics: train it again")
        self.stats: ClosureStats = model.closure
        self.a0, self.g = aperture_functional(model.pca, model.upper_lip, model.lower_lip)
        self.rate = model.marker_rate
        self.hold = hold
        self.closure_taper_s, self.rest_taper_s = closure_taper_s, rest_taper_s
        self._pcs = np.zeros((0, len(self.g)))      # pre-closure PCs from frame self._first on
        self._first = 0
        self._emitted = 0

    @property
    def received(self) -> int:
        return self._first + len(self._pcs)

    def feed(self, pcs: np.ndarray, plan: ClosurePlan, final: bool = False) -> np.ndarray:
        """Take the next smoothed PCs; return the frames now due (all of them when ``final``),
        with the moves of ``plan`` (its intervals and pauses as known now)."""
        self._pcs = np.concatenate([self._pcs, np.asarray(pcs, dtype=np.float64)])
        stop = self.received if final else self.received - self.hold
        if stop <= self._emitted:
            return np.zeros((0, self._pcs.shape[1]))
        frames = np.arange(self._first, self.received)
        times = frames / self.rate
        a = self.a0 + self._pcs @ self.g
        emit = slice(self._emitted - self._first, stop - self._first)
        seen = np.minimum(np.arange(len(frames)) + self.hold, len(frames) - 1)
        c = closure_moves(a, times, plan.intervals, plan.strengths, self.stats.closed,
                          self.closure_taper_s, seen, np.arange(len(frames))[emit], clamp=True)
        out = self._pcs[emit] + c[:, None] * self.stats.direction[None, :]
        b = rest_weights(times[emit], plan.pauses, self.rest_taper_s)
        out = out + b[:, None] * (self.stats.rest[None, :] - out)
        self._emitted = stop
        drop = min(self._emitted, self.received - int(self.KEEP_S * self.rate)) - self._first
        if drop > 0:
            self._pcs = self._pcs[drop:]
            self._first += drop
        return out
