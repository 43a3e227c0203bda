"""The bilabial-closure detector on a stream (live mode acoustic-only, issue 40): the
probabilities of :mod:`facetraj_engine.method.closure_detector` as the frames arrive, equal to the
offline ones frame for frame.

Frame t's probability needs the frames up to t + 3 (its features' last offset); the energy dip
and the running mean of the LSFs look only back, so they carry from block to block (the last
``back`` energies, the running sums). At the end the last frames are repeated, as offline. The
acoustic search's opinion (step 6) counts by the voice match known when the probability is
computed (offline: the whole recording's), in both from the frame after the voice has been heard
(:func:`facetraj_engine.method.voice_match.match_from`).
"""

from __future__ import annotations

import numpy as np

from ..method.closure_detector import ClosureDetector, closure_runs, frame_rows, stacked
from ..method.voice_match import frame_matches


class DetectorStream:
    """Frames' LSFs and energies in, in order (:meth:`feed`; :meth:`flush` at the end); their
    probabilities out as soon as they are known (the last ``KEEP_S`` of them kept for
    :meth:`runs`)."""

    KEEP_S = 4.0

    def __init__(self, detector: ClosureDetector, rate: float):
        self.detector = detector
        self.rate = float(rate)
        self.spec = spec = detector.spec
        self._behind = max(0, -min(spec.offsets))       # rows before a frame its features need
        self._energy = np.zeros(0)                     # the last `back` energies
        self._sums: tuple[np.ndarray, float] | None = None
        self._rows = np.zeros((0, 1 + spec.n_lsf))     # rows of frames self._first ...
        self._search = np.zeros((0, 2))                # the search's rows of the same frames
        self._first = 0
        self._p = np.zeros(0)                          # probabilities of frames self._p0 ...
        self._p0 = 0
        self._given: list[np.ndarray] = []              # every probability given out
        self.known = 0                                  # frames whose probability is out

    def probabilities(self) -> np.ndarray:
        """``(known,)`` every probability given out (a take's record: 8 bytes a frame)."""
        return np.concatenate(self._given) if self._given else np.zeros(0)

    def feed(self, lsf: np.ndarray, energy_db: np.ndarray, search: np.ndarray | None = None,
             match: float = 0.0, trusted_from: int = 0) -> np.ndarray:
        """The next frames' LSFs ``(n, P)``, energies ``(n,)`` and the search's rows ``(n, 2)``
        (:mod:`facetraj_engine.method.closure_search`; ``None``: not known); the probabilities
        now known, the search's opinion counting by the voice ``match`` in frames from
        ``trusted_from`` on (before it the prior, as offline:
        :func:`facetraj_engine.method.voice_match.frame_matches`)."""
        if len(energy_db):
            rows, self._sums = frame_rows(lsf, energy_db, self.spec, self.detector.lsf_mean,
                                          self._energy, self._sums)
            self._energy = np.concatenate([self._energy, energy_db])[-self.spec.back:]
            self._rows = np.concatenate([self._rows, rows])
            self._search = np.concatenate([self._search, np.zeros((len(rows), 2)) if search is None
                                           else search])
        return self._out(self._first + len(self._rows) - self.spec.ahead, match, trusted_from)

    def flush(self, match: float = 0.0, trusted_from: int = 0) -> np.ndarray:
        """The probabilities of the remaining frames (the input ended: its last frame repeated)."""
        return self._out(self._first + len(self._rows), match, trusted_from)

    def runs(self, since: int, threshold: float, final: bool = False) -> np.ndarray:
        """``(J, 2)`` closures (seconds, step 6) among the frames known from frame ``since`` on;
        a run reaching the last known frame has not ended (``inf``) unless ``final``."""
        since = max(since, self._p0)
        p = self._p[since - self._p0:]
        return closure_runs(p, np.arange(since, since + len(p)) / self.rate, threshold,
                            self.spec.min_frames, open_end=not final)

    def record_runs(self, threshold: float) -> np.ndarray:
        """``(J, 2)`` closures (seconds, step 6) among every probability given out (the take's
        record, :meth:`probabilities`), ended."""
        p = self.probabilities()
        return closure_runs(p, np.arange(len(p)) / self.rate, threshold, self.spec.min_frames)

    def _out(self, stop: int, match: float, trusted_from: int) -> np.ndarray:
        """Probabilities of frames ``known .. stop - 1`` (their rows are in)."""
        if stop <= self.known:
            return np.zeros(0)
        lo = self.known - self._first                  # in self._rows
        # the rows kept reach 3 before lo, and past stop - 1 by 3 except at the end (whose last
        # row is repeated, as offline): clipping to them is offline's clipping to the input
        x = stacked(self._rows, self.spec.offsets, lo, stop - self.known)
        xs = stacked(self._search, self.spec.offsets, lo, stop - self.known)
        first = min(max(trusted_from - self.known, 0), stop - self.known)
        p = self.detector.probability(x, xs, frame_matches(match, stop - self.known, first))
        self._given.append(p)
        self._p = np.concatenate([self._p, p])
        cut = len(self._p) - int(self.KEEP_S * self.rate)
        if cut > 0:
            self._p, self._p0 = self._p[cut:], self._p0 + cut
        self.known = stop
        drop = self.known - self._behind - self._first
        if drop > 0:
            self._rows, self._search = self._rows[drop:], self._search[drop:]
            self._first += drop
        return p
