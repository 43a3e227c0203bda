"""The candidate searches of the synthesis modes (paper section 2.3): eq 4's context-phones and
their 5N codewords, the LSF index's acoustically nearest codewords, the robust mode's both
together, and eqs 5-8 over each frame's candidates, split between frame threads. The modes
(:mod:`facetraj_engine.method.modes`) compose them."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..config import SynthConfig
from ..data import PhoneSegment
from ..labels.phoneset import SILENCE
from ..threads import frame_threads, map_spans
from .context import context_ids, segment_index
from .model import Model
from .resynthesis import SynthesisMemo, robust_frames_again
from .selection import context_frames, robust_frames
from .similarity import top_context_phones
from .synthesis import FrameWeights, gamma_grid, nearest_codewords, weight_frames
from .voice_match import PROBE as VOICE_PROBE


@dataclass
class SegmentChoice:
    """The context-phones chosen for one input phone segment (eq 4)."""

    segment: PhoneSegment
    context: np.ndarray      # (2C+1,) phone ids of the input context-phone
    chosen: np.ndarray       # (N,) codebook context-phone indices, best first
    scores: np.ndarray       # (N,) their n_j


@dataclass
class SearchInput:
    """What a mode's search is given: the model, the input frames' LSFs ``w`` ``(T, P)`` at
    ``times``, the labels mapped onto the model's phones (``segs``; ``None`` without labels),
    which of them the model lacks (``unlabelled``), each frame's label ``confidence`` in [0, 1],
    the input's voice distance ratio, and the settings."""

    model: Model
    w: np.ndarray
    times: np.ndarray
    config: SynthConfig
    segs: list[PhoneSegment] | None = None
    unlabelled: np.ndarray | None = None
    confidence: np.ndarray | None = None
    voice_ratio: float = float("nan")
    memo: SynthesisMemo | None = None       # the last label set's work (a label edited)


@dataclass
class SearchResult:
    """A search's eqs 5-8 per frame, and (the modes that read labels) each input phone's chosen
    context-phones (eq 4) and each frame's phone."""

    frames: FrameWeights
    segments: list[SegmentChoice] = field(default_factory=list)
    frame_segment: np.ndarray | None = None
    #: each frame's nearest codeword as the voice match finds it (through the LSF index), when
    #: the acoustic-only search found it on its way (else ``None``)
    nearest: np.ndarray | None = None


def eq4(model: Model, segs: list[PhoneSegment], times: np.ndarray, config: SynthConfig
        ) -> tuple[list[SegmentChoice], np.ndarray, np.ndarray]:
    """Eq 4 per input phone: its chosen context-phones, each frame's phone, and each frame's
    ``(T, 5N)`` candidate codewords."""
    mc, cb = model.config, model.codebook
    pid = {p: i for i, p in enumerate(model.phones)}
    ctx = context_ids([pid[s.label] for s in segs], mc.context, pid[SILENCE])
    top, scores = top_context_phones(ctx, cb.contexts, model.similarity(config.nu), config.xi,
                                     min(config.context, mc.context), config.n_context_phones,
                                     model.context_index)
    segments = [SegmentChoice(seg, ctx[i], top[i], scores[i]) for i, seg in enumerate(segs)]
    frame_seg = segment_index(segs, times)
    return segments, frame_seg, cb.codewords_of(top)[frame_seg]


def robust_weights(model: Model, w: np.ndarray, candidates: np.ndarray, conf: np.ndarray,
                   config: SynthConfig, scale: float = 1.0, w_ctx: np.ndarray | None = None,
                   memo: SynthesisMemo | None = None) -> FrameWeights:
    """The robust mode's eqs 5-8 (``facetraj_engine.method.selection``), its label weight times
    ``scale`` (the voice's distance ratio: eq 5's distances grow with it); ``w_ctx``: the input
    frames at :func:`context_offsets` when ``w`` is part of a longer input (a stream). The chain
    over frames (``facetraj_engine.method.chain``) is the search's, on the whole input. With a
    ``memo`` (``facetraj_engine.method.resynthesis``), the nearest codewords are the audio's
    kept and only the frames whose candidates or confidence changed are weighted again."""
    cb = model.codebook
    k, probe = config.robust_candidates, config.acoustic_probe or 8

    def nearest() -> np.ndarray:
        return model.lsf_index().nearest(w, cb.lsf, k, probe)

    near = nearest() if memo is None else memo.remember(("nearest", k, probe), nearest)
    kappa = config.label_weight * scale
    offsets = context_offsets(model)
    if memo is None:
        return robust_frames(w, candidates, near, conf, cb.lsf, cb.pcs, gammas(config), kappa,
                             cb.lsf_context, offsets, config.context_weight, w_ctx=w_ctx)
    ctx = memo.remember("context frames", lambda: context_frames(w, offsets))
    return robust_frames_again(memo, candidates, conf, kappa, lambda rows: robust_frames(
        w[rows], candidates[rows], near[rows], conf[rows], cb.lsf, cb.pcs, gammas(config), kappa,
        cb.lsf_context, offsets, config.context_weight, w_ctx=ctx[rows]))


def context_offsets(model: Model) -> np.ndarray:
    """The frame offsets of the robust mode's acoustic context (the codewords' stored LSFs)."""
    k = model.config.lsf_context_frames
    return np.array([-k, k])


def weighted(model: Model, w: np.ndarray, candidates: Callable[[int, int], np.ndarray],
             config: SynthConfig) -> FrameWeights:
    """Eqs 5-8 on each frame's candidates (``candidates(a, b)`` of frames ``a:b``), the frames
    split between threads (they are independent)."""
    cb = model.codebook

    def span(a: int, b: int) -> FrameWeights:
        return weight_frames(w[a:b], candidates(a, b), cb.lsf, cb.pcs, gammas(config))

    return FrameWeights.concatenate(map_spans(span, len(w), frame_threads()))


def gammas(config: SynthConfig) -> np.ndarray:
    """The gamma grid of eqs 6-7 that ``config`` asks for."""
    return gamma_grid(config.gamma_min, config.gamma_max, config.gamma_steps)


def acoustic_candidates(model: Model, w: np.ndarray, config: SynthConfig,
                        grouped: np.ndarray | None = None, first: np.ndarray | None = None
                        ) -> np.ndarray:
    """Acoustic-only candidates ``(T, I)`` of frames ``w``: the ``config.acoustic_prefilter``
    codewords nearest by eq 5 through the model's LSF index (``acoustic_probe`` cells), or exactly,
    or every codeword (``acoustic_prefilter=None``, as the paper does). ``grouped``: the index's
    :meth:`~facetraj_engine.method.lsf_index.LsfIndex.grouped` codebook, when the caller keeps it;
    ``first`` ``(T,)``: where the index writes each frame's nearest codeword
    (:func:`finds_voice_nearest` says when that is the voice match's)."""
    cb = model.codebook
    if config.acoustic_prefilter is not None and config.acoustic_probe is not None:
        return model.lsf_index().nearest(w, cb.lsf, config.acoustic_prefilter,
                                         config.acoustic_probe, grouped=grouped, first=first)
    return nearest_codewords(w, cb.lsf, config.acoustic_prefilter)   # every one, or exact K


def acoustic_search(model: Model, w: np.ndarray, config: SynthConfig) -> SearchResult:
    """The acoustic-only mode's search: eqs 5-8 on :func:`acoustic_candidates`, with each
    frame's nearest codeword when the index finds it as the voice match does."""
    first = np.empty(len(w), dtype=np.int64) if finds_voice_nearest(model, config) else None
    fw = weighted(model, w, lambda a, b: acoustic_candidates(
        model, w[a:b], config, first=None if first is None else first[a:b]), config)
    return SearchResult(fw, nearest=first)


def finds_voice_nearest(model: Model, config: SynthConfig) -> bool:
    """Whether :func:`acoustic_candidates` finds each frame's nearest codeword as the voice match
    does (:func:`facetraj_engine.method.voice_match.indexed_distances`): through the index,
    opening as many cells."""
    if config.acoustic_prefilter is None or config.acoustic_probe is None:
        return False
    index = model.lsf_index()
    return index.probes(config.acoustic_prefilter, config.acoustic_probe) == \
        index.probes(1, VOICE_PROBE)
