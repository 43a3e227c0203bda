"""The synthesis pipeline (paper section 2.3): input LSFs, the mode's search of each frame's
candidate codewords and eqs 5-8 (:mod:`facetraj_engine.method.modes`: eq 4 in the phonetic mode, the LSF
index in the acoustic-only mode, both in the robust mode), smoothing, the closure step, and the
PCs back to face points.

Which mode the labels allow is :func:`facetraj_engine.method.modes.choose_mode`, the one rule.
"""

from __future__ import annotations

import functools
import json
import logging
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..config import SynthConfig
from ..data import PhoneSegment, Provenance
from ..errors import InputError, warn_file
from ..io.labelfiles import validate_phones
from ..labels.phoneset import SILENCE, map_labels, normalise_label
from ..threads import above_blas, frame_threads
from .closure import (
    ClosurePlan,
    aperture_functional,
    apply_closure,
    closure_intervals,
    closure_strengths,
    labelled_speech,
    outer_silence,
)
from .closure_detector import beside, causal_closures, closure_runs, frame_energy_db, input_probability
from .closure_search import search_rows
from .context import segment_index
from .model import Model, analysed_frames
from .modes import mode_of
from .resynthesis import SynthesisMemo
from .search import SearchInput, SegmentChoice
from .selection import mean_normalise
from .smoothing import smooth
from .speaker import choose_warp, warp_lsf
from .speech import filtered_energy_db, ranged_speech, speech_mask
from .synthesis import FrameWeights
from .voice_match import frame_matches, match_from, voice_distance, voice_match

log = logging.getLogger(__name__)


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
    closure : where the closure step acted (:mod:`facetraj_engine.method.closure`), ``None`` when off.
    voice_match : the input's voice match (:func:`input_voice_match`) when the synthesis needed
        it (the robust mode, recognized labels), else NaN; ``voice_ratio`` the distance ratio
        ``D / D0`` it is made from.
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
    closure: ClosurePlan | None = None
    voice_match: float = float("nan")
    voice_ratio: float = float("nan")

    def arrays(self) -> dict[str, np.ndarray]:
        """What an ``.npz`` output keeps of the synthesis beside its markers
        (:func:`facetraj_engine.io.export.write_trajectories`)."""
        return {"times": self.times, "pcs": self.pcs, "raw_pcs": self.raw_pcs,
                "gamma": self.frames.gamma, "lsf": self.lsf,
                "config": np.array(json.dumps(self.config.to_dict()))}


def frame_count(n_samples: int, sample_rate: int, marker_rate: float) -> int:
    """The marker frames synthesized from ``n_samples`` of audio: every frame inside it, the
    first at 0 s.

    >>> frame_count(16000, 16000, 60.0)
    61
    """
    return int(np.floor(n_samples / float(sample_rate) * marker_rate + 1e-9)) + 1


def check_length(model: Model, n_samples: int, sample_rate: int, source: str | None,
                 n_frames: int = 2) -> None:
    """Refuse audio shorter than two of the model's marker frames (nothing to smooth or
    interpolate), naming ``source``: before synthesis, and as soon as a file is read (the
    command line, the app's Open audio)."""
    duration = n_samples / float(sample_rate)
    if n_frames < 2 or duration < 2.0 / model.marker_rate:
        raise InputError(source, f"the audio is too short ({duration * 1000:.1f} ms) to synthesize")


@above_blas
def synthesize(model: Model, audio: np.ndarray, sample_rate: int,
               phones: Sequence[PhoneSegment] | None = None, config: SynthConfig | None = None,
               n_frames: int | None = None, label_map: Mapping[str, str] | None = None,
               source: str | None = None, lsf: np.ndarray | None = None,
               audio_source: str | None = None,
               confidence: Sequence[float] | np.ndarray | None = None,
               provenance: Provenance | None = None, voice: bool = False,
               memo: SynthesisMemo | None = None, checked: np.ndarray | None = None) -> Synthesis:
    """Synthesize face point trajectories from speech (paper section 2.3).

    With ``phones`` and ``mode="phonetic"``: per input phone, the top-N context-phones by eq 4,
    and per frame eqs 5-8 over their 5N codewords. Otherwise (acoustic-only) eqs 5-8 over the
    ``config.acoustic_prefilter`` codewords nearest to each frame, found through the model's LSF
    index (``acoustic_probe`` cells), or over the whole codebook as the paper does
    (``acoustic_prefilter=None``). With ``mode="robust"`` (``facetraj_engine.method.selection``): eq 4's
    codewords and the ``robust_candidates`` acoustically nearest together, the target cost eq 5
    with acoustic context plus ``label_weight`` times the label's ``confidence`` (one value in
    [0, 1] per phone, e.g. :attr:`facetraj_engine.labels.provenance.Labels.confidence`; ``None``: 1,
    hand-checked) for codewords eq 4 did not choose. Then smoothing; with ``config.closure`` the
    lips close at the labelled /p b m/ and the face rests in pauses (:mod:`facetraj_engine.method.closure`,
    trusting each label as its ``provenance`` says: ``None``, hand-checked); and the PCs back to
    ``(T, M, 3)`` markers.

    ``n_frames`` defaults to every marker frame inside the audio. ``source`` names the input (the
    labels) in error messages, ``audio_source`` the audio (default ``source``).
    ``lsf`` may pass the input LSFs already computed by :meth:`Model.input_lsf`
    for these frames (when one utterance is synthesized under several configs). ``voice``: the
    input's voice match is computed even when the synthesis does not need it (to show it).
    The input's speech energy (pauses, speech frames) is computed once for both. ``memo``: the
    same recording's last synthesis, whose work is reused where the labels leave it unchanged
    (:mod:`facetraj_engine.method.resynthesis`: the same result, sooner). ``checked``: per phone
    of automatic labels, corrected by hand since (the closure step trusts those fully).
    """
    config = config or SynthConfig()
    trusted = _checked(phones, checked)
    if memo is None:
        return _synthesize(model, audio, sample_rate, phones, config, n_frames, label_map, source,
                           lsf, audio_source, confidence, provenance, voice, None, trusted)
    with memo.lock:
        memo.bind(model, audio, sample_rate, n_frames, config)
        try:
            return _synthesize(model, audio, sample_rate, phones, config, n_frames, label_map,
                               source, lsf, audio_source, confidence, provenance, voice, memo,
                               trusted)
        except BaseException:
            memo.forget()               # half updated: the next synthesis starts again
            raise


def _synthesize(model: Model, audio: np.ndarray, sample_rate: int,
                phones: Sequence[PhoneSegment] | None, config: SynthConfig, n_frames: int | None,
                label_map: Mapping[str, str] | None, source: str | None, lsf: np.ndarray | None,
                audio_source: str | None, confidence: Sequence[float] | np.ndarray | None,
                provenance: Provenance | None, voice: bool, memo: SynthesisMemo | None,
                trusted: list[PhoneSegment] | None = None) -> Synthesis:
    """:func:`synthesize`'s steps (``memo``: bound to this input, or ``None``; ``trusted``: the
    phones corrected by hand)."""
    mode = mode_of(config)
    remember = memo.remember if memo is not None else (lambda _key, compute: compute())
    detecting = detector_may_run(model, config, provenance)
    times, w, warp, analysed, energy_db = remember(("input", detecting), lambda: _input(
        model, audio, sample_rate, n_frames, lsf, config, audio_source or source, detecting))
    energy = remember("energy", lambda: SpeechEnergy(audio, sample_rate))
    recognized = provenance is not None and provenance.kind == "recognized"
    ratio = remember(("voice", recognized, voice), lambda: _voice_ratio(
        model, energy, times, w, config, provenance, voice)) \
        if mode.weighs_labels else float("nan")             # the search weighs by it
    job = SearchInput(model, w, times, config, voice_ratio=ratio, memo=memo)
    if mode.needs_labels:
        if not phones:
            raise InputError(source, f"{config.mode} mode needs phone labels (or use acoustic mode)")
        job.segs, job.unlabelled = _model_phones(model, phones, len(audio) / sample_rate,
                                                 label_map, source, times)
        if mode.weighs_labels:
            job.confidence = frame_confidence(list(phones), confidence, times)
    found = mode.search(job)
    if not mode.weighs_labels:                     # after the search: it may find the nearest
        ratio = _voice_ratio(model, energy, times, w, config, provenance, voice, found.nearest)
    plan = plan_closure(model, audio, sample_rate, times, job.segs, provenance,
                        voice_match(ratio, 1.0), config, energy.filtered if config.closure else None,
                        analysed, found.frames, energy_db, trusted)
    res = _finish(model, times, w, found.frames, config, found.segments, found.frame_segment,
                  warp, plan)
    res.voice_match, res.voice_ratio = voice_match(ratio, 1.0), ratio
    return res


def _input(model: Model, audio: np.ndarray, sample_rate: int, n_frames: int | None,
           lsf: np.ndarray | None, config: SynthConfig, source: str | None, detecting: bool
           ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray | None, np.ndarray | None]:
    """The frame times, the input LSFs w of eq 5 (computed here unless given; speaker-normalised),
    the speaker warp, and the LSFs before the normalisation for the closure detector: those
    computed here, or the given ones when no normalisation changed them (``None`` otherwise: the
    detector analyses the audio itself, inside :func:`synthesize`'s BLAS limit, and a caller's
    LSFs may differ from those to rounding); with ``detecting``, the detector's frame energies
    of the LSFs computed here (:func:`~facetraj_engine.method.closure_detector.frame_energy_db`
    of the same analysis frames), else ``None``."""
    rate = model.marker_rate
    if n_frames is None:
        n_frames = frame_count(len(audio), sample_rate, rate)
    check_length(model, len(audio), sample_rate, source, n_frames)
    times = np.arange(n_frames) / rate
    order = model.config.lpc_order
    energy_db = None
    if lsf is None:
        raw, energy_db = analysed_frames(model.config, audio, sample_rate, times, frame_threads(),
                                         frame_energy_db if detecting else None)
    elif lsf.shape != (n_frames, order):
        raise ValueError(f"lsf must be ({n_frames}, {order}) for these frames, got {lsf.shape}")
    else:
        raw = lsf
    w, warp = normalise_speaker(model, raw, config)
    if mode_of(config).weighs_labels and config.mean_normalise:
        w = mean_normalise(w, model.lsf_mean)
    return times, w, warp, raw if lsf is None or w is lsf else None, energy_db


def _model_phones(model: Model, phones: Sequence[PhoneSegment], duration: float,
                  label_map: Mapping[str, str] | None, source: str | None, times: np.ndarray
                  ) -> tuple[list[PhoneSegment], np.ndarray]:
    """The labels checked against the audio and mapped onto the model's phones, and which are
    unlabelled: a phone the model has never seen (silence for its neighbours' context; its
    frames are the acoustic search's in every mode), with one warning naming each such phone and
    its frames."""
    segs = validate_phones(list(phones), duration, source)
    raw = [normalise_label(s.label) for s in segs]
    segs = map_labels(segs, model.phones, label_map, source, unknown_as=SILENCE, warn_unknown=False)
    unlabelled = np.array([s.label == SILENCE and r != SILENCE for s, r in zip(segs, raw, strict=True)])
    if unlabelled.any():
        frames = Counter(raw[i] for i in segment_index(segs, times) if unlabelled[i])
        unseen = ", ".join(f"{lab!r} ({n} frame{'s' * (n != 1)})" for lab, n in frames.items()) \
            or ", ".join(sorted({repr(r) for r, u in zip(raw, unlabelled, strict=True) if u}))
        warn_file(log, source, "phones not in the model, filled by the acoustic search",
                  f"phones the model has never seen, their frames filled by the acoustic search: "
                  f"{unseen}")
    return segs, unlabelled


def _finish(model: Model, times: np.ndarray, w: np.ndarray, fw: FrameWeights, config: SynthConfig,
            segments: list[SegmentChoice], frame_seg: np.ndarray | None, warp: float,
            plan: ClosurePlan | None) -> Synthesis:
    """Smoothing, the closure step, and the PCs back to markers."""
    pcs = _smoothed(model, fw.pcs, times, config, config.smoothing, plan)
    return Synthesis(times=times, lsf=w, raw_pcs=fw.pcs, pcs=pcs, markers=model.to_markers(pcs),
                     frames=fw, config=config, segments=segments, frame_segment=frame_seg,
                     warp=warp, closure=plan)


def _smoothed(model: Model, raw: np.ndarray, times: np.ndarray, config: SynthConfig, method: str,
              plan: ClosurePlan | None) -> np.ndarray:
    """Raw PCs smoothed by ``method``, then the closure step when there is a plan."""
    pcs = smooth(raw, model.marker_rate, method, config.triangle_s, config.spline_knot_s)
    if plan is None:
        return pcs
    a0, g = aperture_functional(model.pca, model.upper_lip, model.lower_lip)
    return apply_closure(pcs, times, plan, model.closure, a0, g, model.marker_rate,
                         config.closure_taper_s, config.rest_pause_s, config.rest_taper_s,
                         config.rest_lookahead_s)


def plan_closure(model: Model, audio: np.ndarray, sample_rate: int, times: np.ndarray,
                 segs: Sequence[PhoneSegment] | None, provenance: Provenance | None,
                 match: float, config: SynthConfig, filtered: np.ndarray | None = None,
                 lsf: np.ndarray | None = None, frames: FrameWeights | None = None,
                 energy_db: np.ndarray | None = None,
                 trusted: Sequence[PhoneSegment] | None = None) -> ClosurePlan | None:
    """Where the closure step acts (``None``: off, or a model file without its statistics): the
    labelled /p b m/ (``config.closure_labels``), trusted as
    :func:`~facetraj_engine.method.closure.closure_strengths` says (for recognized labels by the
    voice ``match``; NaN: unknown, untrusted), and beside recognized ones the detector's closures
    where none is recognized, trusted by the voice ``match`` (``config.closure_second_opinion``,
    off by default); without labels, the closures the model's detector finds
    (``config.closure_detector``, fully trusted, closed as a stream closes them; ``lsf``: the
    input's LSFs at ``times`` before any speaker warp or mean normalisation, when computed;
    ``frames``: the acoustic-only search's, whose opinion counts by the voice ``match`` from the
    frame a stream would have measured it; ``energy_db``: the detector's frame energies of
    ``lsf``'s analysis, when computed with it); and the silent frames by energy, where the face
    rests (``config.rest``; ``filtered``: :func:`~facetraj_engine.method.speech.filtered_energy_db`
    of the audio, when already computed); ``trusted``: phones corrected by hand, whose /p b m/
    close fully whatever their labels' kind."""
    if not config.closure or model.closure is None:
        return None
    intervals, strengths, p = np.zeros((0, 2)), np.zeros(0), None
    causal = np.zeros(0, dtype=bool)
    speech, ranged = ranged_speech(audio, sample_rate, times, filtered=filtered)
    detecting = config.closure_detector and model.detector is not None
    heard = match_from(speech & ranged)
    if segs:
        kind = (provenance or Provenance()).kind
        if config.closure_labels:
            trust = closure_strengths(len(segs), kind, match if np.isfinite(match) else 1.0)
            if trusted:
                trust = np.where(_among(segs, trusted), 1.0, trust)
            intervals, strengths = closure_intervals(segs, trust)
            causal = np.zeros(len(intervals), dtype=bool)
        if model.detector is not None and kind == "recognized" and \
                config.closure_second_opinion and np.isfinite(match) and match > 0:
            p, runs = _detected(model, audio, sample_rate, times, lsf, None, match, heard, config,
                                energy_db)
            added = beside(runs, intervals)
            intervals = np.concatenate([intervals, added])
            strengths = np.concatenate([strengths, np.full(len(added), match)])
            causal = np.concatenate([causal, np.ones(len(added), dtype=bool)])
    elif detecting:
        p, intervals = _detected(model, audio, sample_rate, times, lsf, frames, match, heard, config,
                                 energy_db)
        strengths, causal = np.ones(len(intervals)), np.ones(len(intervals), dtype=bool)
        log.debug("closure step: the lips close at %d closures the detector found", len(intervals))
    silent = ~speech & ranged if config.rest else np.zeros(len(times), dtype=bool)
    if segs:       # a labelled consonant's silence inside speech is its closure, not a pause
        silent &= ~(labelled_speech(segs, times) & ~outer_silence(silent))
    return ClosurePlan(intervals, strengths, silent, p, causal, leading=config.rest,
                       end=len(times))


def _detected(model: Model, audio: np.ndarray, sample_rate: int, times: np.ndarray,
              lsf: np.ndarray | None, frames: FrameWeights | None, match: float, heard: int,
              config: SynthConfig, energy_db: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """The detector's probabilities and closures of an input (:func:`plan_closure`; the closures
    from each run's confirming frame, :func:`~facetraj_engine.method.closure_detector.causal_closures`);
    the voice ``match`` counts from frame ``heard`` on (before it a stream has not measured the
    voice: :func:`~facetraj_engine.method.voice_match.match_from`); the acoustic-only search is
    made here when its opinion counts and ``frames`` is not that search's (``energy_db``: the
    frame energies of ``lsf``'s analysis, when known)."""
    det = model.detector
    if lsf is None:
        lsf, energy_db = model.input_lsf(audio, sample_rate, times, frame_threads()), None
    m = frame_matches(match, len(times), heard)
    counts = det.search is not None and bool((m > 0).any())
    if frames is None and counts:
        acoustic = config.with_(mode="acoustic")
        frames = mode_of(acoustic).search(SearchInput(model, lsf, times, acoustic)).frames
    search = search_rows(model, frames) if frames is not None and counts else None
    p = input_probability(det, model.config, audio, sample_rate, times, lsf, search, m, energy_db)
    runs = closure_runs(p, times, config.closure_threshold, det.spec.min_frames)
    return p, causal_closures(runs, model.marker_rate, det.spec.min_frames)


def _checked(phones: Sequence[PhoneSegment] | None, checked: np.ndarray | None
             ) -> list[PhoneSegment] | None:
    """The phones of ``phones`` that ``checked`` marks (``None``: none; flags of other phones
    than these, left over from labels replaced, count for none)."""
    if phones is None or checked is None:
        return None
    flags = np.asarray(checked, dtype=bool)
    if flags.shape != (len(phones),):
        log.debug("%d checked flags for %d phones: left out", flags.size, len(phones))
        return None
    return [p for p, c in zip(phones, flags, strict=True) if c] or None


def _among(segs: Sequence[PhoneSegment], trusted: Sequence[PhoneSegment]) -> np.ndarray:
    """Per segment (the labels checked and mapped onto the model's phones), whether it is one of
    ``trusted`` (the same times, within half a millisecond)."""
    starts = np.array([p.start for p in trusted])
    ends = np.array([p.end for p in trusted])
    return np.array([bool(np.any((np.abs(starts - s.start) < 5e-4) & (np.abs(ends - s.end) < 5e-4)))
                     for s in segs], dtype=bool)


def detector_may_run(model: Model, config: SynthConfig, provenance: Provenance | None) -> bool:
    """Whether :func:`plan_closure` may run the model's closure detector on an input of this
    ``config`` and labels' ``provenance``: without labels, or beside recognized ones (it then
    runs unless the voice match is 0); the input's analysis computes its frame energies then."""
    if not (config.closure and model.closure is not None and model.detector is not None):
        return False
    if not mode_of(config).needs_labels:
        return config.closure_detector
    return (provenance or Provenance()).kind == "recognized" and config.closure_second_opinion


class SpeechEnergy:
    """An input's filtered short-time energy (:func:`~facetraj_engine.method.speech.filtered_energy_db`:
    its speech frames and pauses), computed when first asked, once for every step that asks."""

    def __init__(self, audio: np.ndarray, sample_rate: int):
        self.audio, self.sample_rate = audio, sample_rate

    @functools.cached_property
    def filtered(self) -> np.ndarray:
        return filtered_energy_db(self.audio, self.sample_rate)


def _voice_ratio(model: Model, energy: SpeechEnergy, times: np.ndarray, w: np.ndarray,
                 config: SynthConfig, provenance: Provenance | None, wanted: bool,
                 nearest: np.ndarray | None = None) -> float:
    """The input's voice distance ratio when the synthesis weighs by it (a mode that weighs its
    labels by the voice, the closure step's trust in recognized labels) or it is ``wanted``,
    else NaN (not computed); ``nearest``: each frame's nearest codeword, when the search found
    it as the voice match does."""
    recognized = provenance is not None and provenance.kind == "recognized"
    detector = model.detector is not None and model.detector.search is not None and \
        config.closure_detector and not mode_of(config).needs_labels
    if not (wanted or (mode_of(config).weighs_labels and config.label_weight_by_voice) or
            (config.closure and (recognized or detector))):
        return float("nan")
    return input_voice_ratio(model, energy.audio, energy.sample_rate, times, w, energy.filtered,
                             nearest)


def input_voice_ratio(model: Model, audio: np.ndarray, sample_rate: int,
                      times: np.ndarray | None = None, w: np.ndarray | None = None,
                      filtered: np.ndarray | None = None, nearest: np.ndarray | None = None
                      ) -> float:
    """``D / D0`` (:mod:`facetraj_engine.method.voice_match`): how far an input's voice is from the
    codebook's, relative to the training voice's own figure, from the audio alone (its LSFs ``w``
    at ``times``, its filtered energy and its frames' nearest codewords when already computed;
    NaN for a model file without ``D0``)."""
    if not np.isfinite(model.voice_distance):
        return float("nan")
    if times is None or w is None:
        times = np.arange(int(np.floor(len(audio) / sample_rate * model.marker_rate)) + 1) \
            / model.marker_rate
        w = model.input_lsf(audio, sample_rate, times)
    speech = speech_mask(audio, sample_rate, times, filtered=filtered)
    return voice_distance(w, speech, model.codebook.lsf, model.lsf_index(),
                          nearest=nearest) / model.voice_distance


def input_voice_match(model: Model, audio: np.ndarray, sample_rate: int,
                      times: np.ndarray | None = None, w: np.ndarray | None = None) -> float:
    """The voice match in [0, 1] of an input (:func:`input_voice_ratio` through
    :func:`facetraj_engine.method.voice_match.voice_match`)."""
    return voice_match(input_voice_ratio(model, audio, sample_rate, times, w), 1.0)


def normalise_speaker(model: Model, w: np.ndarray, config: SynthConfig) -> tuple[np.ndarray, float]:
    """The input LSFs ``w`` warped by ``config.speaker_warp`` (chosen here for these frames when
    it is ``None``), and the warp factor (``facetraj_engine.method.speaker``)."""
    alpha = config.speaker_warp
    if alpha is None:
        alpha = choose_warp(w, model.codebook.lsf)
        log.info("speaker warp %.2f chosen", alpha)
    return (w, 1.0) if alpha == 1.0 else (warp_lsf(w, alpha), float(alpha))


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
    """Markers ``(T, M, 3)`` from ``result``'s raw PCs smoothed with another ``method`` (and its
    closure step, when it had one)."""
    return model.to_markers(_smoothed(model, result.raw_pcs, result.times, result.config, method,
                                      result.closure))
