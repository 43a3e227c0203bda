"""Live mode with phones (issue 27): the default mode of a recording with no labels -- the robust
mode over recognized phones, then the closure step -- on audio blocks as they arrive.

Per frame t (at ``t / marker_rate``), in order:

1. its input LSFs (``facetraj_engine.streaming.front``), and those of the robust mode's acoustic context
   (frames t +- 3);
2. **its phone**: frame t waits until the recognizer has settled the phone at its time
   (``facetraj_engine.streaming.recognizer``), but never longer than ``wait_s`` of audio after it; a
   settled phone makes it a robust-mode frame (eq 4's codewords of that phone in its context --
   the phones settled so far, silence after them -- and the acoustically nearest ones, the label
   weighed by the phone's confidence and the running voice ratio,
   :func:`facetraj_engine.method.search.robust_weights`); without one it is an acoustic-only frame, as
   in ``facetraj live`` before (:func:`facetraj_engine.method.search.acoustic_candidates`);
3. frames are analysed ``batch`` at a time, smoothed by the triangular window (3 frames later);
4. the closure step (``facetraj_engine.streaming.closure``): the lips close at the settled /p b m/ (trusted
   as far as the running voice match is low, :func:`facetraj_engine.method.closure.closure_strengths`),
   the face rests in the pauses found by energy (``facetraj_engine.streaming.speech``), ``hold`` frames
   later, and once the speech or silence of the frames its rest reads ahead is decided.

So a frame is emitted at most ``lookahead_s`` after its time: ``max(wait_s, the LSF context)`` +
``(batch - 1)`` frames + the smoothing's 3 frames + ``hold`` frames (the rest's decisions come
sooner).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..config import SynthConfig
from ..labels.phoneset import SILENCE, map_labels
from ..method.closure import BILABIALS, ClosurePlan, closure_strengths
from ..method.context import context_ids, segment_index
from ..method.model import Model
from ..method.pipeline import frame_confidence
from ..method.search import acoustic_candidates, context_offsets, robust_weights
from ..method.similarity import top_context_phones
from ..method.smoothing import TriangularStream
from ..method.synthesis import gamma_grid, weight_frames
from ..method.voice_match import trust_by_voice
from .closure import ClosureStream, decided_silence
from .front import LsfFront
from .phones import PhoneSnapshot
from .speech import SpeechStream
from .synthesizer import StreamFrames
from .voice import RunningVoice, VoiceTracker

#: Frames whose LSFs are computed together once their windows are in (before they are analysed:
#: a frame waits for its phone far longer than for its window; fewer, larger numpy calls).
LSF_BATCH = 6


class PhoneSource(Protocol):
    """Where the settled phones come from (a :class:`facetraj_engine.streaming.phones.PhoneTrack`, or a
    recognizer running in another thread)."""

    @property
    def settled_s(self) -> float: ...

    def snapshot(self, since_s: float = 0.0, before: int = 0) -> PhoneSnapshot: ...


@dataclass(frozen=True)
class PhoneticTiming:
    """When frames are analysed and emitted: ``wait_s`` the longest a frame waits for its phone
    (seconds of audio after its time), ``batch`` frames analysed at once, ``hold`` frames the
    closure step looks ahead."""

    wait_s: float = 0.15
    batch: int = 2
    hold: int = 0

    def __post_init__(self) -> None:
        if not (0.0 <= self.wait_s <= 2.0 and 1 <= self.batch <= 60 and 0 <= self.hold <= 60):
            raise ValueError(f"wait_s 0-2 s, batch 1-60 and hold 0-60 frames, not {self}")


class ContextCodewords:
    """Eq 4's candidate codewords of context-phones (rows ``[l_C .. l_1, c, r_1 .. r_C]`` of the
    model's phone ids), each context-phone's computed once: a stream meets the same one batch
    after batch (:func:`facetraj_engine.method.similarity.top_context_phones`, as offline)."""

    def __init__(self, model: Model, config: SynthConfig):
        self.model, self.config = model, config
        self._known: dict[tuple[int, ...], np.ndarray] = {}

    def __call__(self, rows: np.ndarray) -> np.ndarray:
        """``(n, 5N)`` codebook indices for ``rows`` ``(n, 2C + 1)``."""
        keys = [tuple(r) for r in rows.tolist()]
        new = list(dict.fromkeys(k for k in keys if k not in self._known))
        if new:
            mc, cb, cfg = self.model.config, self.model.codebook, self.config
            top, _ = top_context_phones(np.array(new), cb.contexts, self.model.similarity(cfg.nu),
                                        cfg.xi, min(cfg.context, mc.context), cfg.n_context_phones,
                                        self.model.context_index)
            self._known.update(zip(new, cb.codewords_of(top), strict=True))
        return np.array([self._known[k] for k in keys])


class PhoneticSynthesizer:
    """Feed audio blocks with :meth:`feed`, end with :meth:`flush`; ``phones`` gives the settled
    phones (fed the same audio by the caller, before each block here), made as ``kind`` says
    (``recognized``; a file's labels known before: how they were made)."""

    def __init__(self, model: Model, sample_rate: int, synth: SynthConfig, phones: PhoneSource,
                 timing: PhoneticTiming | None = None, kind: str = "recognized"):
        if synth.smoothing not in ("triangular", "none") or synth.mean_normalise or \
                synth.speaker_warp != 1.0:
            raise ValueError("a stream with phones smooths with the triangle or not at all, and "
                             "neither warps nor normalises the speaker's LSFs")
        self.model, self.synth, self.phones, self.kind = model, synth, phones, kind
        self.timing = timing or PhoneticTiming()
        self.rate = model.marker_rate
        self.front = LsfFront(model, sample_rate)
        self.speech = SpeechStream(sample_rate, self.rate)
        self._voice = VoiceTracker(model, self.speech)
        self.voice: RunningVoice = self._voice.voice
        cb = model.codebook
        self._ctx = model.config.lsf_context_frames if cb.lsf_context is not None else 0
        self._smoother = TriangularStream(self.rate, synth.triangle_s if synth.smoothing ==
                                          "triangular" else 0.0)
        self._closure = ClosureStream(model, self.timing.hold, synth.closure_taper_s,
                                      synth.rest_taper_s, synth.rest_pause_s, synth.rest_lookahead_s) \
            if synth.closure and model.closure else None
        self._gammas = gamma_grid(synth.gamma_min, synth.gamma_max, synth.gamma_steps)
        self._grouped = model.lsf_index().grouped(cb.lsf)
        self._eq4 = ContextCodewords(model, synth)
        self._phone_id = {p: i for i, p in enumerate(model.phones)}
        self._mapped: dict[str, str] = {}
        self._w = np.zeros((0, model.config.lpc_order))     # LSFs of frames self._w0 ...
        self._w0 = 0
        self._next = 0                                       # the next frame to analyse
        self._emitted = 0
        self.labelled: list[bool] = []                       # per analysed frame: had a phone

    @property
    def lookahead_s(self) -> float:
        """The longest a frame waits after its time before it is emitted (with the rest in
        pauses, at least until the speech/silence decisions its rest reads are made)."""
        lsf = self.front.lookahead_s + self._ctx / self.rate
        t = self.timing
        search = max(t.wait_s, lsf) + (t.batch - 1 + self._smoother.lookahead + t.hold) / self.rate
        if self._closure is None or not self.synth.rest:
            return search
        return max(search, self._closure.wait_s(self.speech.delay_s))

    @property
    def received_s(self) -> float:
        return self.front.received_s

    # ------------------------------------------------------------------ blocks
    def feed(self, block: np.ndarray) -> StreamFrames:
        """Face frames completed by the next ``block`` of audio samples (mono)."""
        complete = self.front.feed(block)
        self.speech.feed(block)
        if complete - (self._w0 + len(self._w)) >= LSF_BATCH:
            self._lsf(complete, None)
        stop = self._ready(complete)
        raw = self._analyse(stop, None) if stop - self._next >= self.timing.batch else None
        return self._emit(self._smoother.feed(raw) if raw is not None else None, final=False)

    def flush(self) -> StreamFrames:
        """The remaining frames, the audio ended (as many as offline synthesis makes)."""
        total = self.front.flush()
        self.speech.flush(total)
        raw = self._analyse(total, total) if total > self._next else np.zeros((0, self._k))
        smoothed = np.concatenate([self._smoother.feed(raw), self._smoother.flush()]) \
            if total else None
        return self._emit(smoothed, final=True)

    @property
    def _k(self) -> int:
        return self.model.codebook.pcs.shape[1]

    # ------------------------------------------------------------------ when
    def _ready(self, complete: int) -> int:
        """Frames before the returned one may be analysed: their LSF context is in, and their
        phone is settled or they have waited ``wait_s``."""
        settled = self.phones.settled_s
        waited = int(np.floor((self.front.received_s - self.timing.wait_s) * self.rate)) + 1
        by_phone = max(int(np.ceil(settled * self.rate - 1e-9)), waited)
        return max(self._next, min(complete - self._ctx, by_phone))

    # ------------------------------------------------------------------ eqs 4-8
    def _lsf(self, stop: int, total: int | None) -> None:
        """LSFs up to frame ``stop`` (clipped to the frames that exist), the cache kept from the
        context of the next frame to analyse."""
        end = self._w0 + len(self._w)
        stop = min(stop, total) if total is not None else stop
        if stop > end:
            self._w = np.concatenate([self._w, self.front.lsf(end, stop)])
            self.front.release(stop)
        drop = self._next - self._ctx - self._w0
        if drop > 0:
            self._w, self._w0 = self._w[drop:], self._w0 + drop

    def _analyse(self, stop: int, total: int | None) -> np.ndarray:
        """Raw PCs (eqs 4-8) of frames ``self._next .. stop-1`` (``total``: the audio ended)."""
        a = self._next
        self._lsf(stop + self._ctx, total)
        frames = np.arange(a, stop)
        last = (total if total is not None else self._w0 + len(self._w)) - 1
        w = self._w[frames - self._w0]
        w_ctx = None
        if self._ctx:
            at = np.clip(frames[:, None] + context_offsets(self.model)[None, :], 0, last)
            w_ctx = self._w[at - self._w0]
        times = frames / self.rate
        snap = self.phones.snapshot(times[0], self.model.config.context)
        labelled = times < snap.settled_s
        raw = np.zeros((len(frames), self._k))
        if labelled.any():
            raw[labelled] = self._robust(w[labelled], None if w_ctx is None else w_ctx[labelled],
                                         times[labelled], snap)
        if (~labelled).any():
            wa = w[~labelled]
            raw[~labelled] = weight_frames(wa, acoustic_candidates(self.model, wa, self.synth,
                                                                   self._grouped),
                                           self.model.codebook.lsf, self.model.codebook.pcs,
                                           self._gammas).pcs
        self._voice.add(w)
        self.labelled += labelled.tolist()
        self._next = stop
        return raw

    def _robust(self, w: np.ndarray, w_ctx: np.ndarray | None, times: np.ndarray,
                snap: PhoneSnapshot) -> np.ndarray:
        """The robust mode on frames whose phones are settled."""
        segs = snap.segments
        labels = [self._model_label(s) for s in segs]
        unknown = np.array([m == SILENCE and s.label != SILENCE for m, s in zip(labels, segs,
                                                                               strict=True)])
        ids = [self._phone_id[m] for m in labels]
        frame_seg = segment_index(segs, times)
        rows = context_ids(ids, self.model.config.context, self._phone_id[SILENCE])
        candidates = self._eq4(rows[frame_seg])
        conf = trust_by_voice(frame_confidence(segs, snap.confidence, times), self.voice.ratio,
                              self.synth.label_weight_by_voice)
        conf[unknown[frame_seg]] = 0.0
        scale = self.voice.weight_scale(self.synth.label_weight_by_voice)
        return robust_weights(self.model, w, candidates, conf, self.synth, scale, w_ctx).pcs

    def _model_label(self, seg) -> str:
        """The model's phone for a recognized one (its fallback, or silence: unlabelled, as
        offline in the robust mode), looked up once per label (and warned about once)."""
        if seg.label not in self._mapped:
            self._mapped[seg.label] = map_labels([seg], self.model.phones, None, "live",
                                                 unknown_as=SILENCE)[0].label
        return self._mapped[seg.label]

    # ------------------------------------------------------------------ out
    def _emit(self, smoothed: np.ndarray | None, final: bool) -> StreamFrames:
        self._voice.update(final)
        pcs = np.zeros((0, self._k)) if smoothed is None else smoothed
        closure = self._closure
        if closure is not None and (len(pcs) or final or closure.received > closure.emitted):
            pcs = closure.feed(pcs, self._plan(), final,
                               self.speech.known if self.synth.rest else None)
        index = np.arange(self._emitted, self._emitted + len(pcs))
        self._emitted += len(pcs)
        return StreamFrames(index, index / self.rate, pcs, self.model.to_markers(pcs))

    def _plan(self) -> ClosurePlan:
        """The settled /p b m/ and the pauses around the frames about to be emitted."""
        since = self._emitted / self.rate - ClosureStream.KEEP_S
        snap = self.phones.snapshot(max(0.0, since))
        bil = [s for s in snap.segments if s.label in BILABIALS]
        intervals = np.array([(s.start, min(s.end, snap.settled_s)) for s in bil]).reshape(-1, 2)
        strengths = closure_strengths(len(bil), self.kind, self.voice.match)
        first = max(0, self._emitted - self._closure.lookback)
        silent, leading = decided_silence(self.speech.decisions, first,
                                          lambda times: recognized_silence(snap, times), self.rate) \
            if self.synth.rest else (np.zeros(0, dtype=bool), False)
        if not self.synth.closure_labels:
            intervals, strengths = np.zeros((0, 2)), np.zeros(0)
        return ClosurePlan(intervals, strengths, silent, silent_from=first, leading=leading)



def recognized_silence(snap: PhoneSnapshot, times: np.ndarray) -> np.ndarray:
    """Whether the settled phone at each of ``times`` is silence (times not settled: no). Before
    a stream's energy has spanned its range (:mod:`facetraj_engine.streaming.speech`: the silence before
    the first words), the recognizer says where the pauses are.

    >>> from facetraj_engine.data import PhoneSegment
    >>> snap = PhoneSnapshot([PhoneSegment(0, .3, "sil"), PhoneSegment(.3, .4, "b")],
    ...                      np.ones(2), 0.4)
    >>> recognized_silence(snap, np.array([0.1, 0.35, 0.5])).tolist()
    [True, False, False]
    """
    out = np.zeros(len(times), dtype=bool)
    for seg in snap.segments:
        if seg.label == SILENCE:
            out |= (times >= seg.start) & (times < min(seg.end, snap.settled_s))
    return out
