"""The input LSFs of a stream (paper section 2.3's first step, on audio blocks as they arrive).

The same computation as :meth:`facetraj_engine.method.model.Model.input_lsf` (resampling to the model's
rate, pre-emphasis, 25 ms Hamming windows centred on the marker frames, LPC, LSFs), with the state
carried between blocks: the resampler's filter memory (``facetraj_engine.method.lsf.ResampleStream``), the
last sample for the pre-emphasis and the analysis samples not yet used by a frame. Frame t's
window is complete half a window (12.5 ms) after its time, plus the resampler's few samples.
"""

from __future__ import annotations

import numpy as np

from ..method.lsf import ResampleStream, frame_lsf, frame_start, frame_starts, preemphasize
from ..method.model import Model


class LsfFront:
    """Audio blocks in (:meth:`feed`, :meth:`flush`), the LSFs of any frames whose windows are in
    out (:meth:`lsf`); :meth:`release` forgets the samples before a frame's window."""

    def __init__(self, model: Model, sample_rate: int):
        mc = model.config
        self.sample_rate = int(sample_rate)
        self.rate = model.marker_rate
        self.order = mc.lpc_order
        self._audio_rate = mc.audio_rate
        self._preemphasis = mc.preemphasis
        self._resampler = ResampleStream(self.sample_rate, mc.audio_rate)
        self._n = int(round(mc.window_s * mc.audio_rate))          # analysis window, samples
        self._half = self._n // 2
        self._hamming = np.hamming(self._n)
        self._buffer = np.zeros(0)          # pre-emphasized analysis samples from self._first on
        self._first = 0
        self.analysed = 0                   # analysis samples received so far
        self._previous: float | None = None
        self.received = 0                   # input samples received so far
        self._complete = 0                  # frames whose windows are known to be complete

    @property
    def lookahead_s(self) -> float:
        """Audio needed after a frame's time before its window is complete."""
        return (self._n - self._half) / self._audio_rate + self._resampler.lookahead / self.sample_rate

    @property
    def received_s(self) -> float:
        return self.received / self.sample_rate

    def feed(self, block: np.ndarray) -> int:
        """Take the next ``block`` of samples; the number of frames whose windows are complete."""
        block = np.asarray(block, dtype=np.float64).ravel()
        self.received += len(block)
        self._append(self._resampler.feed(block))
        while self.window_start(self._complete) + self._n <= self.analysed:
            self._complete += 1
        return self._complete

    def flush(self) -> int:
        """The audio ended: the resampler's last samples; the number of frames offline synthesis
        makes of the whole audio (0 when it is shorter than two frames)."""
        self._append(self._resampler.flush())
        duration = self.received / float(self.sample_rate)
        total = int(np.floor(duration * self.rate + 1e-9)) + 1
        return 0 if total < 2 or duration < 2.0 / self.rate else total

    def window_start(self, t: int) -> int:
        """The first analysis sample of frame t's window (may be negative: zeros before)."""
        return frame_start(t / self.rate, self._audio_rate) - self._half

    def lsf(self, start: int, stop: int) -> np.ndarray:
        """``(stop - start, P)`` LSFs of frames ``start .. stop-1``; analysis samples not received
        yet are zero (only at the end of the audio). The samples before ``start``'s window must
        not have been released."""
        t = np.arange(start, stop)
        if len(t) == 0:
            return np.zeros((0, self.order))
        length = self.analysed
        starts = np.clip(frame_starts(t / self.rate, self._audio_rate), 0, length) - self._half
        idx = starts[:, None] + np.arange(self._n)[None, :]
        inside = (idx >= 0) & (idx < length)
        local = np.clip(idx - self._first, 0, max(len(self._buffer) - 1, 0))
        values = self._buffer[local] if len(self._buffer) else np.zeros(idx.shape)
        return frame_lsf(np.where(inside, values, 0.0) * self._hamming[None, :], self.order)

    def release(self, t: int) -> None:
        """Forget the samples before frame ``t``'s window (frames before t are done)."""
        keep = self.window_start(t)
        if keep > self._first:
            self._buffer = self._buffer[keep - self._first:]
            self._first = keep

    def _append(self, samples: np.ndarray) -> None:
        if len(samples) == 0:
            return
        emphasized = preemphasize(samples, self._preemphasis, self._previous)
        self._previous = float(samples[-1])
        self._buffer = np.concatenate([self._buffer, emphasized])
        self.analysed += len(samples)
