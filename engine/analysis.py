"""Analysis of a model and of its synthesis errors, for the app's analysis views and reports.

* phone order by hierarchical clustering of the eq 2 distances (visemes group), the similarity
  matrix (eq 3) as CSV;
* Table 2 and the N sweep (Figure 5) as rows and CSV, from an :class:`~engine.evaluation.EvalResult`;
* per-frame lip error, per-phone correlation and RMS error, per-utterance errors, worst segments;
* the codebook inspector: everything eqs 4-8 did at one frame;
* principal component modes (Figure 2): displacement, standard deviations, which markers move.

Pure numpy/scipy; every number the app shows is computed here or in the other engine modules.
"""

from __future__ import annotations

import csv
import io
import logging
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.cluster import hierarchy
from scipy.spatial.distance import squareform

from .config import SynthConfig
from .corpus import Corpus
from .data import PhoneSegment, Utterance
from .evaluation import EvalConfig, EvalResult, pearson, speech_mask, trajectory_correlations
from .formats import atomic_write
from .model import Model
from .phones import SILENCE, segment_index
from .pipeline import Synthesis, synthesize
from .progress import Progress
from .selection import RobustFrames
from .synthesis import lsf_distances, perceptual_weights

log = logging.getLogger(__name__)



def _write_csv(path: str | os.PathLike[str], header: Sequence[str], rows: Iterable[Sequence],
               overwrite: bool = True) -> Path:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for r in rows:
        w.writerow([f"{x:.6g}" if isinstance(x, float) else x for x in r])
    path = Path(path)
    with atomic_write(path, overwrite) as tmp:
        tmp.write_text(buf.getvalue(), encoding="utf-8")
    return path


def subset_corpus(corpus: Corpus, per_split: int | None) -> Corpus:
    """The same corpus with only the first ``per_split`` utterances of each split (all when
    ``None`` or 0): a quick look at Table 2 or the N sweep before the full run."""
    if not per_split:
        return corpus
    info = replace(corpus.info, train=list(corpus.info.train[:per_split]),
                   test=list(corpus.info.test[:per_split]))
    return Corpus(corpus.root, info)


# ---------------------------------------------------------------------- similarity
@dataclass
class PhoneClustering:
    """Hierarchical clustering of the phones on the eq 2 distances.

    ``order`` indexes ``model.phones`` in dendrogram leaf order (phones without tokens, whose
    distances are NaN, come last); ``linkage`` is scipy's linkage matrix over ``clustered``
    (the indices that took part), ``labels`` the phone labels in ``order``.
    """

    order: list[int]
    labels: list[str]
    linkage: np.ndarray
    clustered: list[int]


def cluster_phones(model: Model, method: str = "average") -> PhoneClustering:
    """Order the phones by hierarchical clustering (``scipy.cluster.hierarchy``, optimal leaf
    ordering) of the model's eq 2 distance matrix, so that visually similar phones sit together.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> d = np.array([[0, 9, 1, 9], [9, 0, 9, 2], [1, 9, 0, 9], [9, 2, 9, 0]], dtype=float)
    >>> c = cluster_phones(SimpleNamespace(distances=d, phones=["a", "b", "c", "e"]))
    >>> sorted([sorted(c.labels[:2]), sorted(c.labels[2:])])
    [['a', 'c'], ['b', 'e']]
    """
    d = np.asarray(model.distances, dtype=np.float64)
    ok = [i for i in range(len(d)) if np.isfinite(d[i]).sum() > 1 or len(d) == 1]
    ok = [i for i in ok if np.isfinite(d[i, ok]).all()]
    rest = [i for i in range(len(d)) if i not in ok]
    if len(ok) >= 3:
        sub = d[np.ix_(ok, ok)]
        sub = 0.5 * (sub + sub.T)
        np.fill_diagonal(sub, 0.0)
        z = hierarchy.linkage(squareform(sub, checks=False), method=method)
        z = hierarchy.optimal_leaf_ordering(z, squareform(sub, checks=False))
        leaves = hierarchy.leaves_list(z)
        order = [ok[i] for i in leaves] + rest
    else:
        z = np.zeros((0, 4))
        order = ok + rest
    return PhoneClustering(order, [model.phones[i] for i in order], z, ok)


@dataclass
class Dendrogram:
    """Line segments of a dendrogram (scipy's ``icoord``/``dcoord``): leaf ``k`` of the order sits
    at x = 10 k + 5, heights are eq 2 distances."""

    icoord: list[list[float]]
    dcoord: list[list[float]]
    labels: list[str]


def dendrogram(clustering: PhoneClustering) -> Dendrogram:
    """The dendrogram's segments, leaves in ``clustering.order``."""
    if len(clustering.linkage) == 0:
        return Dendrogram([], [], clustering.labels)
    r = hierarchy.dendrogram(clustering.linkage, no_plot=True, count_sort=False,
                             distance_sort=False)
    return Dendrogram(r["icoord"], r["dcoord"], clustering.labels)


def similarity_in_order(model: Model, nu: float | None, order: Sequence[int]) -> np.ndarray:
    """The eq 3 matrix for ``nu`` with rows and columns in ``order``."""
    s = model.similarity(nu)
    idx = np.asarray(order)
    return s[np.ix_(idx, idx)]


def write_similarity_csv(path: str | os.PathLike[str], model: Model, nu: float | None = None,
                         order: Sequence[int] | None = None, overwrite: bool = True) -> Path:
    """Write the K x K similarity matrix (eq 3, ``nu`` default the model's) as CSV: a header row of
    phones, then one row per phone starting with its label."""
    order = list(range(len(model.phones))) if order is None else list(order)
    s = similarity_in_order(model, nu, order)
    labels = [model.phones[i] for i in order]
    return _write_csv(path, ["phone", *labels],
                      ([lab, *map(float, row)] for lab, row in zip(labels, s, strict=True)), overwrite)


# ---------------------------------------------------------------------- Table 2 and Figure 5
SMOOTHING_NAMES = {"triangular": "Triang.", "spline": "Spline", "none": "None"}


def condition_name(split: str, smoothing: str, mode: str = "phonetic", n: int | None = None) -> str:
    """A Table 2 row name, e.g. ``Train (Triang.)``; acoustic-only rows say so.

    Examples
    --------
    >>> condition_name("test", "spline", "acoustic")
    'Test (Spline, acoustic only)'
    """
    name = f"{split.title()} ({SMOOTHING_NAMES.get(smoothing, smoothing)}"
    if mode != "phonetic":
        name += ", acoustic only"
    if n is not None:
        name += f", N={n}"
    return name + ")"


@dataclass
class Table2Row:
    """One row of Table 2: condition and the three mean correlations."""

    name: str
    split: str
    mode: str
    smoothing: str
    n_context_phones: int
    whole_face: float
    lower_lip: float
    upper_lip: float
    utterances: int


def table2_rows(result: EvalResult) -> list[Table2Row]:
    """Table 2 rows, ordered as the paper (train before test, triangular before spline),
    phonetic rows before acoustic-only ones."""
    rows = []
    for r in result.table():
        count = sum(1 for s in result.scores if (s.split, s.mode, s.smoothing, s.n_context_phones)
                    == (r["split"], r["mode"], r["smoothing"], r["n_context_phones"]))
        rows.append(Table2Row(condition_name(r["split"], r["smoothing"], r["mode"]), r["split"],
                              r["mode"], r["smoothing"], r["n_context_phones"], r["whole_face"],
                              r["lower_lip"], r["upper_lip"], count))
    rank = {"train": 0, "test": 1}
    srank = {"triangular": 0, "spline": 1}
    rows.sort(key=lambda r: (r.mode != "phonetic", rank.get(r.split, 2), srank.get(r.smoothing, 2),
                             r.n_context_phones))
    return rows


def write_table2_csv(path: str | os.PathLike[str], result: EvalResult, overwrite: bool = True) -> Path:
    """Write Table 2 (plus acoustic-only rows) as CSV."""
    rows = table2_rows(result)
    return _write_csv(path, ["condition", "split", "mode", "smoothing", "N", "whole_face",
                             "lower_lip", "upper_lip", "utterances"],
                      ([r.name, r.split, r.mode, r.smoothing, r.n_context_phones, r.whole_face,
                        r.lower_lip, r.upper_lip, r.utterances] for r in rows), overwrite)


@dataclass
class SweepCurve:
    """Mean correlation against N for one split (Figure 5)."""

    split: str
    ns: np.ndarray
    whole_face: np.ndarray
    lower_lip: np.ndarray
    upper_lip: np.ndarray


def sweep_curves(result: EvalResult, smoothing: str = "triangular") -> list[SweepCurve]:
    """The N sweep per split from a :func:`~engine.evaluation.sweep_n` result."""
    out = []
    for split in ("train", "test"):
        ns = sorted({s.n_context_phones for s in result.scores
                     if s.split == split and s.smoothing == smoothing})
        if not ns:
            continue
        means = [result.mean(split, smoothing, "phonetic", n) for n in ns]
        out.append(SweepCurve(split, np.array(ns), *(np.array([m[k] for m in means])
                                                     for k in ("whole_face", "lower_lip", "upper_lip"))))
    return out


def write_sweep_csv(path: str | os.PathLike[str], result: EvalResult, overwrite: bool = True) -> Path:
    """Write the N sweep as CSV: split, N and the three mean correlations."""
    rows = [(c.split, int(n), float(w), float(lo), float(up)) for c in sweep_curves(result)
            for n, w, lo, up in zip(c.ns, c.whole_face, c.lower_lip, c.upper_lip, strict=True)]
    return _write_csv(path, ["split", "N", "whole_face", "lower_lip", "upper_lip"], rows, overwrite)


# ---------------------------------------------------------------------- errors
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
    if e.ndim == 2:
        e = np.nanmean(e, axis=1) if np.isfinite(e).any() else e[:, 0]
    seg = segment_index(phones, times[: len(e)])
    out = []
    for i, s in enumerate(phones):
        vals = e[seg == i]
        vals = vals[np.isfinite(vals)]
        if vals.size:
            out.append(SegmentError(utterance, s.label, s.start, s.end, float(vals.mean())))
    return out


def worst_segments(errors: Sequence[SegmentError], count: int = 5,
                   exclude: Sequence[str] = (SILENCE,)) -> list[SegmentError]:
    """The ``count`` segments with the largest mean error (silence left out by default).

    Examples
    --------
    >>> segs = [SegmentError("u", "m", 0, 1, 2.0), SegmentError("u", "sil", 1, 2, 9.0),
    ...         SegmentError("u", "aa", 2, 3, 3.0)]
    >>> [s.label for s in worst_segments(segs, 2)]
    ['aa', 'm']
    """
    keep = [s for s in errors if s.label not in exclude]
    return sorted(keep, key=lambda s: -s.error)[:count]


@dataclass
class PhoneError:
    """Correlation and RMS error of one phone, pooled over every frame labelled with it.

    ``correlation`` is the mean of the upper-lip-y and lower-lip-y Pearson correlations over the
    pooled frames; ``rms`` the root mean square lip error (mm, both lip markers).
    """

    phone: str
    correlation: float
    rms: float
    frames: int
    segments: int


@dataclass
class UtteranceError:
    """Errors of one utterance: the Table 2 correlations on speech frames, the RMS lip error on
    speech frames (mm), and its worst segment (time = segment centre)."""

    utterance: str
    split: str
    whole_face: float
    lower_lip: float
    upper_lip: float
    rms: float
    worst_label: str
    worst_time: float
    worst_error: float


@dataclass
class UtteranceAnalysis:
    """Everything the error views need about one utterance."""

    summary: UtteranceError
    times: np.ndarray
    lip_error: np.ndarray           # (T, 2)
    segments: list[SegmentError]
    frame_phone: list[str]          # label of each frame
    lips_y: np.ndarray              # (T, 2, 2): [frame, (original, synthesized), (upper, lower)]


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
    return UtteranceAnalysis(summary, times, err, segs, labels, lips_y)


@dataclass
class ErrorReport:
    """Per-phone and per-utterance errors over a set of utterances, and the worst segments."""

    phones: list[PhoneError] = field(default_factory=list)
    utterances: list[UtteranceError] = field(default_factory=list)
    worst: list[SegmentError] = field(default_factory=list)


def phone_errors(analyses: Sequence[UtteranceAnalysis]) -> list[PhoneError]:
    """Pool the frames of every phone over ``analyses`` and score each phone, worst
    (lowest correlation) first; phones with under 3 frames get NaN correlation."""
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
        r = [pearson(y[:, 0, j], y[:, 1, j]) for j in range(2)]
        r = [x for x in r if np.isfinite(x)]
        e = np.concatenate(errs[p])
        e = e[np.isfinite(e).all(axis=1)]
        out.append(PhoneError(p, float(np.mean(r)) if r else float("nan"),
                              float(np.sqrt(np.mean(e**2))) if e.size else float("nan"),
                              int(ok.sum()), nseg.get(p, 0)))
    out.sort(key=lambda x: (np.nan_to_num(x.correlation, nan=np.inf), x.phone))
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
    return ErrorReport(phone_errors(analyses), [a.summary for a in analyses],
                       worst_segments(segs, worst_count))


def write_error_csv(path: str | os.PathLike[str], report: ErrorReport, overwrite: bool = True) -> Path:
    """Write the per-utterance errors as CSV."""
    return _write_csv(path, ["utterance", "split", "whole_face", "lower_lip", "upper_lip", "rms_mm",
                             "worst_phone", "worst_time", "worst_error_mm"],
                      ([u.utterance, u.split, u.whole_face, u.lower_lip, u.upper_lip, u.rms,
                        u.worst_label, u.worst_time, u.worst_error] for u in report.utterances),
                      overwrite)


# ---------------------------------------------------------------------- codebook inspector
@dataclass
class CodewordRow:
    """One of the 5N candidate codewords of a frame."""

    index: int              # codebook codeword index i
    context_index: int      # its context-phone (codebook row)
    context: str            # the context-phone as text, e.g. "sil m [aa] t"
    position: int           # which of the 5 codewords of the phone (0-4)
    utterance: str          # training utterance it came from
    time: float             # its time in that utterance (s)
    distance: float         # d_i (eq 5)
    weight: float           # v_i (eq 6)
    target_cost: float = float("nan")   # robust mode: eq 5 with acoustic context (engine.selection)
    label_cost: float = float("nan")    # robust mode: kappa * confidence if eq 4 did not choose it
    from_labels: bool = True            # chosen by eq 4 (always, in phonetic mode)


@dataclass
class FrameInspection:
    """Why one synthesized frame looks as it does (eqs 4-8)."""

    frame: int
    time: float
    phone: str
    context: str
    chosen: list[tuple[str, float, int]]   # (context-phone text, n_j, codebook context index)
    codewords: list[CodewordRow]
    gamma: float
    lsf: np.ndarray          # w (P,)
    lsf_hat: np.ndarray      # w-hat (P,)
    error: float             # sum_k h_k |w_k - w-hat_k|
    audio_rate: float = 16000.0
    mode: str = "phonetic"
    confidence: float = float("nan")   # robust mode: the frame's label confidence

    @property
    def lsf_hz(self) -> np.ndarray:
        """w in Hz (LSFs are angles in radians at the analysis rate)."""
        return self.lsf * self.audio_rate / (2 * np.pi)

    @property
    def lsf_hat_hz(self) -> np.ndarray:
        """w-hat in Hz."""
        return self.lsf_hat * self.audio_rate / (2 * np.pi)

    @property
    def weight_sum(self) -> float:
        return float(sum(c.weight for c in self.codewords))


def context_text(model: Model, ids: Sequence[int]) -> str:
    """A context-phone as text with the centre bracketed: ``l3 l2 l1 [c] r1 r2 r3``."""
    labels = [model.phones[int(i)] for i in ids]
    c = len(labels) // 2
    labels[c] = f"[{labels[c]}]"
    return " ".join(labels)


def inspect_frame(model: Model, synthesis: Synthesis, frame: int, top: int | None = None) -> FrameInspection:
    """The eq 4-8 details of ``frame`` of ``synthesis``: the current phone and context-phone, the
    chosen context-phones with n_j, the candidate codewords with d_i and v_i (heaviest first;
    ``top`` limits them), gamma, and w against w-hat."""
    frame = int(np.clip(frame, 0, len(synthesis.times) - 1))
    fw = synthesis.frames
    cb = model.codebook
    phone, ctx_txt, chosen = "", "", []
    if synthesis.frame_segment is not None and synthesis.segments:
        sc = synthesis.segments[int(synthesis.frame_segment[frame])]
        phone = sc.segment.label
        ctx_txt = context_text(model, sc.context)
        chosen = [(context_text(model, cb.contexts[j]), float(s), int(j))
                  for j, s in zip(sc.chosen, sc.scores, strict=True)]
    cand = np.asarray(fw.candidates[frame])
    robust = isinstance(fw, RobustFrames)
    w = synthesis.lsf[frame]
    d = lsf_distances(w, cb.lsf[cand], perceptual_weights(w))
    v = fw.weights[frame]
    order = np.argsort(-v, kind="stable")
    if top is not None:
        order = order[:top]
    n = cb.n_per_phone
    rows = []
    if robust:
        order = np.array([i for i in order if np.isfinite(fw.acoustic_cost[frame, i])], dtype=int)
    for i in order:
        ci = int(cand[i])
        ctx = ci // n
        utt_k = int(cb.token_utt[ctx])
        utt = model.train_utterances[utt_k] if utt_k < len(model.train_utterances) else str(utt_k)
        pos = ci % n
        start, end = float(cb.token_start[ctx]), float(cb.token_end[ctx])
        extra = (float(fw.acoustic_cost[frame, i]), float(fw.label_cost[frame, i]),
                 bool(fw.from_labels[frame, i])) if robust else ()
        rows.append(CodewordRow(ci, ctx, context_text(model, cb.contexts[ctx]), pos, utt,
                                start + (pos + 0.5) * (end - start) / n, float(d[i]), float(v[i]),
                                *extra))
    return FrameInspection(frame, float(synthesis.times[frame]), phone, ctx_txt, chosen, rows,
                           float(fw.gamma[frame]), np.asarray(w), np.asarray(fw.lsf_hat[frame]),
                           float(fw.error[frame]), float(model.config.audio_rate),
                           synthesis.config.mode,
                           float(fw.confidence[frame]) if robust else float("nan"))


# ---------------------------------------------------------------------- PC modes (Figure 2)
def mode_sd(model: Model) -> np.ndarray:
    """Standard deviation of each PC's coefficient, ``(K,)`` (the slider spans +-3 of these)."""
    return np.sqrt(np.asarray(model.pca.variances, dtype=np.float64))


def variance_shares(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Share of the total variance of each PC and the cumulative share, both ``(K,)`` in %.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> m = SimpleNamespace(pca=SimpleNamespace(explained_ratio=np.array([0.5, 0.3, 0.1])))
    >>> [a.round(1).tolist() for a in variance_shares(m)]
    [[50.0, 30.0, 10.0], [50.0, 80.0, 90.0]]
    """
    share = 100.0 * np.asarray(model.pca.explained_ratio, dtype=np.float64)
    return share, np.cumsum(share)


def mode_displacement(model: Model, component: int, value: float) -> np.ndarray:
    """Displacement of every marker from the neutral face when PC ``component`` is ``value``:
    ``value`` times the eigenvector, ``(M, 3)`` mm."""
    return model.mode_shape(component, value) - model.neutral_face()


@dataclass
class ModeSummary:
    """How one PC moves the face."""

    component: int
    variance_share: float
    sd: float
    markers: list[tuple[str, float]]   # the markers it moves most, with their share of the motion
    axis: str                          # the dominant direction: "vertical", "lateral", "forward"

    def text(self) -> str:
        names = ", ".join(n for n, _ in self.markers)
        return (f"PC{self.component + 1}: {100 * self.variance_share:.1f} % of the variance, "
                f"mostly {self.axis} motion of {names}")


def describe_mode(model: Model, component: int, count: int = 4) -> ModeSummary:
    """Which markers PC ``component`` moves most and in which direction (x lateral, y vertical,
    z forward); PC1 of a talking face should be the jaw: chin and lower lip, vertical."""
    vec = np.asarray(model.pca.components[component]).reshape(-1, 3)
    mag = np.linalg.norm(vec, axis=1)
    share = mag**2 / max(float((mag**2).sum()), 1e-12)
    top = np.argsort(-mag)[:count]
    axis_energy = (vec**2).sum(axis=0)
    axis = ("lateral", "vertical", "forward")[int(np.argmax(axis_energy))]
    return ModeSummary(component, float(model.pca.explained_ratio[component]),
                       float(mode_sd(model)[component]),
                       [(model.marker_names[i], float(share[i])) for i in top], axis)
