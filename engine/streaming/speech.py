"""Speech and pauses of a stream, by energy (live mode, issue 27): what
:func:`facetraj_engine.method.speech.speech_mask` and :func:`~facetraj_engine.method.speech.pauses` compute on
a
whole recording, computed as the audio arrives.

The same short-time energy (20 ms Hamming window, 4 ms hop) and 112 ms median filter (its values
equal :func:`facetraj_engine.method.speech.filtered_energy_db`'s for a signal whose peak is 1, as
a file is streamed, :func:`facetraj_engine.streaming.live.stream_file`; tested); a marker frame's
value is known 66 ms after its time (half the filter and half the window). What a stream cannot know is the
recording's floor and peak (its 5th and 99th energy percentiles): the threshold uses those of the
filtered energy so far (at most the last ``HISTORY_S``), and until the energy has spanned
``min_range_db`` a frame is *unranged*: neither speech nor pause (nothing rests, as offline in a
recording without a pause; the voice match measures nothing). Each frame is decided once, when
its value is known, and kept.
"""

from __future__ import annotations

import numpy as np

from ..config import EvalConfig

#: The floor and peak are those of the last this many seconds of filtered energy.
HISTORY_S = 60.0
#: A frame's decision: silence, speech, or not decidable yet (the energy has not spanned the range).
SILENT, SPEECH, UNRANGED = 0, 1, -1


class SpeechStream:
    """Audio blocks in (:meth:`feed`; :meth:`flush` at the end), per marker frame
    :data:`SPEECH`, :data:`SILENT` or :data:`UNRANGED` (:attr:`decisions`) as soon as it is known
    (:attr:`known`)."""

    def __init__(self, sample_rate: int, marker_rate: float, config: EvalConfig | None = None,
                 min_range_db: float = 20.0):
        self.config = c = config or EvalConfig()
        self.rate = int(sample_rate)
        self.marker_rate = float(marker_rate)
        self.min_range_db = min_range_db
        self._n = max(1, int(round(c.energy_window_s * self.rate)))
        self._hop = max(1, int(round(c.energy_hop_s * self.rate)))
        k = int(round(c.median_s / c.energy_hop_s))
        self._k = k + 1 if k % 2 == 0 else k
        self._window = np.hamming(self._n)
        self._audio = np.zeros(self._n // 2)     # samples from self._audio0 on (zeros before 0)
        self._audio0 = -(self._n // 2)
        self._energy = np.zeros(self._k // 2)    # dB of hop frames from self._e0 on (the filter's
        self._e0 = -(self._k // 2)                # zero padding before frame 0)
        self._n_energy = 0                        # hop frames whose energy is computed
        self._filtered = np.zeros(0)             # filtered dB from hop frame self._f0 on
        self._f0 = 0
        self.received = 0
        self.decisions: list[int] = []
        self.ranged = False

    @property
    def known(self) -> int:
        """Marker frames decided."""
        return len(self.decisions)

    @property
    def delay_s(self) -> float:
        """The most audio after a marker frame's time before its decision: half the median
        filter and the energy window's second half, from the hop frame nearest the marker frame
        (at most half a hop after it)."""
        hop = self.config.energy_hop_s
        return (self._k // 2 + 0.5) * hop + (self._n - self._n // 2) / self.rate

    @property
    def filtered(self) -> np.ndarray:
        """The filtered energy (dB) of the hop frames kept (the last ``HISTORY_S``)."""
        return self._filtered

    def feed(self, block: np.ndarray) -> int:
        """Take the next ``block`` of samples; the number of frames now decided."""
        block = np.asarray(block, dtype=np.float64).ravel()
        self.received += len(block)
        self._audio = np.concatenate([self._audio, block])
        last = (self.received - (self._n - self._n // 2)) // self._hop    # its window is in
        self._energies(last + 1)
        self._filter(final=False)
        self._decide(None)
        return self.known

    def flush(self, total: int) -> int:
        """The audio ended: decide the frames up to ``total`` (the stream's frame count)."""
        self._audio = np.concatenate([self._audio, np.zeros(self._n)])
        self._energies(self.received // self._hop + 1)
        self._filter(final=True)
        self._decide(total)
        return self.known

    # ------------------------------------------------------------------ the steps
    def _energies(self, count: int) -> None:
        """Energy (dB) of hop frames up to ``count`` (their windows are in the buffer)."""
        if count <= self._n_energy:
            return
        starts = np.arange(self._n_energy, count) * self._hop - self._n // 2 - self._audio0
        frames = self._audio[starts[:, None] + np.arange(self._n)[None, :]] * self._window
        db = 10 * np.log10((frames**2).sum(axis=1) / self._n + 1e-12)
        self._energy = np.concatenate([self._energy, db])
        self._n_energy = count
        drop = count * self._hop - self._n // 2 - self._audio0
        if drop > 0:
            self._audio = self._audio[drop:]
            self._audio0 += drop

    def _filter(self, final: bool) -> None:
        """The median filter of every hop frame whose window of energies is in."""
        half = self._k // 2
        if final:
            self._energy = np.concatenate([self._energy, np.zeros(half)])
        done = self._f0 + len(self._filtered)
        stop = self._n_energy if final else self._n_energy - half
        if stop <= done:
            return
        e = self._energy[done - half - self._e0: stop + half - self._e0]
        med = np.median(np.lib.stride_tricks.sliding_window_view(e, self._k), axis=1)
        self._filtered = np.concatenate([self._filtered, med])
        keep = int(HISTORY_S / self.config.energy_hop_s)
        if len(self._filtered) > keep:                  # bounded memory in a long take
            cut = len(self._filtered) - keep
            self._filtered = self._filtered[cut:]
            self._f0 += cut
        cut = stop - half - self._e0                     # energies no window needs any more
        if cut > 0:
            self._energy = self._energy[cut:]
            self._e0 += cut

    def _decide(self, total: int | None) -> None:
        """Decide each marker frame whose filtered energy is known (``total``: the end)."""
        have = self._f0 + len(self._filtered)
        hop = self.config.energy_hop_s
        levels = None                       # the floor and peak: one filtered history per call
        while total is None or self.known < total:
            j = int(round(self.known / self.marker_rate / hop))
            if total is None and j >= have:
                break
            j = min(max(j, self._f0), have - 1)
            if have > self._f0 and levels is None:
                levels = np.percentile(self._filtered, [5, 99])
            self.decisions.append(self._decision(self._filtered[j - self._f0], *levels)
                                  if have > self._f0 else UNRANGED)

    def _decision(self, value: float, floor: float, peak: float) -> int:
        self.ranged = self.ranged or bool(peak - floor >= self.min_range_db)
        if not self.ranged:
            return UNRANGED
        return SPEECH if value > floor + self.config.threshold_fraction * (peak - floor) else SILENT
