"""The closure step on a stream (live mode, issue 27): lips that close at the settled /p b m/
or where the detector finds a closure, and a face that rests in pauses, as far as a frame's
emission time lets them be known.

Offline (:mod:`facetraj_engine.method.closure`), the lips at a labelled /p b m/ segment j move by
``c_j = s_j min(0, closed - m_j)`` along the closing direction, ``m_j`` the smallest aperture of
the segment's frames, flat over the segment with raised-cosine tapers outside it. A stream emits
frame t before the frames after it are known. Here ``m_j`` is the smallest aperture of the
segment's frames *known when frame t is emitted* (those up to ``seen[t]``), or frame t's own when
none is: frames inside the segment reach the closed aperture at its first frame and wherever the
aperture falls below what came before; frames before it (the first taper) close towards it from
their own aperture. With every frame known, the moves are the offline ones (tested). A /p b m/
still going on when a frame is emitted has no end yet (its end is infinity).

The detector's closures and the rest in pauses are defined as a stream can make them offline
too (issue 46: :func:`facetraj_engine.method.closure.closure_moves` with ``lead=False``;
:func:`facetraj_engine.method.closure.rest_weights` reads a frame, those before it and the
``rest_lookahead_s`` after it, for which a stream holds the frame), so a stream makes them as
offline synthesis does, given the same probabilities and silent frames; once its input has ended
the frames after the end are silent, as offline.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from ..method.closure import (
    ClosurePlan,
    ClosureStats,
    aperture_functional,
    closure_moves,
    frame_rest,
    rest_ahead_frames,
)
from ..method.model import Model
from .speech import SILENT, SPEECH, UNRANGED


def decided_silence(decisions: Sequence[int], first: int,
                    unranged_silent: Callable[[np.ndarray], np.ndarray] | None = None,
                    rate: float = 60.0) -> tuple[np.ndarray, bool]:
    """The silent frames among a stream's decisions (:mod:`facetraj_engine.streaming.speech`) from
    frame ``first`` on, and whether none before ``first`` is speech (the take began in
    silence). A frame whose energy is not ranged yet -- the silence a take starts with, before
    the first words have spanned the range -- counts as silent, or where ``unranged_silent(times)``
    is given, as it says (the recognizer's silence).

    >>> decided_silence([UNRANGED, UNRANGED, SILENT, SPEECH, SILENT], 1)
    (array([ True,  True, False,  True]), True)
    >>> decided_silence([UNRANGED, SPEECH, SILENT], 2)
    (array([ True]), False)
    """
    dec = np.asarray(decisions, dtype=np.int64)
    if not len(dec) or first >= len(dec):
        return np.zeros(0, dtype=bool), not (dec == SPEECH).any()
    now = dec[first:]
    unranged = now == UNRANGED
    if unranged_silent is not None and unranged.any():
        unranged &= unranged_silent(np.arange(first, len(dec)) / rate)
    return (now == SILENT) | unranged, not (dec[:first] == SPEECH).any()


class ClosureStream:
    """Smoothed PCs in (:meth:`feed`, with what is known of the /p b m/ and pauses then), the
    closure step applied out; frames are held ``hold`` frames so that the minimum of a labelled
    /p b m/ can see that far ahead (0: none held), and until the speech or silence of the
    ``rest_lookahead_s`` after them is decided, which their rest reads. The last ``KEEP_S`` of PCs
    are kept for the minima."""

    KEEP_S = 2.0

    def __init__(self, model: Model, hold: int = 0, closure_taper_s: float = 0.05,
                 rest_taper_s: float = 0.05, rest_pause_s: float = 0.1,
                 rest_lookahead_s: float = 0.05):
        if model.closure is None:
            raise ValueError("the model has no closure statistics: train it again")
        self.stats: ClosureStats = model.closure
        self.a0, self.g = aperture_functional(model.pca, model.upper_lip, model.lower_lip)
        self.rate = model.marker_rate
        self.hold = hold
        self.closure_taper_s, self.rest_taper_s = closure_taper_s, rest_taper_s
        self.rest_pause_s = rest_pause_s
        self.ahead = rest_ahead_frames(rest_lookahead_s, self.rate)
        self._pcs = np.zeros((0, len(self.g)))      # pre-closure PCs from frame self._first on
        self._first = 0
        self._emitted = 0

    @property
    def received(self) -> int:
        return self._first + len(self._pcs)

    @property
    def emitted(self) -> int:
        return self._emitted

    def wait_s(self, decision_delay_s: float) -> float:
        """The most audio after a frame's time before it is due, when a frame's speech or
        silence is decided ``decision_delay_s`` after its time (the frames its rest reads)."""
        return decision_delay_s + self.ahead / self.rate

    @property
    def lookback(self) -> int:
        """Frames before the next to emit whose silence the rest rule reads
        (:func:`facetraj_engine.method.closure.rest_weights`: a pause's rest is full once it has
        lasted ``rest_pause_s + rest_taper_s``)."""
        return int(np.ceil((self.rest_pause_s + self.rest_taper_s) * self.rate)) + 2

    def feed(self, pcs: np.ndarray, plan: ClosurePlan, final: bool = False,
             decided: int | None = None) -> np.ndarray:
        """Take the next smoothed PCs; return the frames now due (all of them when ``final``: the
        input ended after them), with the moves of ``plan`` (its intervals and silent frames as
        known now); ``decided``: the frames whose speech or silence is known; a frame is due once
        the ``ahead`` frames after it are among them (its rest reads them)."""
        self._pcs = np.concatenate([self._pcs, np.asarray(pcs, dtype=np.float64)])
        stop = self.received if final else self.received - self.hold
        if decided is not None and not final:
            stop = min(stop, decided - self.ahead)
        if final:
            plan = replace(plan, end=self.received)
        if stop <= self._emitted:
            return np.zeros((0, self._pcs.shape[1]))
        frames = np.arange(self._first, self.received)
        times = frames / self.rate
        a = self.a0 + self._pcs @ self.g
        emit = np.arange(len(frames))[self._emitted - self._first: stop - self._first]
        seen = np.minimum(np.arange(len(frames)) + self.hold, len(frames) - 1)
        causal = plan.is_causal
        c = closure_moves(a, times, plan.intervals[~causal], plan.strengths[~causal],
                          self.stats.closed, self.closure_taper_s, seen, emit)
        c = np.minimum(c, closure_moves(a, times, plan.intervals[causal], plan.strengths[causal],
                                        self.stats.closed, self.closure_taper_s,
                                        np.arange(len(frames)), emit, lead=False))
        c = np.maximum(c, np.minimum(0.0, self.stats.closed - a[emit]))    # never past closed
        out = self._pcs[emit] + c[:, None] * self.stats.direction[None, :]
        b = frame_rest(plan, len(emit), self.rate, self.rest_pause_s, self.rest_taper_s,
                       self._emitted, self.ahead)
        out = out + b[:, None] * (self.stats.rest[None, :] - out)
        self._emitted = stop
        drop = min(self._emitted, self.received - int(self.KEEP_S * self.rate)) - self._first
        if drop > 0:
            self._pcs = self._pcs[drop:]
            self._first += drop
        return out
