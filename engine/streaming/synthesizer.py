"""Streaming acoustic-only synthesis: audio blocks in, face frames out as soon as they are determined.

The same computation as :func:`facetraj_engine.method.pipeline.synthesize` in acoustic-only mode (paper
section
2.3: input LSFs, the LSF-index search, eqs 5-8, the triangular smoothing), with the state carried
between blocks: the resampler's filter memory (``facetraj_engine.method.lsf.ResampleStream``), the last sample
for the pre-emphasis, the analysis samples not yet used by a frame, and the smoother's last raw
frames (``facetraj_engine.method.smoothing.TriangularStream``). Frame t (at ``t / marker_rate``) is emitted
once
the audio up to ``t / marker_rate + lookahead_s`` has arrived: half the analysis window (12.5 ms),
the resampler's few samples and the smoothing window's second half (3 frames, 50 ms, at 60 Hz),
plus up to ``batch_frames - 1`` frames when frames are analysed in batches (live mode: 3).
The frames emitted by the blocks and :meth:`StreamingSynthesizer.flush` together equal the
offline synthesis of the whole audio, frame for frame (to rounding).

With ``synth.closure`` (live mode, ``facetraj live --acoustic-only``) the closure step follows
the smoothing (:mod:`facetraj_engine.streaming.closure`): the lips close where the model's
bilabial-closure detector finds a closure (:mod:`facetraj_engine.streaming.detector`: its
probabilities need the frames up to 3 after a frame, which the smoothing has waited for already,
so it adds no lookahead) and the face rests in the pauses found by energy so far
(:mod:`facetraj_engine.streaming.speech`): a frame is shown once the speech or silence of the 3
frames after it is decided, 118 ms after its time at most, within live mode's 129 ms.

Spline smoothing needs the whole utterance and is not available here.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from ..config import SynthConfig
from ..method.closure import ClosurePlan
from ..method.closure_detector import causal_closures
from ..method.closure_search import bilabial_codewords, search_rows
from ..method.model import Model
from ..method.search import acoustic_candidates
from ..method.smoothing import TriangularStream
from ..method.speaker import warp_lsf
from ..method.synthesis import FrameWeights, gamma_grid, weight_frames
from .closure import ClosureStream, decided_silence
from .detector import DetectorStream
from .front import LsfFront
from .speech import SpeechStream
from .voice import VoiceTracker

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class StreamConfig:
    """Settings of a stream.

    Attributes
    ----------
    sample_rate : the rate of the audio blocks fed in.
    synth : the synthesis settings (acoustic mode is used whatever ``synth.mode`` says; smoothing
        ``triangular`` or ``none``; ``speaker_warp`` must be a number: a stream has no whole
        utterance to choose it from).
    batch_frames : analyse the determined frames once this many are waiting (1: each as soon as
        it is determined). Larger batches make fewer, larger numpy calls (the per-call overhead
        dominates one frame's LPC, index search and eqs 5-8) for up to ``batch_frames - 1``
        frames more delay; the frames themselves are the same.
    """

    sample_rate: int = 16000
    synth: SynthConfig = field(default_factory=lambda: SynthConfig(mode="acoustic", closure=False))
    batch_frames: int = 1

    def __post_init__(self) -> None:
        if not (isinstance(self.batch_frames, int) and 1 <= self.batch_frames <= 60):
            raise ValueError(f"batch_frames must be an integer from 1 to 60, not {self.batch_frames!r}")


#: the frame batch of live mode (``facetraj live`` and the Live window): 5 frames at 60 Hz add
#: at most 67 ms to the lookahead, for a stream of small blocks that keeps up with fewer, larger
#: analyses (docs/benchmarks.md, "Live mode", has the latency and the speed)
LIVE_BATCH_FRAMES = 5


@dataclass
class StreamFrames:
    """Frames emitted by one call: ``index`` ``(n,)`` frame numbers (time ``index / rate``),
    ``pcs`` ``(n, K)`` smoothed PCs, ``raw_pcs`` ``(n, K)`` unsmoothed ones (eq 8) and
    ``markers`` ``(n, M, 3)``."""

    index: np.ndarray
    times: np.ndarray
    pcs: np.ndarray
    markers: np.ndarray

    def __len__(self) -> int:
        return len(self.index)


class StreamingSynthesizer:
    """Feed audio blocks of any size with :meth:`feed`, end with :meth:`flush`.

    ``feed`` returns the face frames the block completed (possibly none); ``flush`` the rest,
    padding the end as offline synthesis does. The input LSFs and raw PCs of every analysed frame
    are kept (:attr:`lsf`, :attr:`raw_pcs`) for saving the take.
    """

    def __init__(self, model: Model, config: StreamConfig | None = None):
        self.model = model
        self.config = config or StreamConfig()
        cfg = self.config.synth.with_(mode="acoustic")
        if cfg.smoothing not in ("triangular", "none"):
            raise ValueError(f"streaming supports triangular or no smoothing, not {cfg.smoothing!r}")
        if cfg.speaker_warp is None:
            raise ValueError("streaming needs a fixed speaker_warp (a number), not None")
        self.synth = cfg
        self.front = LsfFront(model, self.config.sample_rate)
        self.rate = model.marker_rate
        self._next = 0                      # the next frame to analyse
        self._smoother = TriangularStream(self.rate, cfg.triangle_s if cfg.smoothing ==
                                          "triangular" else 0.0)
        self._emitted = 0
        self._gammas = gamma_grid(cfg.gamma_min, cfg.gamma_max, cfg.gamma_steps)
        self._lsf: list[np.ndarray] = []
        self._raw: list[np.ndarray] = []
        self._grouped = model.lsf_index().grouped(model.codebook.lsf)   # once, not per block
        self.closure = StreamClosure(model, self.config.sample_rate, cfg) \
            if cfg.closure and model.closure is not None else None

    @property
    def lookahead_s(self) -> float:
        """Audio needed after a frame's time before the frame is emitted (the algorithm's delay;
        with ``batch_frames > 1`` the most: the first frame of a batch waits for its last; with
        the rest in pauses, at least the speech/silence decisions its rest reads)."""
        batch = (self.config.batch_frames - 1) / self.rate
        search = self.front.lookahead_s + batch + self._smoother.lookahead / self.rate
        if self.closure is None or not self.synth.rest:
            return search
        return max(search, self.closure.step.wait_s(self.closure.speech.delay_s))

    @property
    def received_s(self) -> float:
        """Seconds of audio fed so far."""
        return self.front.received_s

    @property
    def lsf(self) -> np.ndarray:
        """``(T, P)`` input LSFs (after the speaker warp) of the frames analysed so far."""
        return np.concatenate(self._lsf) if self._lsf else np.zeros((0, self.model.config.lpc_order))

    @property
    def raw_pcs(self) -> np.ndarray:
        """``(T, K)`` unsmoothed PCs (eq 8) of the frames analysed so far."""
        k = self.model.codebook.pcs.shape[1]
        return np.concatenate(self._raw) if self._raw else np.zeros((0, k))

    def feed(self, block: np.ndarray) -> StreamFrames:
        """Face frames completed by the next ``block`` of audio samples (mono)."""
        last = self.front.feed(block)           # frame t is complete once its window is in
        if self.closure is not None:
            self.closure.speech.feed(block)
        if last - self._next < self.config.batch_frames:
            last = self._next                           # not a whole batch yet: wait
        return self._emit(self._analyse(last), self._smoother.feed)

    def flush(self) -> StreamFrames:
        """The remaining frames, the audio ended: as many frames in all as offline synthesis makes
        of the same audio (none if it is shorter than two frames)."""
        total = self.front.flush()
        if total == 0:
            return self._emit(np.zeros((0, self.model.codebook.pcs.shape[1])), self._smoother.feed)
        raw = self._analyse(total)
        if self.closure is not None:
            self.closure.finish(total)
        frames = self._emit(raw, self._smoother.feed)
        rest = self._emit(np.zeros((0, raw.shape[1])), lambda _: self._smoother.flush(),
                          final=True)
        return StreamFrames(np.concatenate([frames.index, rest.index]),
                            np.concatenate([frames.times, rest.times]),
                            np.concatenate([frames.pcs, rest.pcs]),
                            np.concatenate([frames.markers, rest.markers]))

    # ------------------------------------------------------------------ the steps
    def _analyse(self, stop: int) -> np.ndarray:
        """Raw PCs (eqs 5-8) of frames ``self._next .. stop-1``."""
        k = self.model.codebook.pcs.shape[1]
        if stop <= self._next:
            return np.zeros((0, k))
        if self.closure is not None:
            raw, energy = self.front.lsf_energy(self._next, stop)
        else:
            raw = self.front.lsf(self._next, stop)
        w = warp_lsf(raw, self.synth.speaker_warp) if self.synth.speaker_warp != 1.0 else raw
        cb = self.model.codebook
        fw = weight_frames(w, acoustic_candidates(self.model, w, self.synth, self._grouped), cb.lsf, cb.pcs,
                           self._gammas)
        if self.closure is not None:
            self.closure.analysed(raw, energy, w, fw)
        self._lsf.append(w)
        self._raw.append(fw.pcs)
        self._next = stop
        self.front.release(stop)                        # samples before the next window: done
        return fw.pcs

    def _emit(self, raw: np.ndarray, smoother, final: bool = False) -> StreamFrames:
        pcs = smoother(raw)
        if self.closure is not None:
            pcs = self.closure.feed(pcs, final)
        index = np.arange(self._emitted, self._emitted + len(pcs))
        self._emitted += len(pcs)
        return StreamFrames(index, index / self.rate, pcs, self.model.to_markers(pcs))


class StreamClosure:
    """The closure step of an acoustic-only stream: the silent frames by energy, the detector's
    closures (the search's opinion counting by the running voice match from the frame after the
    voice has been heard, :func:`facetraj_engine.method.voice_match.match_from`, as offline), and
    the step on the smoothed frames (held until the silence their rest reads is decided)."""

    def __init__(self, model: Model, sample_rate: int, synth: SynthConfig):
        self.model, self.synth, self.rate = model, synth, model.marker_rate
        self.speech = SpeechStream(sample_rate, self.rate)
        self.detector = DetectorStream(model.detector, self.rate) \
            if synth.closure_detector and model.detector is not None else None
        searching = self.detector is not None and model.detector.search is not None
        self.voice = VoiceTracker(model, self.speech) if searching else None
        self._bilabial = bilabial_codewords(model) if searching else None
        self.step = ClosureStream(model, 0, synth.closure_taper_s, synth.rest_taper_s,
                                  synth.rest_pause_s, synth.rest_lookahead_s)
        self._final = False

    @property
    def match(self) -> float:
        """The running voice match (the prior until it is measured)."""
        return self.voice.voice.match if self.voice is not None else 0.0

    @property
    def trusted_from(self) -> int:
        """The first frame whose detector probability uses the voice match (none yet: a frame
        beyond every one)."""
        heard = self.voice.heard_from if self.voice is not None else None
        return heard if heard is not None else np.iinfo(np.int64).max

    def analysed(self, lsf: np.ndarray, energy_db: np.ndarray, w: np.ndarray,
                 frames: FrameWeights) -> None:
        """The next analysed frames' unwarped LSFs and energies, the LSFs searched ``w`` and the
        search's weights."""
        if self.detector is None:
            return
        search = None
        if self.voice is not None:
            self.voice.add(w)
            self.voice.update()
            search = search_rows(self.model, frames, self._bilabial)
        self.detector.feed(lsf, energy_db, search, self.match, self.trusted_from)

    def finish(self, total: int) -> None:
        """The audio ended (``total`` frames in all)."""
        self.speech.flush(total)
        if self.detector is not None:
            if self.voice is not None:
                self.voice.update(final=True)
            self.detector.flush(self.match, self.trusted_from)
        self._final = True

    def feed(self, pcs: np.ndarray, final: bool = False) -> np.ndarray:
        """The smoothed frames after the step, as far as the plan is known now."""
        if not len(pcs) and not final and self.step.received <= self.step.emitted:
            return pcs
        return self.step.feed(pcs, self.plan(), final,
                              self.speech.known if self.synth.rest else None)

    def plan(self) -> ClosurePlan:
        """The detector's closures and the silent frames around the frames about to be emitted."""
        intervals = np.zeros((0, 2))
        if self.detector is not None and self.synth.closure_detector:
            since = max(0, self.step.received - int(ClosureStream.KEEP_S * self.rate))
            runs = self.detector.runs(since, self.synth.closure_threshold, self._final)
            intervals = causal_closures(runs, self.rate, self.detector.spec.min_frames)
        first = max(0, self.step.emitted - self.step.lookback)
        silent, leading = decided_silence(self.speech.decisions, first) if self.synth.rest else \
            (np.zeros(0, dtype=bool), False)
        return ClosurePlan(intervals, np.ones(len(intervals)), silent, None,
                           np.ones(len(intervals), dtype=bool), first, leading)


def stream_synthesize(model: Model, audio: np.ndarray, sample_rate: int, block: int,
                      synth: SynthConfig | None = None) -> StreamFrames:
    """The whole of ``audio`` through a :class:`StreamingSynthesizer` in blocks of ``block``
    samples; all the frames emitted (for tests and benchmarks)."""
    cfg = StreamConfig(sample_rate, synth or SynthConfig(mode="acoustic", closure=False))
    stream = StreamingSynthesizer(model, cfg)
    parts = [stream.feed(audio[a:a + block]) for a in range(0, len(audio), block)]
    parts.append(stream.flush())
    return StreamFrames(*(np.concatenate([getattr(p, f) for p in parts])
                          for f in ("index", "times", "pcs", "markers")))
