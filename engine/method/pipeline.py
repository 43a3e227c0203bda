"""The synthesis pipeline (paper section 2.3): input LSFs, the candidate codewords of each frame
(eq 4 in phonetic mode, the LSF index in acoustic-only mode, both in the robust mode), eqs 5-8
(``engine.method.synthesis``; ``engine.method.selection`` for the robust mode), smoothing, and the PCs back to
face points.

The rule for which mode the labels allow lives here, once: :func:`mode_for`.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..config import SynthConfig
from ..data import PhoneSegment
from ..errors import InputError
from ..io.labelfiles import validate_phones
from ..labels.phoneset import SILENCE, map_labels
from ..threads import frame_threads, map_spans
from .context import context_ids, segment_index
from .model import Model
from .selection import mean_normalise, robust_frames
from .similarity import top_context_phones
from .smoothing import smooth
from .speaker import choose_warp, warp_lsf
from .synthesis import FrameWeights, gamma_grid, nearest_codewords, weight_frames

log = logging.getLogger(__name__)


#: Label sources that are hand-checked (``engine.labels.alignment.Labels.source``): a label file is taken
#: as hand-checked; aligned and recognized labels are not.
HAND_CHECKED = ("file",)


def mode_for(config: SynthConfig, phones: Sequence[PhoneSegment] | None,
             source: str | None = "file", explicit: bool = False) -> SynthConfig:
    """THE rule for the synthesis mode the labels allow: ``config``, switched

    * to acoustic-only when a mode that needs labels (phonetic, robust) has none;
    * from phonetic to ``robust`` when the labels are not hand-checked (``source`` not in
      :data:`HAND_CHECKED`: aligned or recognized), unless the user chose phonetic
      (``explicit``) -- the paper's eq 4 trusts its labels fully.

    >>> mode_for(SynthConfig(), None).mode
    'acoustic'
    >>> mode_for(SynthConfig(), [PhoneSegment(0.0, 0.1, "sil")]).mode
    'phonetic'
    >>> mode_for(SynthConfig(), [PhoneSegment(0.0, 0.1, "sil")], "recognized").mode
    'robust'
    >>> mode_for(SynthConfig(), [PhoneSegment(0.0, 0.1, "sil")], "aligned", explicit=True).mode
    'phonetic'
    """
    if config.mode in ("phonetic", "robust") and not phones:
        log.info("no phone labels: acoustic-only synthesis")
        return config.with_(mode="acoustic")
    if config.mode == "phonetic" and source not in HAND_CHECKED and not explicit:
        log.info("%s labels are not hand-checked: robust synthesis", source)
        return config.with_(mode="robust")
    return config


@dataclass
class SegmentChoice:
    """The context-phones chosen for one input phone segment (eq 4)."""

    segment: PhoneSegment
    context: np.ndarray      # (2C+1,) phone ids of the input context-phone
    chosen: np.ndarray       # (N,) codebook context-phone indices, best first
    scores: np.ndarray       # (N,) their n_j


@dataclass
class Synthesis:
    """The result of :func:`synthesize`.

    Attributes
    ----------
    times : ``(T,)`` frame times in seconds (frame t at ``t / marker_rate``).
    lsf : ``(T, P)`` input LSF vectors w (after the speaker warp, if any).
    raw_pcs : ``(T, K)`` unsmoothed p-hat(t) (eq 8).
    pcs : ``(T, K)`` smoothed PCs; ``markers`` ``(T, M, 3)`` rebuilt from them (head frame).
    frames : per-frame eq 5-8 details (gamma, weights, candidates, w-hat).
    segments : per input phone, the chosen context-phones (phonetic mode), else empty.
    frame_segment : ``(T,)`` index into ``segments`` (phonetic mode), else -1.
    warp : the speaker warp factor applied to the input LSFs (``config.speaker_warp``).
    """

    times: np.ndarray
    lsf: np.ndarray
    raw_pcs: np.ndarray
    pcs: np.ndarray
    markers: np.ndarray
    frames: FrameWeights
    config: SynthConfig
    segments: list[SegmentChoice] = field(default_factory=list)
    frame_segment: np.ndarray | None = None
    warp: float = 1.0

    def arrays(self) -> dict[str, np.ndarray]:
        """What an ``.npz`` output keeps of the synthesis beside its markers
        (:func:`engine.io.export.write_trajectories`)."""
        return {"times": self.times, "pcs": self.pcs, "raw_pcs": self.raw_pcs,
                "gamma": self.frames.gamma, "lsf": self.lsf,
                "config": np.array(json.dumps(self.config.to_dict()))}


def check_length(model: Model, n_samples: int, sample_rate: int, source: str | None,
                 n_frames: int = 2) -> None:
    """Refuse audio shorter than two of the model's marker frames (nothing to smooth or
    interpolate), naming ``source``: before synthesis, and as soon as a file is read (the
    command line, the app's Open audio)."""
    duration = n_samples / float(sample_rate)
    if n_frames < 2 or duration < 2.0 / model.marker_rate:
        raise InputError(source, f"the audio is too short ({duration * 1000:.1f} ms) to synthesize")


def synthesize(model: Model, audio: np.ndarray, sample_rate: int,
               phones: Sequence[PhoneSegment] | None = None, config: SynthConfig | None = None,
               n_frames: int | None = None, label_map: Mapping[str, str] | None = None,
               source: str | None = None, lsf: np.ndarray | None = None,
               audio_source: str | None = None,
               confidence: Sequence[float] | np.ndarray | None = None) -> Synthesis:
    """Synthesize face point trajectories from speech (paper section 2.3).

    With ``phones`` and ``mode="phonetic"``: per input phone, the top-N context-phones by eq 4,
    and per frame eqs 5-8 over their 5N codewords. Otherwise (acoustic-only) eqs 5-8 over the
    ``config.acoustic_prefilter`` codewords nearest to each frame, found through the model's LSF
    index (``acoustic_probe`` cells), or over the whole codebook as the paper does
    (``acoustic_prefilter=None``). With ``mode="robust"`` (``engine.method.selection``): eq 4's codewords
    and the ``robust_candidates`` acoustically nearest together, the target cost eq 5 with acoustic
    context plus ``label_weight`` times the label's ``confidence`` (one value in [0, 1] per phone,
    e.g. :attr:`engine.labels.alignment.Labels.confidence`; ``None``: 1, hand-checked) for codewords eq 4
    did not choose. Then smoothing, and the PCs back to ``(T, M, 3)`` markers.

    ``n_frames`` defaults to every marker frame inside the audio. ``source`` names the input (the
    labels) in error messages, ``audio_source`` the audio (default ``source``).
    ``lsf`` may pass the input LSFs already computed by :meth:`Model.input_lsf`
    for these frames (when one utterance is synthesized under several configs).
    """
    config = config or SynthConfig()
    duration = len(audio) / float(sample_rate)
    rate = model.marker_rate
    if n_frames is None:
        n_frames = int(np.floor(duration * rate + 1e-9)) + 1
    check_length(model, len(audio), sample_rate, audio_source or source, n_frames)
    times = np.arange(n_frames) / rate
    mc = model.config
    threads = frame_threads()
    if lsf is None:
        w = model.input_lsf(audio, sample_rate, times, threads)
    elif lsf.shape != (n_frames, mc.lpc_order):
        raise ValueError(f"lsf must be ({n_frames}, {mc.lpc_order}) for these frames, got {lsf.shape}")
    else:
        w = lsf
    w, warp = normalise_speaker(model, w, config)
    cb = model.codebook
    segments: list[SegmentChoice] = []
    frame_seg = None
    if config.mode == "robust" and config.mean_normalise:
        w = mean_normalise(w, model.lsf_mean)
    if config.mode in ("phonetic", "robust"):
        if not phones:
            raise InputError(source, f"{config.mode} mode needs phone labels (or use acoustic mode)")
        segs = validate_phones(list(phones), duration, source)
        segs = map_labels(segs, model.phones, label_map, source)
        pid = {p: i for i, p in enumerate(model.phones)}
        ctx = context_ids([pid[s.label] for s in segs], mc.context, pid[SILENCE])
        s = model.similarity(config.nu)
        top, scores = top_context_phones(ctx, cb.contexts, s, config.xi,
                                         min(config.context, mc.context), config.n_context_phones)
        segments = [SegmentChoice(seg, ctx[i], top[i], scores[i]) for i, seg in enumerate(segs)]
        frame_seg = segment_index(segs, times)
        candidates = cb.codewords_of(top)[frame_seg]
        if config.mode == "robust":
            conf = frame_confidence(list(phones), confidence, times)
            near = model.lsf_index().nearest(w, cb.lsf, config.robust_candidates,
                                              config.acoustic_probe or 8)
            fw = robust_frames(w, candidates, near, conf, cb.lsf, cb.pcs, _gammas(config),
                               config.label_weight, cb.lsf_context,
                               np.array([-mc.lsf_context_frames, mc.lsf_context_frames]),
                               config.context_weight)
            return _finish(model, times, w, fw, config, segments, frame_seg, warp)

        def span(a: int, b: int) -> FrameWeights:
            return weight_frames(w[a:b], candidates[a:b], cb.lsf, cb.pcs, _gammas(config))
    elif config.mode == "acoustic":
        def span(a: int, b: int) -> FrameWeights:
            return weight_frames(w[a:b], acoustic_candidates(model, w[a:b], config), cb.lsf,
                                 cb.pcs, _gammas(config))
    else:
        raise ValueError(f"unknown mode {config.mode!r} (phonetic, acoustic or robust)")
    fw = FrameWeights.concatenate(map_spans(span, n_frames, threads))    # frames independent
    return _finish(model, times, w, fw, config, segments, frame_seg, warp)


def _gammas(config: SynthConfig) -> np.ndarray:
    return gamma_grid(config.gamma_min, config.gamma_max, config.gamma_steps)


def _finish(model: Model, times: np.ndarray, w: np.ndarray, fw: FrameWeights, config: SynthConfig,
            segments: list[SegmentChoice], frame_seg: np.ndarray | None, warp: float) -> Synthesis:
    """Smoothing and the PCs back to markers."""
    pcs = smooth(fw.pcs, model.marker_rate, config.smoothing, config.triangle_s,
                 config.spline_knot_s)
    return Synthesis(times=times, lsf=w, raw_pcs=fw.pcs, pcs=pcs, markers=model.to_markers(pcs),
                     frames=fw, config=config, segments=segments, frame_segment=frame_seg,
                     warp=warp)


def normalise_speaker(model: Model, w: np.ndarray, config: SynthConfig) -> tuple[np.ndarray, float]:
    """The input LSFs ``w`` warped by ``config.speaker_warp`` (chosen here for these frames when
    it is ``None``), and the warp factor (``engine.method.speaker``)."""
    alpha = config.speaker_warp
    if alpha is None:
        alpha = choose_warp(w, model.codebook.lsf)
        log.info("speaker warp %.2f chosen", alpha)
    return (w, 1.0) if alpha == 1.0 else (warp_lsf(w, alpha), float(alpha))


def acoustic_candidates(model: Model, w: np.ndarray, config: SynthConfig,
                        grouped: np.ndarray | None = None) -> np.ndarray:
    """Acoustic-only candidates ``(T, I)`` of frames ``w``: the ``config.acoustic_prefilter``
    codewords nearest by eq 5 through the model's LSF index (``acoustic_probe`` cells), or exactly,
    or every codeword (``acoustic_prefilter=None``, as the paper does). ``grouped``: the index's
    :meth:`~engine.method.lsf_index.LsfIndex.grouped` codebook, when the caller keeps it."""
    cb = model.codebook
    if config.acoustic_prefilter is not None and config.acoustic_probe is not None:
        return model.lsf_index().nearest(w, cb.lsf, config.acoustic_prefilter,
                                         config.acoustic_probe, grouped=grouped)
    return nearest_codewords(w, cb.lsf, config.acoustic_prefilter)   # every one, or exact K


def frame_confidence(phones: Sequence[PhoneSegment], confidence: Sequence[float] | np.ndarray | None,
                     times: np.ndarray) -> np.ndarray:
    """Each frame's label confidence in [0, 1]: that of the phone holding it (1 everywhere when
    ``confidence`` is ``None``: hand-checked labels; a NaN confidence, a phone without a score,
    counts 1/2).

    >>> segs = [PhoneSegment(0.0, 0.1, "sil"), PhoneSegment(0.1, 0.2, "p")]
    >>> frame_confidence(segs, [0.9, float("nan")], np.array([0.05, 0.15])).tolist()
    [0.9, 0.5]
    """
    if confidence is None:
        return np.ones(len(times))
    c = np.asarray(confidence, dtype=np.float64)
    if c.shape != (len(phones),):
        raise ValueError(f"{c.size} label confidences for {len(phones)} phones")
    c = np.clip(np.where(np.isfinite(c), c, 0.5), 0.0, 1.0)
    return c[segment_index(phones, times)]


def resmooth(model: Model, result: Synthesis, method: str) -> np.ndarray:
    """Markers ``(T, M, 3)`` from ``result``'s raw PCs smoothed with another ``method``."""
    cfg = result.config
    return model.to_markers(smooth(result.raw_pcs, model.marker_rate, method, cfg.triangle_s,
                                   cfg.spline_knot_s))
