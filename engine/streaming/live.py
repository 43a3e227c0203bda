"""Live mode's stream (issue 27): the recognizer beside the synthesizer, one take at a time.

:class:`LiveStream` is what ``facetraj live`` (with or without its window) and the Live window
run: with phones (the default, "phones + acoustics"), a :class:`~facetraj_engine.streaming.recognizer.
StreamingRecognizer` and a :class:`~facetraj_engine.streaming.phonetic.PhoneticSynthesizer` fed the same
blocks; acoustic-only, the paper's search as before (:class:`~facetraj_engine.streaming.synthesizer.
StreamingSynthesizer`, frames in batches of ``LIVE_BATCH_FRAMES``).

The recognizer runs in the caller's thread (``threaded=False``: each block is recognized before
it is synthesized, so a file gives the same face every time: ``facetraj live --from-file``, the
benchmarks, the report) or in a thread of its own (``threaded=True``: the Live window, whose
audio comes on the GUI thread). A frame whose phone the recognizer has not settled when the
frame's wait is over is synthesized acoustic-only: the face never waits longer than
:attr:`LiveStream.lookahead_s` for the recognizer.

The latency budget (``LIVE_TIMING``, ``LIVE_RECOGNIZER``; measured in docs/benchmarks.md, "Live
mode"): the recognizer settles a phone 80 ms behind its front, which is about 50 ms behind the
audio: 130 ms; a frame waits at most ``wait_s`` = 150 ms for its phone, then batches of 2 frames
(17 ms), the smoothing (50 ms), no closure hold: 217 ms in all, against 129 ms acoustic-only.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..config import SynthConfig
from ..data import PhoneSegment, Provenance
from ..labels.phoneset import SILENCE
from ..labels.provenance import SCORE_SCALE, Labels
from ..level import to_full_scale
from ..method.model import Model
from ..method.modes import ModeChoice, choose_mode
from .phones import KnownPhones, PhoneSnapshot
from .phonetic import PhoneticSynthesizer, PhoneticTiming
from .recognizer import RecognizerConfig, RunningCmn, StreamingRecognizer
from .synthesizer import LIVE_BATCH_FRAMES, StreamClosure, StreamConfig, StreamFrames, StreamingSynthesizer

log = logging.getLogger(__name__)

#: With phones, blocks are taken in steps of this many seconds of audio, recognized and then
#: synthesized step by step: what a frame knows of the phones then does not depend on the size
#: of the blocks (a file gives the same face in 10 ms or 1 s blocks).
STEP_S = 0.01
#: Live mode's timing with phones (module docstring).
LIVE_TIMING = PhoneticTiming(wait_s=0.16, batch=2, hold=0)
LIVE_RECOGNIZER = RecognizerConfig(settle_s=0.1)


@dataclass(frozen=True)
class LiveConfig:
    """A take's settings: ``phones`` (phones + acoustics) or acoustic-only, the recognizer's and
    the phonetic synthesizer's timing."""

    phones: bool = True
    recognizer: RecognizerConfig = field(default_factory=lambda: LIVE_RECOGNIZER)
    timing: PhoneticTiming = field(default_factory=lambda: LIVE_TIMING)


def live_mode(config: SynthConfig, model: Model, phones: bool = True,
              labels: Labels | None = None) -> ModeChoice:
    """The synthesis settings of a take: with phones, those the mode rule
    (:func:`facetraj_engine.method.modes.choose_mode`) gives recognized labels -- the robust mode with the
    model's cross-validated settings, and the closure step, but not the chain over frames
    (``facetraj_engine.method.chain``: its forward-backward needs the whole input); acoustic-only, the
    paper's search and the closure step with the model's bilabial-closure detector, as
    ``facetraj synth --mode acoustic`` (``facetraj_engine.streaming.synthesizer``). With
    ``labels`` known before the audio (a file's, by the one rule) the rule decides by them, as
    ``synth`` does: aligned or recognized labels, the robust mode; hand-checked ones, the
    stream's robust search with every label trusted fully (a stream has no phonetic search of its
    own)."""
    if not phones:
        return ModeChoice(config.with_(mode="acoustic"), "acoustic-only, chosen")
    if labels is not None:
        rule = choose_mode(config.with_(mode="phonetic"), labels.phones, labels.provenance,
                           tuned=model.tuned)
        if rule.mode != "robust":
            return ModeChoice(config.with_(mode="robust", chain_beta=0.0),
                              f"{rule.reason}: the stream's robust search, every label trusted")
        return ModeChoice(rule.config.with_(chain_beta=0.0), rule.reason)
    streamed = [PhoneSegment(0.0, 1.0, SILENCE)]       # phones to come: the rule needs to know
    rule = choose_mode(config.with_(mode="phonetic"), streamed, Provenance("recognized"),
                       tuned=model.tuned)
    return ModeChoice(rule.config.with_(chain_beta=0.0),
                      f"phones recognized as they are spoken ({rule.reason})")


class _ThreadedPhones:
    """A recognizer in a thread of its own: blocks queued by :meth:`feed`, the settled phones
    read under a lock. An error in the thread stops recognition (logged, kept in ``error``): the
    frames after it are acoustic-only."""

    def __init__(self, recognizer: StreamingRecognizer):
        self.recognizer = recognizer
        self.error: BaseException | None = None
        self._lock = threading.Lock()
        self._queue: queue.SimpleQueue = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._run, name="live-recognizer", daemon=True)
        self._thread.start()

    @property
    def settled_s(self) -> float:
        with self._lock:
            return self.recognizer.track.settled_s

    def snapshot(self, since_s: float = 0.0, before: int = 0) -> PhoneSnapshot:
        with self._lock:
            return self.recognizer.track.snapshot(since_s, before)

    @property
    def running(self) -> bool:
        return self._thread.is_alive()

    def feed(self, block: np.ndarray) -> None:
        self._queue.put(block)

    def finish(self, flush: bool = True) -> None:
        """Wait for the queued blocks, then (``flush``) settle the rest."""
        self._queue.put(None)
        self._thread.join()
        if flush and self.error is None:
            with self._lock:
                self.recognizer.flush()

    def _run(self) -> None:
        while (block := self._queue.get()) is not None:
            if self.error is not None:
                continue
            try:
                with self._lock:
                    self.recognizer.feed(block)
            except Exception as exc:                    # recognition stops; the face goes on
                log.warning("live recognition stopped: %s", exc)
                self.error = exc


class LiveStream:
    """One take: :meth:`feed` blocks of audio (mono floats), :meth:`flush` at the end; each
    returns the face frames it completed. ``cmn`` carries the recognizer's running cepstral mean
    over from an earlier take (the Live window's)."""

    def __init__(self, model: Model, sample_rate: int, synth: SynthConfig | None = None,
                 config: LiveConfig | None = None, threaded: bool = False,
                 cmn: RunningCmn | None = None, labels: Labels | None = None):
        self.model = model
        self.config = config or LiveConfig()
        self.known = labels if self.config.phones else None
        self.choice = live_mode(synth or SynthConfig(), model, self.config.phones, self.known)
        self.sample_rate = int(sample_rate)
        self.recognizer: StreamingRecognizer | None = None
        self._threaded: _ThreadedPhones | None = None
        self.phonetic: PhoneticSynthesizer | None = None
        self.acoustic: StreamingSynthesizer | None = None
        self.recognize_s = 0.0                         # seconds spent recognizing (this thread)
        self._step = max(1, int(round(STEP_S * sample_rate)))
        self._pending = np.zeros(0)
        if self.known is not None:                      # phones known: nothing to recognize
            trust = self.known.trust()
            source = KnownPhones(self.known.phones, np.ones(len(self.known.phones))
                                 if trust is None else trust)
            self.phonetic = PhoneticSynthesizer(model, sample_rate, self.choice.config, source,
                                                self.config.timing, self.known.provenance.kind)
        elif self.config.phones:
            self.recognizer = StreamingRecognizer(sample_rate, self.config.recognizer, cmn)
            source = self.recognizer.track
            if threaded:
                self._threaded = source = _ThreadedPhones(self.recognizer)
            self.phonetic = PhoneticSynthesizer(model, sample_rate, self.choice.config, source,
                                                self.config.timing)
        else:
            self.acoustic = StreamingSynthesizer(model, StreamConfig(sample_rate, self.choice.config,
                                                                     LIVE_BATCH_FRAMES))

    # ------------------------------------------------------------------ blocks
    @property
    def lookahead_s(self) -> float:
        """The longest a frame waits after its time before it is emitted."""
        return (self.phonetic or self.acoustic).lookahead_s

    @property
    def received_s(self) -> float:
        return (self.phonetic or self.acoustic).received_s

    def feed(self, block: np.ndarray) -> StreamFrames:
        """The face frames the next ``block`` completes."""
        block = np.nan_to_num(np.asarray(block, dtype=np.float64).ravel(), nan=0.0,
                              posinf=1.0, neginf=-1.0)
        if self.acoustic is not None:
            return self.acoustic.feed(block)
        x = np.concatenate([self._pending, block]) if len(self._pending) else block
        whole = len(x) // self._step * self._step
        self._pending = x[whole:]
        return _joined([self._feed_step(x[a:a + self._step]) for a in range(0, whole, self._step)],
                       self.model.codebook.pcs.shape[1], self.model.n_markers)

    def _feed_step(self, step: np.ndarray) -> StreamFrames:
        if self._threaded is not None:
            self._threaded.feed(step)
        elif self.recognizer is not None:
            t0 = time.perf_counter()
            self.recognizer.feed(step)
            self.recognize_s += time.perf_counter() - t0
        return self.phonetic.feed(step)

    def flush(self) -> StreamFrames:
        """The last frames (the audio ended)."""
        if self.acoustic is not None:
            return self.acoustic.flush()
        last = self._feed_step(self._pending) if len(self._pending) else None
        self._pending = np.zeros(0)
        if self._threaded is not None:
            self._threaded.finish()
        elif self.recognizer is not None:
            self.recognizer.flush()
        return _joined([p for p in (last, self.phonetic.flush()) if p is not None],
                       self.model.codebook.pcs.shape[1], self.model.n_markers)

    def close(self) -> None:
        """Stop the recognizer's thread without settling the rest (a take abandoned)."""
        if self._threaded is not None and self._threaded.running:
            self._threaded.finish(flush=False)

    # ------------------------------------------------------------------ what the take knows
    @property
    def recognition_error(self) -> BaseException | None:
        return self._threaded.error if self._threaded is not None else None

    def snapshot(self, since_s: float = 0.0) -> PhoneSnapshot | None:
        """The settled phones from ``since_s`` on (``None`` acoustic-only)."""
        if self.phonetic is None:
            return None
        return self.phonetic.phones.snapshot(since_s)

    @property
    def _detecting(self) -> StreamClosure | None:
        """The closure step when it has the bilabial-closure detector (acoustic-only with the
        closure step and a model with a detector; else ``None``)."""
        closure = self.acoustic.closure if self.acoustic is not None else None
        return closure if closure is not None and closure.detector is not None else None

    @property
    def closure_probability(self) -> np.ndarray | None:
        """Per frame so far, the bilabial-closure detector's probability (``None`` without it)."""
        closure = self._detecting
        return closure.detector.probabilities() if closure is not None else None

    @property
    def detected_closures(self) -> np.ndarray | None:
        """``(J, 2)`` the detector's closures (seconds) over the frames so far, at the stream's
        own threshold (``None`` without the detector)."""
        closure = self._detecting
        return closure.detector.record_runs(closure.synth.closure_threshold) \
            if closure is not None else None

    @property
    def voice_ratio(self) -> float:
        """The running ``D / D0`` (NaN while unknown, or acoustic-only)."""
        return self.phonetic.voice.ratio if self.phonetic is not None else float("nan")

    @property
    def voice_match(self) -> float:
        """The running voice match (NaN acoustic-only; the prior while unknown)."""
        return self.phonetic.voice.match if self.phonetic is not None else float("nan")

    @property
    def heard_s(self) -> float:
        """Seconds of speech the running voice ratio has measured (0 acoustic-only)."""
        return self.phonetic.voice.heard / self.model.marker_rate if self.phonetic is not None else 0.0

    @property
    def label_scale(self) -> float:
        """The factor of the robust mode's label weight now (1 acoustic-only)."""
        if self.phonetic is None:
            return 1.0
        return self.phonetic.voice.weight_scale(self.choice.config.label_weight_by_voice)

    @property
    def labelled_share(self) -> float:
        """The share of the analysed frames that had a settled phone (NaN acoustic-only)."""
        if self.phonetic is None or not self.phonetic.labelled:
            return float("nan")
        return float(np.mean(self.phonetic.labelled))

    def labels(self, duration: float) -> Labels | None:
        """The take's recognized phones as :class:`Labels` covering ``[0, duration]``, their
        confidence the stability of each (``facetraj_engine.streaming.phones``), their provenance
        ``recognized`` by the streamed search; ``None`` acoustic-only."""
        if self.known is not None:
            return self.known
        if self.recognizer is None:
            return None
        snap = self.phonetic.phones.snapshot(0.0)
        return take_labels(snap.segments, snap.confidence, duration, self.recognizer.tool)


def _joined(parts: list[StreamFrames], k: int, m: int) -> StreamFrames:
    """Consecutive frames as one :class:`StreamFrames` (``k`` PCs, ``m`` markers when none)."""
    if not parts:
        return StreamFrames(np.zeros(0, int), np.zeros(0), np.zeros((0, k)), np.zeros((0, m, 3)))
    if len(parts) == 1:
        return parts[0]
    return StreamFrames(*(np.concatenate([getattr(p, f) for p in parts])
                          for f in ("index", "times", "pcs", "markers")))


def take_labels(segments: list[PhoneSegment], confidence: np.ndarray, duration: float,
                tool: str) -> Labels:
    """Settled phones as :class:`Labels` over ``[0, duration]``: the last phone reaches the end
    (silence after it when it stops short), each confidence stored as the score it is
    (``SCORE_SCALE ln c``).

    >>> lab = take_labels([PhoneSegment(0, .1, "sil"), PhoneSegment(.1, .2, "b")],
    ...                   np.array([1.0, 0.5]), 0.3, "PocketSphinx 5.1.1, streamed")
    >>> [(p.label, p.end) for p in lab.phones], lab.confidence.round(3).tolist()
    ([('sil', 0.1), ('b', 0.2), ('sil', 0.3)], [1.0, 0.5, 1.0])
    """
    phones = [s for s in segments if s.start < duration]
    conf = list(np.asarray(confidence, dtype=np.float64)[:len(phones)])
    if phones and phones[-1].end > duration:
        phones[-1] = PhoneSegment(phones[-1].start, duration, phones[-1].label)
    end = phones[-1].end if phones else 0.0
    if duration - end > 1e-9:
        phones.append(PhoneSegment(end, duration, SILENCE))
        conf.append(1.0)
    with np.errstate(divide="ignore"):
        scores = SCORE_SCALE * np.log(np.clip(np.array(conf, dtype=np.float64), 1e-9, 1.0))
    return Labels(phones, [], "recognized", scores, provenance=Provenance("recognized", tool))


@dataclass
class FileTake:
    """A file streamed through live mode: its frames, the recognized phones (``None``
    acoustic-only), the wall time, and per block the processing time (seconds)."""

    frames: StreamFrames
    labels: Labels | None
    wall_s: float
    block_s: list[float] = field(default_factory=list)
    stream: LiveStream | None = None


def stream_file(model: Model, audio: np.ndarray, rate: int, block_s: float,
                synth: SynthConfig | None = None, config: LiveConfig | None = None,
                real_time: bool = False, sleep: Callable[[float], None] = time.sleep,
                cmn: RunningCmn | None = None, labels: Labels | None = None) -> FileTake:
    """``audio`` through a :class:`LiveStream` in blocks of ``block_s`` seconds (the recognizer in
    this thread), paced to the audio clock when ``real_time``: ``facetraj live --from-file``
    (``cmn``: the running cepstral mean of earlier takes, as the Live window keeps it; ``labels``:
    the file's phones when the one rule found them, streamed instead of recognized). The file
    is scaled to a peak of 1 first (:func:`facetraj_engine.level.to_full_scale`: its gain changes
    nothing, samples beyond full scale are not clipped for the recognizer, and the stream's
    energies are those of offline synthesis, relative to the peak)."""
    audio = to_full_scale(audio)
    stream = LiveStream(model, rate, synth, config, cmn=cmn, labels=labels)
    block = max(1, int(round(block_s * rate)))
    parts, times = [], []
    t0 = time.perf_counter()
    for a in range(0, len(audio), block):
        if real_time:                                   # the block's last sample "arrives" now
            delay = t0 + min(a + block, len(audio)) / rate - time.perf_counter()
            if delay > 0:
                sleep(delay)
        t1 = time.perf_counter()
        parts.append(stream.feed(audio[a:a + block]))
        times.append(time.perf_counter() - t1)
    parts.append(stream.flush())
    wall = time.perf_counter() - t0
    frames = _joined(parts, model.codebook.pcs.shape[1], model.n_markers)
    return FileTake(frames, stream.labels(len(audio) / rate), wall, times, stream)
