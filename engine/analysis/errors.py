"""The errors view's numbers: per-frame lip error, per-phone correlation and RMS error,
per-utterance errors and the worst segments of a synthesis against the original markers; and the
synthesized closures judged by the talker's own lips (issue 46,
:mod:`facetraj_engine.evaluation.closed_lips`)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import EvalConfig, SynthConfig
from ..data import PhoneSegment, Utterance
from ..evaluation.closed_lips import (
    ClosureAgreement,
    TalkerClosed,
    TalkerLips,
    agreements,
    talker_closed,
    talker_lips,
)
from ..evaluation.scores import pearson, speech_mask, trajectory_correlations
from ..io.corpus import Corpus
from ..method.context import segment_index
from ..method.model import Model
from ..method.pipeline import Synthesis, synthesize
from ..progress import Progress
from .apertures import SILENT_LABELS
from .common import write_csv


def lip_error(model: Model, original: np.ndarray, synthesized: np.ndarray) -> np.ndarray:
    """Per-frame ``|original - synthesized|`` (Euclidean, mm) of the upper and the lower lip
    centre markers, ``(T, 2)`` (columns upper, lower); NaN where the original is missing.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> o = np.zeros((2, 2, 3)); s = o.copy(); s[1, 1] = [3, 4, 0]
    >>> lip_error(SimpleNamespace(upper_lip=0, lower_lip=1), o, s).tolist()
    [[0.0, 0.0], [0.0, 5.0]]
    """
    n = min(len(original), len(synthesized))
    lips = [model.upper_lip, model.lower_lip]
    d = original[:n, lips] - synthesized[:n, lips]
    return np.linalg.norm(d, axis=-1)


@dataclass
class SegmentError:
    """Mean lip error (mm) over one phone segment of one utterance."""

    utterance: str
    label: str
    start: float
    end: float
    error: float


def segment_errors(phones: Sequence[PhoneSegment], times: np.ndarray, error: np.ndarray,
                   utterance: str = "") -> list[SegmentError]:
    """Mean of a per-frame error ``(T,)`` or ``(T, k)`` (averaged over columns) per phone segment;
    segments with no finite frame are left out."""
    e = np.asarray(error, dtype=np.float64)
    if e.ndim == 2:                 # the mean of each frame's finite columns (NaN: none)
        finite = np.isfinite(e)
        count = finite.sum(axis=1)
        e = np.where(count > 0, np.where(finite, e, 0.0).sum(axis=1) / np.maximum(count, 1), np.nan)
    seg = segment_index(phones, times[: len(e)])
    out = []
    for i, s in enumerate(phones):
        vals = e[seg == i]
        vals = vals[np.isfinite(vals)]
        if vals.size:
            out.append(SegmentError(utterance, s.label, s.start, s.end, float(vals.mean())))
    return out


def worst_segments(errors: Sequence[SegmentError], count: int = 5,
                   exclude: Sequence[str] = SILENT_LABELS) -> list[SegmentError]:
    """The ``count`` segments with the largest mean error (silences left out by default: ``sil``,
    ``sp``, ``pau``, ... in any case, as HPRC's ``SIL`` and ``sp``).

    Examples
    --------
    >>> segs = [SegmentError("u", "m", 0, 1, 2.0), SegmentError("u", "sil", 1, 2, 9.0),
    ...         SegmentError("u", "aa", 2, 3, 3.0), SegmentError("u", "SP", 3, 4, 9.4)]
    >>> [s.label for s in worst_segments(segs, 2)]
    ['aa', 'm']
    """
    left_out = {e.lower() for e in exclude}
    keep = [s for s in errors if s.label.lower() not in left_out]
    return sorted(keep, key=lambda s: -s.error)[:count]


#: the fewest pooled frames a phone's correlation is given for: over fewer (a held closure of 14
#: frames, a short vowel) the lips hardly move and r says nothing (an /m/ ranked worst by r -0.13
#: though its lips were within 0.7 mm); its RMS error in mm means something at any length
MIN_CORRELATION_FRAMES = 30


@dataclass
class PhoneError:
    """RMS error and correlation of one phone, pooled over every frame labelled with it.

    ``rms`` is the root mean square lip error (mm, both lip markers): what the phones are ranked
    by. ``correlation`` is the mean of the upper-lip-y and lower-lip-y Pearson correlations over
    the pooled frames, NaN when there are fewer than ``MIN_CORRELATION_FRAMES`` of them.
    """

    phone: str
    correlation: float
    rms: float
    frames: int
    segments: int


@dataclass
class UtteranceError:
    """Errors of one utterance: the Table 2 correlations on speech frames, the RMS lip error on
    speech frames (mm), its worst segment (time = segment centre), and on the same frames the
    synthesized closures' precision and recall against the talker's closed lips (NaN until the
    talker's closed value is known over the utterances analysed, :func:`error_report`)."""

    utterance: str
    split: str
    whole_face: float
    lower_lip: float
    upper_lip: float
    rms: float
    worst_label: str
    worst_time: float
    worst_error: float
    closure_precision: float = float("nan")
    closure_recall: float = float("nan")


@dataclass
class UtteranceAnalysis:
    """Everything the error views need about one utterance."""

    summary: UtteranceError
    times: np.ndarray
    lip_error: np.ndarray           # (T, 2)
    segments: list[SegmentError]
    frame_phone: list[str]          # label of each frame
    lips_y: np.ndarray              # (T, 2, 2): [frame, (original, synthesized), (upper, lower)]
    lips: TalkerLips | None = None  # the original and synthesized apertures on speech frames


def analyse_utterance(model: Model, utt: Utterance, split: str = "test",
                      config: SynthConfig | None = None, eval_config: EvalConfig | None = None,
                      synthesis: Synthesis | None = None) -> UtteranceAnalysis:
    """Synthesize ``utt`` (or use ``synthesis``) and measure its errors against the original."""
    if utt.markers is None:
        raise ValueError(f"{utt.name}: no original markers to compare with")
    config = config or SynthConfig()
    res = synthesis or synthesize(model, utt.audio, utt.sample_rate, utt.phones, config,
                                  n_frames=utt.n_frames, source=utt.name)
    orig = model.normalise_markers(utt.markers)
    n = min(len(orig), len(res.markers))
    orig, syn, times = orig[:n], res.markers[:n], res.times[:n]
    mask = speech_mask(utt.audio, utt.sample_rate, times, eval_config)
    corr = trajectory_correlations(orig, syn, mask, model, eval_config)
    err = lip_error(model, orig, syn)
    sp = err[mask]
    sp = sp[np.isfinite(sp).all(axis=1)]
    rms = float(np.sqrt(np.mean(sp**2))) if sp.size else float("nan")
    segs = segment_errors(utt.phones, times, err, utt.name)
    worst = worst_segments(segs, 1)
    w = worst[0] if worst else SegmentError(utt.name, "", 0.0, 0.0, float("nan"))
    idx = segment_index(utt.phones, times)
    labels = [utt.phones[i].label for i in idx]
    y = 1
    lips_y = np.stack([orig[:, [model.upper_lip, model.lower_lip], y],
                       syn[:, [model.upper_lip, model.lower_lip], y]], axis=1)
    summary = UtteranceError(utt.name, split, corr["whole_face"], corr["lower_lip"],
                             corr["upper_lip"], rms, w.label, 0.5 * (w.start + w.end), w.error)
    lips = talker_lips(orig, times, utt.phones, mask, model.upper_lip, model.lower_lip)
    lips.add(syn)
    return UtteranceAnalysis(summary, times, err, segs, labels, lips_y, lips)


@dataclass
class ErrorReport:
    """Per-phone and per-utterance errors over a set of utterances, the worst segments, and the
    closures against the talker's lips (``talker``: its closed value; ``closures``: pooled)."""

    phones: list[PhoneError] = field(default_factory=list)
    utterances: list[UtteranceError] = field(default_factory=list)
    worst: list[SegmentError] = field(default_factory=list)
    talker: TalkerClosed | None = None
    closures: ClosureAgreement | None = None


def judge_closures(analyses: Sequence[UtteranceAnalysis]) -> tuple[TalkerClosed, ClosureAgreement]:
    """The talker's closed value over ``analyses`` (each with its lips), each utterance's
    closure precision and recall set on its summary, and the pooled agreement."""
    parts = [a.lips for a in analyses if a.lips is not None]
    talker = talker_closed(parts)
    counts = [c[0] for c in agreements(parts, talker)]
    for a, c in zip([a for a in analyses if a.lips is not None], counts, strict=True):
        a.summary.closure_precision, a.summary.closure_recall = c.precision, c.recall
    return talker, ClosureAgreement.pooled(counts)


def phone_errors(analyses: Sequence[UtteranceAnalysis],
                 min_frames: int = MIN_CORRELATION_FRAMES) -> list[PhoneError]:
    """Pool the frames of every phone over ``analyses`` and score each phone, worst (the largest
    RMS lip error in mm) first; a correlation only for phones of at least ``min_frames``
    frames (else NaN)."""
    pooled: dict[str, list[np.ndarray]] = {}
    errs: dict[str, list[np.ndarray]] = {}
    nseg: dict[str, int] = {}
    for a in analyses:
        lab = np.array(a.frame_phone)
        for p in np.unique(lab):
            sel = lab == p
            pooled.setdefault(p, []).append(a.lips_y[sel])
            errs.setdefault(p, []).append(a.lip_error[sel])
        for s in a.segments:
            nseg[s.label] = nseg.get(s.label, 0) + 1
    out = []
    for p in pooled:
        y = np.concatenate(pooled[p])
        ok = np.isfinite(y).all(axis=(1, 2))
        y = y[ok]
        r = [pearson(y[:, 0, j], y[:, 1, j]) for j in range(2)] if len(y) >= max(min_frames, 3) else []
        r = [x for x in r if np.isfinite(x)]
        e = np.concatenate(errs[p])
        e = e[np.isfinite(e).all(axis=1)]
        out.append(PhoneError(p, float(np.mean(r)) if r else float("nan"),
                              float(np.sqrt(np.mean(e**2))) if e.size else float("nan"),
                              int(ok.sum()), nseg.get(p, 0)))
    out.sort(key=lambda x: (-np.nan_to_num(x.rms, nan=-np.inf), x.phone))
    return out


def error_report(model: Model, corpus: Corpus, splits: Sequence[str] = ("test",),
                 config: SynthConfig | None = None, eval_config: EvalConfig | None = None,
                 worst_count: int = 20, progress: Progress | None = None) -> ErrorReport:
    """Synthesize every utterance of ``splits`` and collect per-phone and per-utterance errors."""
    ids = [(sp, u) for sp in splits for u in getattr(corpus.info, sp)]
    analyses = []
    for k, (sp, u) in enumerate(ids):
        if progress:
            progress(k / max(len(ids), 1), f"{sp}: {u}")
        analyses.append(analyse_utterance(model, corpus.utterance(u), sp, config, eval_config))
    if progress:
        progress(1.0, "done")
    segs = [s for a in analyses for s in a.segments]
    talker, closures = judge_closures(analyses)
    return ErrorReport(phone_errors(analyses), [a.summary for a in analyses],
                       worst_segments(segs, worst_count), talker, closures)


def write_error_csv(path: str | os.PathLike[str], report: ErrorReport, overwrite: bool = True) -> Path:
    """Write the per-utterance errors as CSV."""
    return write_csv(path, ["utterance", "split", "whole_face", "lower_lip", "upper_lip", "rms_mm",
                            "worst_phone", "worst_time", "worst_error_mm", "closure_precision",
                            "closure_recall"],
                     ([u.utterance, u.split, u.whole_face, u.lower_lip, u.upper_lip, u.rms,
                       u.worst_label, u.worst_time, u.worst_error, u.closure_precision,
                       u.closure_recall] for u in report.utterances),
                     overwrite)


__all__ = ["MIN_CORRELATION_FRAMES", "ErrorReport", "PhoneError", "SegmentError", "UtteranceAnalysis",
           "UtteranceError", "analyse_utterance", "error_report", "judge_closures", "lip_error",
           "phone_errors", "segment_errors", "worst_segments", "write_error_csv"]
