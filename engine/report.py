"""The results report (issue 7): the paper's Table 1, Table 2, Figure 5 and a Figure-4-style plot
reproduced on a corpus's train/test split, the acoustic-only mode and two baselines on the same
split, the paper's numbers beside ours and a discussion of the differences.

Pure engine: no plotting here. :func:`write_report` computes everything (:func:`compute_report`),
calls an optional ``figures`` callable to draw the figures (``app.report_figures`` does it with
matplotlib) and writes ``results.md`` and ``results.json``.
"""

from __future__ import annotations

import datetime as dt
import itertools
import json
import logging
import math
import os
import re
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import __version__
from .baselines import FrameData, evaluate_baselines, fit_baselines, frame_data
from .config import SynthConfig
from .corpus import Corpus, load_corpus
from .data import PhoneSegment
from .evaluation import (
    METRICS,
    EvalResult,
    UtteranceScore,
    evaluate,
    moving_coordinates,
    speech_mask,
    sweep_n,
    table2,
    trajectory_correlations,
)
from .formats import atomic_write
from .label_eval import LABEL_EVAL_FILE, LabelEval, format_markdown, read_label_eval
from .model import Model
from .pipeline import resmooth, synthesize
from .progress import Progress
from .similarity import SimilarRow, top_similar
from .training import train

log = logging.getLogger(__name__)


#: the sentence of the paper's Figure 4
FIGURE4_TEXT = "Tornadoes often destroy acres of farm land"

#: the paper's Table 2: (split, smoothing) -> (whole face, lower lip, upper lip), N = 3
PAPER_TABLE2: dict[tuple[str, str], tuple[float, float, float]] = {
    ("train", "triangular"): (0.9239, 0.9463, 0.9287),
    ("train", "spline"): (0.9145, 0.9388, 0.9126),
    ("test", "triangular"): (0.7338, 0.8468, 0.7230),
    ("test", "spline"): (0.6969, 0.7721, 0.7060),
}

#: the paper's Table 1 (top three visually most similar phonemes and their similarity)
PAPER_TABLE1_TEXT = """
aa aw 0.86 hh 0.71 eh 0.70|ae ay 0.94 ey 0.46 aa 0.26|ah dh 0.83 y 0.77 ih 0.75
ao ow 0.62 r 0.24 ah 0.20|aw aa 0.86 hh 0.64 eh 0.64|ax t 0.78 el 0.76 d 0.69
axr uw 0.81 uh 0.72 el 0.69|ay ae 0.94 ey 0.47 aa 0.26|b p 0.78 m 0.58 uw 0.49
ch zh 0.77 sh 0.74 z 0.61|d t 0.88 ih 0.81 dh 0.73|dh ih 0.84 ah 0.83 d 0.73
eh hh 0.94 ey 0.84 aa 0.70|el r 0.81 ax 0.76 uh 0.73|en t 0.75 jh 0.71 ax 0.68
ey eh 0.84 hh 0.77 aa 0.57|f v 0.68 m 0.23 axr 0.18|g l 0.86 iy 0.67 k 0.57
hh eh 0.94 ey 0.77 aa 0.71|ih n 0.92 dh 0.84 d 0.81|iy n 0.83 ng 0.76 l 0.75
jh sh 0.77 en 0.71 z 0.68|k iy 0.70 l 0.60 g 0.57|l g 0.86 iy 0.75 ng 0.62
m p 0.81 b 0.58 uw 0.26|n ih 0.92 ng 0.84 iy 0.83|ng n 0.84 ih 0.77 iy 0.76
ow r 0.65 ao 0.62 el 0.43|p m 0.81 b 0.78 uw 0.46|r el 0.81 uh 0.67 ax 0.67
s z 0.93 sh 0.88 jh 0.60|sh z 0.89 s 0.88 jh 0.77|t d 0.88 ax 0.78 en 0.75
th dh 0.68 ah 0.65 ax 0.59|uh uw 0.76 el 0.73 axr 0.72|uw axr 0.81 uh 0.76 el 0.59
v f 0.68 axr 0.20 m 0.14|w ao 0.12 ow 0.07 r 0.02|y ah 0.77 ih 0.73 n 0.72
z s 0.93 sh 0.89 jh 0.68|zh ch 0.77 sh 0.64 z 0.56
"""


def paper_table1() -> dict[str, list[tuple[str, float]]]:
    """The paper's Table 1 as ``phone -> [(neighbour, similarity)] * 3``."""
    out = {}
    for entry in PAPER_TABLE1_TEXT.replace("\n", "|").split("|"):
        parts = entry.split()
        if parts:
            out[parts[0]] = [(parts[i], float(parts[i + 1])) for i in (1, 3, 5)]
    return out


# ---------------------------------------------------------------------- the data
@dataclass
class Figure4Data:
    """A Figure-4-style example: waveform, upper and lower lip y, original vs the two smoothings.

    Attributes
    ----------
    utterance, text, split : which utterance (``found`` False when the paper's sentence is not in
        the corpus and another test utterance stands in).
    audio, sample_rate : the speech signal (top plot).
    times : ``(T,)`` marker frame times.
    upper_lip, lower_lip : ``{"original", "triangular", "spline"} -> (T,)`` y coordinates (mm,
        head-normalised).
    speech : ``(T,)`` the speech/silence detection (the dotted line of the paper's figure).
    phones : the phone labels (for annotation).
    correlations : ``smoothing -> {whole_face, lower_lip, upper_lip}`` on speech frames.
    """

    utterance: str
    text: str
    split: str
    found: bool
    audio: np.ndarray
    sample_rate: int
    times: np.ndarray
    upper_lip: dict[str, np.ndarray]
    lower_lip: dict[str, np.ndarray]
    speech: np.ndarray
    phones: list[PhoneSegment]
    correlations: dict[str, dict[str, float]]


@dataclass
class ReportData:
    """Everything in the report.

    Attributes
    ----------
    corpus : corpus folder and summary (name, utterances and minutes per split).
    model : model summary (PCs, variance explained, codewords, context-phones, phones, training time).
    table1 : our top-3 similar phones; ``paper_table1`` the paper's.
    table2 : rows ``{split, smoothing, whole_face, lower_lip, upper_lip}`` (phonetic, N = 3).
    comparisons : rows ``{method, split, smoothing, whole_face, lower_lip, upper_lip, *_std, n}``.
    sweep : ``{"ns": [...], "train": {metric: [...]}, "test": {metric: [...]}}`` (triangular).
    figure4 : the Figure-4 example (``None`` when the corpus has no test utterance).
    figures : figure name -> path relative to the report folder (filled by the figures callable).
    timings : seconds per stage.
    labels : the evaluation with automatic labels (``engine.label_eval``), when one was saved.
    """

    corpus: dict
    model: dict
    table1: list[SimilarRow]
    paper_table1: dict[str, list[tuple[str, float]]]
    table2: list[dict]
    comparisons: list[dict]
    sweep: dict
    figure4: Figure4Data | None
    timings: dict[str, float] = field(default_factory=dict)
    figures: dict[str, str] = field(default_factory=dict)
    created: str = ""
    labels: LabelEval | None = None

    def row(self, mode: str, split: str = "test", smoothing: str = "triangular") -> dict | None:
        """The comparison row of one mode (``phonetic``, ``acoustic``, ``acoustic-indexed``,
        ``viseme``, ``ridge``), split and smoothing."""
        for r in self.comparisons:
            if r["mode"] == mode and r["split"] == split and r["smoothing"] == smoothing:
                return r
        return None

    def to_json(self) -> dict:
        """All numbers of the report (arrays of the Figure-4 example left out)."""
        fig4 = None
        if self.figure4 is not None:
            f = self.figure4
            fig4 = {"utterance": f.utterance, "text": f.text, "split": f.split, "found": f.found,
                    "duration_s": len(f.audio) / f.sample_rate,
                    "speech_frames": int(f.speech.sum()), "correlations": f.correlations}
        return _finite({
            "created": self.created, "facetraj": __version__, "corpus": self.corpus,
            "model": self.model,
            "table1": [{"phone": r.phone, "neighbours": [list(n) for n in r.neighbours]}
                       for r in self.table1],
            "table2": self.table2,
            "paper_table2": [{"split": sp, "smoothing": sm, **dict(zip(METRICS, v, strict=True))}
                             for (sp, sm), v in PAPER_TABLE2.items()],
            "comparisons": self.comparisons, "sweep": self.sweep, "figure4": fig4,
            "table1_agreement": table1_agreement(self.table1, self.paper_table1),
            "at_a_glance": at_a_glance(self),
            "timings_s": self.timings, "figures": self.figures,
            "automatic_labels": self.labels.to_json()["summary"] if self.labels else None,
        })


def _finite(obj):
    """NaN and inf to ``None`` (valid JSON)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite(v) for v in obj]
    if isinstance(obj, np.generic):
        return _finite(obj.item())
    return obj


FigureMaker = Callable[[ReportData, Path], dict[str, Path]]
"""Draws the report's figures into a folder; returns figure name -> file."""


# ---------------------------------------------------------------------- computing
def _norm_text(text: str) -> str:
    return " ".join(re.sub(r"[^a-z ]+", " ", text.lower()).split())


def find_utterance(corpus: Corpus, text: str = FIGURE4_TEXT) -> tuple[str, str] | None:
    """``(id, split)`` of the utterance whose ``<id>.txt`` holds ``text`` (test split first)."""
    target = _norm_text(text)
    for split in ("test", "train"):
        for utt_id in getattr(corpus.info, split):
            p = corpus.root / f"{utt_id}.txt"
            if p.exists() and target in _norm_text(p.read_text(encoding="utf-8", errors="replace")):
                return utt_id, split
    return None


def summarise(scores: Iterable[UtteranceScore], method: str | None = None) -> list[dict]:
    """Mean, std and count per (mode, N, split, smoothing) of the three metrics."""
    groups: dict[tuple, list[UtteranceScore]] = {}
    for s in scores:
        groups.setdefault((s.mode, s.n_context_phones, s.split, s.smoothing), []).append(s)
    rows = []
    for (mode, n, split, sm), rs in groups.items():
        row: dict = {"method": method or mode, "mode": mode, "n_context_phones": n, "split": split,
                     "smoothing": sm, "n": len(rs)}
        for m in METRICS:
            v = np.array([getattr(r, m) for r in rs], dtype=float)
            v = v[np.isfinite(v)]
            row[m] = float(v.mean()) if v.size else float("nan")
            row[f"{m}_std"] = float(v.std(ddof=1)) if v.size > 1 else float("nan")
        rows.append(row)
    return rows


def table1_agreement(ours: Sequence[SimilarRow], paper: dict[str, list[tuple[str, float]]]) -> dict:
    """How our Table 1 agrees with the paper's on the phones both have."""
    common = [r for r in ours if r.phone in paper]
    top1 = sum(r.neighbours[0][0] == paper[r.phone][0][0] for r in common if r.neighbours)
    overlap = [len({n for n, _ in r.neighbours[:3]} & {n for n, _ in paper[r.phone]}) for r in common]
    return {"phones_compared": len(common), "same_closest": int(top1),
            "mean_top3_overlap": float(np.mean(overlap)) if overlap else float("nan")}


def figure4_data(model: Model, corpus: Corpus, text: str = FIGURE4_TEXT) -> Figure4Data | None:
    """Synthesize the paper's Figure 4 sentence (or the first test utterance) and collect the lip
    y trajectories, original vs triangular vs spline, and the speech/silence detection."""
    hit = find_utterance(corpus, text)
    found = hit is not None
    if hit is None:
        ids = corpus.info.test or corpus.info.train
        if not ids:
            return None
        hit = (ids[0], "test" if corpus.info.test else "train")
        log.warning("no utterance says %r; Figure 4 shows %s instead", text, hit[0])
    utt = corpus.utterance(hit[0])
    res = synthesize(model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(), n_frames=utt.n_frames,
                     source=utt.name)
    original = model.normalise_markers(utt.markers)
    synth = {"triangular": resmooth(model, res, "triangular"), "spline": resmooth(model, res, "spline")}
    mask = speech_mask(utt.audio, utt.sample_rate, res.times)
    y = 1
    ul, ll = model.upper_lip, model.lower_lip
    return Figure4Data(
        utterance=utt.name, text=utt.text, split=hit[1], found=found, audio=utt.audio,
        sample_rate=utt.sample_rate, times=res.times,
        upper_lip={"original": original[:, ul, y], **{k: v[:, ul, y] for k, v in synth.items()}},
        lower_lip={"original": original[:, ll, y], **{k: v[:, ll, y] for k, v in synth.items()}},
        speech=mask, phones=list(utt.phones),
        correlations={k: trajectory_correlations(original, v, mask, model) for k, v in synth.items()})


def _stage(progress: Progress, lo: float, hi: float) -> Progress:
    def inner(fraction: float, message: str) -> None:
        progress(lo + (hi - lo) * fraction, message)
    return inner


def compute_report(corpus_dir: str | os.PathLike[str], model: Model | None = None,
                   progress: Progress | None = None, ns: Iterable[int] = range(1, 11)) -> ReportData:
    """Compute every number of the report on the corpus's own train/test split.

    Trains a model on the train split when ``model`` is ``None``.
    """
    progress = progress or (lambda f, m: None)
    corpus = load_corpus(corpus_dir)
    info = corpus.info
    ns = list(ns)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    if model is None:
        model = train(corpus, progress=_stage(progress, 0.0, 0.1))
        timings["train"] = time.perf_counter() - t0
    # Table 1 (eqs 1-3)
    rows1 = top_similar(model.similarity(), model.phones, 3)
    # Table 2 and acoustic-only (N = 3, triangular and spline)
    t = time.perf_counter()
    res2 = table2(model, corpus, acoustic=True, progress=_stage(progress, 0.1, 0.45))
    timings["table2_and_acoustic"] = time.perf_counter() - t
    # acoustic-only with the default (indexed) search, as the app and `facetraj synth` run it
    t = time.perf_counter()
    indexed = SynthConfig(mode="acoustic")
    res_ix = evaluate(model, corpus, ("train", "test"), [indexed], ("triangular", "spline"),
                      progress=_stage(progress, 0.45, 0.47))
    timings["acoustic_indexed"] = time.perf_counter() - t
    # Figure 5
    t = time.perf_counter()
    res5 = sweep_n(model, corpus, ns, progress=_stage(progress, 0.47, 0.8))
    timings["sweep_n"] = time.perf_counter() - t
    # baselines
    t = time.perf_counter()
    frames: dict[str, list[FrameData]] = {"train": [], "test": []}
    ids = [(sp, u) for sp in ("train", "test") for u in getattr(info, sp)]
    for k, (sp, utt_id) in enumerate(ids):
        progress(0.8 + 0.15 * k / max(len(ids), 1), f"baselines: {utt_id}")
        frames[sp].append(frame_data(model, corpus.utterance(utt_id)))
    base = fit_baselines(model, frames["train"])
    base_scores = evaluate_baselines(model, base, frames)
    timings["baselines"] = time.perf_counter() - t
    # Figure 4
    t = time.perf_counter()
    progress(0.96, "Figure 4")
    fig4 = figure4_data(model, corpus)
    timings["figure4"] = time.perf_counter() - t

    comparisons = []
    for r in summarise(res2.scores):
        r["method"] = "phonetic (N = 3)" if r["mode"] == "phonetic" else "acoustic-only"
        comparisons.append(r)
    for r in summarise(res_ix.scores):
        r["mode"] = "acoustic-indexed"
        r["method"] = (f"acoustic-only, indexed (K = {indexed.acoustic_prefilter} nearest, "
                       f"the default search)")
        comparisons.append(r)
    names = {"viseme": "viseme lookup (labels, no acoustics)",
             "ridge": f"ridge regression (LSFs of frames t-{base.context}..t+{base.context})"}
    for r in summarise(base_scores):
        r["method"] = names[r["mode"]]
        comparisons.append(r)
    t2 = [{k: r[k] for k in ("split", "smoothing", *METRICS, *(f"{m}_std" for m in METRICS), "n")}
          for r in comparisons if r["mode"] == "phonetic"]
    sweep = sweep_table(res5, ns)
    durations = {sp: _minutes(corpus, getattr(info, sp)) for sp in ("train", "test")}
    cb = model.codebook
    summary = {
        "root": str(corpus.root), "name": info.name, "n_markers": len(info.marker_names),
        "marker_rate": info.marker_rate, "n_train": len(info.train), "n_test": len(info.test),
        "train_minutes": durations["train"], "test_minutes": durations["test"],
    }
    model_summary = {
        "n_pcs": model.pca.n_components,
        "variance_explained": float(model.pca.explained_ratio.sum()),
        "n_codewords": int(cb.lsf.shape[0]), "n_context_phones": cb.n_contexts,
        "n_phones": len(model.phones), "phones": model.phones,
        "moving_coordinates": int(len(moving_coordinates(model))),
        "config": model.config.to_dict(), "ridge_lambda": base.ridge.lam,
    }
    progress(1.0, "done")
    return ReportData(corpus=summary, model=model_summary, table1=rows1, paper_table1=paper_table1(),
                      table2=t2, comparisons=comparisons, sweep=sweep, figure4=fig4, timings=timings,
                      created=f"{dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC")


def _minutes(corpus: Corpus, ids: Sequence[str]) -> float:
    """Total audio minutes of utterances (from the file headers when soundfile can, else loaded)."""
    total = 0.0
    for utt_id in ids:
        try:
            import soundfile

            from .corpus import audio_path

            total += soundfile.info(str(audio_path(corpus.root, utt_id))).duration
        except Exception:  # any reader problem: load it the normal way
            total += corpus.utterance(utt_id).duration
    return total / 60.0


def sweep_table(result: EvalResult, ns: Sequence[int]) -> dict:
    """Figure 5 numbers: per split and metric, the mean correlation for each N (triangular)."""
    out: dict = {"ns": list(ns)}
    for split in ("train", "test"):
        out[split] = {m: [result.mean(split, "triangular", "phonetic", n)[m] for n in ns] for m in METRICS}
    test = out["test"]["whole_face"]
    if test and np.isfinite(test).any():
        best = float(np.nanmax(test))
        out["test_levels_off_at"] = int(next(n for n, v in zip(ns, test, strict=True)
                                             if np.isfinite(v) and v >= best - 0.005))
        out["test_best_n"] = int(ns[int(np.nanargmax(test))])
    return out


# ---------------------------------------------------------------------- Markdown
def _f(v: float | None, digits: int = 4) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.{digits}f}"


def _pm(row: dict, m: str) -> str:
    sd = row.get(f"{m}_std", float("nan"))
    return _f(row[m]) + (f" ± {sd:.2f}" if sd is not None and math.isfinite(sd) else "")


def discussion(data: ReportData) -> list[str]:
    """The discussion paragraphs, from the numbers (so that they stay true when the data change)."""
    out = []
    c = data.corpus
    ours = {(r["split"], r["smoothing"]): r for r in data.table2}
    tr, te = ours.get(("train", "triangular")), ours.get(("test", "triangular"))
    trs, tes = ours.get(("train", "spline")), ours.get(("test", "spline"))
    paper_tr, paper_te = PAPER_TABLE2[("train", "triangular")], PAPER_TABLE2[("test", "triangular")]
    out.append(
        f"**The data are not the paper's.** The paper used about 10 minutes of training and 5 minutes "
        f"of test data from one real talker, 54 points tracked optically at 60 Hz. The default corpus "
        f"here ({c['n_train']} training utterances, {c['train_minutes']:.1f} min; {c['n_test']} test "
        f"utterances, {c['test_minutes']:.1f} min; {c['n_markers']} markers at {c['marker_rate']:g} Hz) "
        f"is synthetic: speech from the VocalTractLab articulatory synthesizer and a face rig driven "
        f"by the same articulatory tracks (jaw, lips), plus head motion, marker noise and dropouts "
        f"(`docs/corpus.md`). Its acoustics and face motion are therefore tied far more "
        f"deterministically than a real talker's, its rest posture in pauses is always the same "
        f"(the paper blames much of its error on variable silences), and its voice is a synthesizer's, "
        f"so neither the absolute correlations nor the similarity table can be expected to match.")
    if tr and te:
        gap_ours = tr["whole_face"] - te["whole_face"]
        gap_paper = paper_tr[0] - paper_te[0]
        out.append(
            f"**Train vs test (Table 2).** Whole face, triangular: {_f(tr['whole_face'])} train and "
            f"{_f(te['whole_face'])} test here, 0.9239 and 0.7338 in the paper (a gap of "
            f"{gap_ours:.2f} vs {gap_paper:.2f}). Resynthesizing a training utterance finds its own "
            f"context-phones in the codebook, so the training figure is an upper limit in both. "
            + ("Our test figure is higher than the paper's, which the deterministic synthetic "
               "articulation and fixed rest posture explain: what the codebook saw in training "
               "predicts held-out sentences well. "
               if te["whole_face"] > paper_te[0] + 0.02 else
               "Our test figure is below the paper's. " if te["whole_face"] < paper_te[0] - 0.02 else
               "Our test figure is close to the paper's. ")
            + f"Lips on test: lower {_f(te['lower_lip'])} (paper 0.8468), upper {_f(te['upper_lip'])} "
              f"(paper 0.7230)"
            + ("; as in the paper, the lower lip, carried by the jaw, is predicted better than the "
               "upper lip." if te["lower_lip"] > te["upper_lip"] else
               "; unlike the paper, the upper lip is predicted at least as well as the lower lip. "
               "A likely reason is the synthetic rig: its upper lip follows one articulatory track, "
               "while its lower lip adds the jaw rotation and the lip opening, two sources the "
               "codebook must get right together.")
            + " The ± values are standard deviations over utterances: single sentences vary a lot, "
              "and short sentences with few speech frames give noisy correlations.")
    if tr and te and trs and tes:
        tri_better = (te["whole_face"] >= tes["whole_face"]) and (tr["whole_face"] >= trs["whole_face"])
        out.append(
            "**Triangular vs spline.** "
            + ("As in the paper, triangular smoothing scores above spline smoothing "
               f"(test whole face {_f(te['whole_face'])} vs {_f(tes['whole_face'])}). "
               if tri_better else
               "Unlike the paper, triangular smoothing does not score above spline smoothing "
               f"everywhere (test whole face {_f(te['whole_face'])} vs {_f(tes['whole_face'])}). ")
            + "The paper does not say how its spline was fitted; ours passes a cubic spline through "
              "box-averaged knots every 100 ms, which lags and flattens fast gestures (the delay the "
              "paper blames), so the size of this difference depends on that choice.")
    sw = data.sweep
    if sw.get("ns") and "test_levels_off_at" in sw:
        trw = sw["train"]["whole_face"]
        decreasing = all(b <= a + 1e-3 for a, b in itertools.pairwise(trw)) and trw[-1] < trw[0] - 0.005
        out.append(
            f"**N (Figure 5).** The paper's held-out curve levels off after N = 3. Ours reaches "
            f"within 0.005 of its best at N = {sw['test_levels_off_at']} (best at N = "
            f"{sw['test_best_n']}). "
            + ("As in the paper, the training curve falls as N grows: more context-phones dilute the "
               "exact training token. " if decreasing else
               f"Unlike the paper's, our training curve hardly falls ({trw[0]:.3f} at N = "
               f"{sw['ns'][0]}, {trw[-1]:.3f} at N = {sw['ns'][-1]}). The extra context-phones are "
               "tokens of the same phone in similar contexts, and in this synthetic corpus the face "
               "follows the phone sequence almost deterministically, so such tokens carry nearly the "
               "same face as the exact training token; diluting it costs little (the acoustic "
               "weights of eqs 5-6 also keep favouring the exact token, whose LSFs match the input). ")
            + (f"With only {c['n_test']} test sentences the curve is noisy at the 0.005 level."
               if c["n_test"] < 30 else
               "Our held-out curve keeps rising slowly beyond N = 3: the acoustic weights (eq 6) "
               "pick the best-matching codewords among the 5N candidates, so more candidates rarely "
               "hurt on this corpus, whose tokens of a phone vary little from one sentence to "
               "another."))
    ac, ix = data.row("acoustic"), data.row("acoustic-indexed")
    vis, rid = data.row("viseme"), data.row("ridge")
    if te and ac:
        out.append(
            f"**Acoustic-only.** Without labels (the whole codebook searched by eq 5) the test whole "
            f"face is {_f(ac['whole_face'])} against {_f(te['whole_face'])} with labels"
            + (": the phonetic restriction helps, as the paper expects (acoustically confusable "
               "phones such as /m/ and /n/ pick wrong faces). "
               if te["whole_face"] > ac["whole_face"] + 0.01 else
               ": the phonetic restriction makes little difference here (under 0.01), unlike the "
               "paper's expectation; the synthetic voice's spectra separate the phones, and their "
               "faces, well enough on their own. "
               if abs(te["whole_face"] - ac["whole_face"]) <= 0.01 else
               ": here the whole-codebook search is better than the restricted one, which suggests "
               "that N = 3 context-phones chosen by eq 4 often exclude the acoustically best "
               "codewords. ")
            + "The paper gives no number for this mode."
            + (f" The default indexed search (the {SynthConfig().acoustic_prefilter} codewords "
               f"nearest by eq 5, found in the model's LSF index) scores {_f(ix['whole_face'])} on "
               f"the same frames ({ix['whole_face'] - ac['whole_face']:+.4f}): "
               + ("leaving out the far codewords costs nothing measurable here."
                  if abs(ix["whole_face"] - ac["whole_face"]) <= 0.01 else
                  "slightly better, because leaving out the far codewords removes their small "
                  "pull towards the codebook's average face."
                  if ix["whole_face"] > ac["whole_face"] else
                  "the price of its speed (`docs/benchmarks.md`).") if ix else ""))
    if te and vis and rid:
        best = max(("the paper's method", te["whole_face"]), ("the viseme lookup", vis["whole_face"]),
                   ("the ridge regression", rid["whole_face"]), key=lambda x: x[1])
        out.append(
            f"**Baselines.** On the same test frames and smoothing, a viseme lookup (each frame gets "
            f"its phone's mean PC vector) scores {_f(vis['whole_face'])} and a ridge regression from "
            f"LSFs stacked over ±5 frames scores {_f(rid['whole_face'])}, against "
            f"{_f(te['whole_face'])} for the paper's method; {best[0]} is best. "
            + ("The codebook method beats both, so context-phones and acoustic weighting add "
               "something over labels alone and over a linear map. "
               if best[0] == "the paper's method" else
               "That a simpler method does as well or better is a warning against reading the "
               "absolute correlation as evidence for the codebook design on this corpus. ")
            + "The viseme lookup has no coarticulation and steps at phone boundaries (smoothed by the "
              "same 100 ms window); the ridge regression sees ±83 ms of acoustics but no labels.")
    agree = table1_agreement(data.table1, data.paper_table1)
    same = [r.phone + "-" + r.neighbours[0][0] for r in data.table1
            if r.neighbours and r.phone in data.paper_table1
            and r.neighbours[0][0] == data.paper_table1[r.phone][0][0]]
    out.append(
        f"**Table 1.** Only {agree['same_closest']} of {agree['phones_compared']} phones have the "
        f"paper's closest phone ({', '.join(same) or 'none'}); on average "
        f"{_f(agree['mean_top3_overlap'], 2)} of the three neighbours agree. The visual similarity "
        "is computed from face PCs, and the synthetic face moves only with the jaw and lips: "
        "phones that differ in the tongue (invisible in both the paper's data and ours) or in "
        "cheek and lip shape details of a real talker cannot be told apart the same way, and our "
        "similarities are lower overall because the largest distance sets the scale (eq 3). "
        "The lip-driven groups that the paper highlights (b, p, m; f, v; s, z, sh, zh; ch, jh) are "
        "the ones to compare.")
    out.append(
        "**Choices the paper leaves open** also move the numbers: which coordinates make up the "
        "\"whole face\" average (here the "
        f"{data.model['moving_coordinates']} head-normalised coordinates whose training standard "
        "deviation is at least 10 % of the largest; cheek, chin and nose points move little against "
        "the marker noise and pull the whole-face average down), the energy threshold of the "
        "speech/silence detector, the LSF analysis (order 18, 25 ms Hamming window, pre-emphasis "
        "0.97), and the scale of the distance before eq 3 (normalised by the largest distance; the "
        "paper does not say what its distances were measured in). See `docs/algorithm.md`.")
    return out


def at_a_glance(data: ReportData) -> list[dict]:
    """The paper's headline claims beside ours: ``{claim, paper, ours, same}`` rows (``same`` is
    ``None`` when ours cannot be computed)."""
    ours = {(r["split"], r["smoothing"]): r for r in data.table2}
    rows = []
    for label, split, metric, paper in (
            ("whole face, train (triangular)", "train", "whole_face", 0.9239),
            ("whole face, test (triangular)", "test", "whole_face", 0.7338),
            ("lower lip, test (triangular)", "test", "lower_lip", 0.8468),
            ("upper lip, test (triangular)", "test", "upper_lip", 0.7230)):
        r = ours.get((split, "triangular"))
        v = r[metric] if r else float("nan")
        rows.append({"claim": label, "paper": f"{paper:.2f}", "ours": _f(v, 2),
                     "same": None if not math.isfinite(v) else abs(v - paper) <= 0.05})
    sw = data.sweep
    if "test_levels_off_at" in sw:
        n = sw["test_levels_off_at"]
        rows.append({"claim": "held-out curve against N levels off at", "paper": "N = 3",
                     "ours": f"N = {n}", "same": n == 3})
        trw = sw["train"]["whole_face"]
        if len(trw) > 1 and math.isfinite(trw[0]) and math.isfinite(trw[-1]):
            rows.append({"claim": "training curve falls as N grows (by more than 0.005)", "paper": "yes",
                         "ours": f"{trw[0]:.3f} (N = {sw['ns'][0]}) -> {trw[-1]:.3f} (N = {sw['ns'][-1]})",
                         "same": trw[-1] < trw[0] - 0.005})
    tr, sp = ours.get(("test", "triangular")), ours.get(("test", "spline"))
    if tr and sp:
        better = all(tr[m] >= sp[m] for m in METRICS)
        rows.append({"claim": "triangular above spline (test, all three measures)", "paper": "yes",
                     "ours": "yes" if better else "no", "same": better})
    return rows


def render_markdown(data: ReportData) -> str:
    """``results.md`` from the report data."""
    c, m = data.corpus, data.model
    lines = [
        f"# Results: the paper's tables and figures on the `{Path(c['root']).name}` corpus",
        "",
        f"Written by `facetraj report` (facetraj {__version__}) on {data.created}. Corpus "
        f"`{Path(c['root']).name}/`: {c['n_train']} training utterances ({c['train_minutes']:.1f} min) "
        f"and {c['n_test']} test utterances ({c['test_minutes']:.1f} min), {c['n_markers']} markers at "
        f"{c['marker_rate']:g} Hz. Model: {m['n_pcs']} PCs ({100 * m['variance_explained']:.2f} % of "
        f"the variance), {m['n_context_phones']} context-phones, {m['n_codewords']} codewords, "
        f"{m['n_phones']} phones. All correlations are Pearson correlations between original and "
        f"synthesized head-normalised trajectories on speech frames only (section 3), averaged over "
        f"utterances (± one standard deviation over utterances). All numbers are in "
        f"[`results.json`](results.json).",
        "",
        "## At a glance",
        "",
        "| The paper's result | Paper | Ours | Reproduced |",
        "|---|---|---|---|",
        *[f"| {g['claim']} | {g['paper']} | {g['ours']} | "
          f"{'n/a' if g['same'] is None else ('yes' if g['same'] else 'no')} |" for g in at_a_glance(data)],
        "",
        "Numbers count as reproduced within ± 0.05. Why they differ: see the discussion at the end.",
        "",
        "## Table 2: correlation, original vs synthesized (N = 3)",
        "",
        "| Test condition | Whole face | Lower lip | Upper lip | Paper: whole | lower | upper |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in data.table2:
        p = PAPER_TABLE2.get((r["split"], r["smoothing"]), (float("nan"),) * 3)
        lines.append(f"| {r['split'].title()} ({r['smoothing']}) | {_pm(r, 'whole_face')} | "
                     f"{_pm(r, 'lower_lip')} | {_pm(r, 'upper_lip')} | {_f(p[0])} | {_f(p[1])} | "
                     f"{_f(p[2])} |")
    lines += ["", "## Figure 5: correlation against N", ""]
    if "figure5" in data.figures:
        lines += [f"![Figure 5]({data.figures['figure5']})", ""]
    sw = data.sweep
    lines += ["| N | " + " | ".join(str(n) for n in sw["ns"]) + " |",
              "|---|" + "---:|" * len(sw["ns"])]
    for split in ("train", "test"):
        for metric in METRICS:
            vals = sw[split][metric]
            lines.append(f"| {split} {metric.replace('_', ' ')} | "
                         + " | ".join(_f(v, 3) for v in vals) + " |")
    if "test_levels_off_at" in sw:
        lines += ["", f"Triangular smoothing. The test whole-face curve comes within 0.005 of its "
                      f"best at N = {sw['test_levels_off_at']} (best N = {sw['test_best_n']}); the "
                      f"paper's levels off after N = 3."]
    lines += ["", "## Figure 4: an example", ""]
    f4 = data.figure4
    if f4 is None:
        lines.append("The corpus has no utterance to show.")
    else:
        said = (f"\"{f4.text}\" ({f4.utterance}, {f4.split} split)" if f4.found else
                f"The paper's sentence \"{FIGURE4_TEXT}\" is not in the corpus; {f4.utterance} "
                f"({f4.split} split, \"{f4.text}\") stands in")
        lines += [f"{said}. Top: the speech signal. Middle and bottom: upper and lower lip centre "
                  f"y (mm, head-normalised): original (dotted), spline (dark) and triangular (light) "
                  f"synthesis, N = 3; dots along the middle mark the frames detected as speech.", ""]
        if "figure4" in data.figures:
            lines += [f"![Figure 4]({data.figures['figure4']})", ""]
        lines += ["| Smoothing | Whole face | Lower lip | Upper lip |", "|---|---:|---:|---:|"]
        for sm, cor in f4.correlations.items():
            lines.append(f"| {sm} | {_f(cor['whole_face'])} | {_f(cor['lower_lip'])} | "
                         f"{_f(cor['upper_lip'])} |")
    lines += ["", "## Comparisons on the same split", "",
              "The paper's method with labels (phonetic, N = 3), without them (acoustic-only: eq 5 "
              "over the whole codebook, as the paper; and the default indexed search), and two "
              "baselines fitted on the training split only (`engine/baselines.py`), all scored the "
              "same way.", ""]
    if "comparison" in data.figures:
        lines += [f"![Comparison]({data.figures['comparison']})", ""]
    lines += ["| Method | Split | Smoothing | Whole face | Lower lip | Upper lip | Utterances |",
              "|---|---|---|---:|---:|---:|---:|"]
    order = {"phonetic": 0, "acoustic": 1, "acoustic-indexed": 2, "viseme": 3, "ridge": 4}
    for r in sorted(data.comparisons, key=lambda r: (r["split"] != "test", r["smoothing"] != "triangular",
                                                     order.get(r["mode"], 9))):
        lines.append(f"| {r['method']} | {r['split']} | {r['smoothing']} | {_pm(r, 'whole_face')} | "
                     f"{_pm(r, 'lower_lip')} | {_pm(r, 'upper_lip')} | {r['n']} |")
    lines += ["", "## Table 1: the three visually most similar phones", ""]
    agree = table1_agreement(data.table1, data.paper_table1)
    lines += [f"Eqs 1-3 (nu = {m['config']['nu']:g}, distances scaled by "
              f"`{m['config']['distance_scale']}`). Of the {agree['phones_compared']} phones in both "
              f"tables, {agree['same_closest']} have the same closest phone as the paper; on average "
              f"{_f(agree['mean_top3_overlap'], 2)} of the three neighbours agree.", "",
              "| Phone | Closest | 2nd | 3rd | Paper: closest | 2nd | 3rd |",
              "|---|---|---|---|---|---|---|"]
    for r in data.table1:
        ours = [f"{p} {v:.2f}" for p, v in r.neighbours] + [""] * (3 - len(r.neighbours))
        paper = [f"{p} {v:.2f}" for p, v in data.paper_table1.get(r.phone, [])] or ["", "", ""]
        lines.append(f"| {r.phone} | " + " | ".join(ours + paper) + " |")
    if data.labels is not None:
        lines += ["", "## Beyond the paper: automatic labels on held-out sentences", "",
                  format_markdown(data.labels)]
    lines += ["", "## Discussion: where and why we differ from the paper", ""]
    for para in discussion(data):
        lines += [para, ""]
    tm = data.timings
    lines += ["## Reproducing", "",
              "```sh", "facetraj report data_samples -o docs     # or: make report", "```", "",
              "Run time: " + ", ".join(f"{k.replace('_', ' ')} {v:.0f} s" for k, v in tm.items()) + ".",
              ""]
    return "\n".join(lines)


def write_report(corpus_dir: str | os.PathLike[str], out_dir: str | os.PathLike[str],
                 model: Model | None = None, progress: Progress | None = None,
                 ns: Iterable[int] = range(1, 11), figures: FigureMaker | None = None) -> Path:
    """Compute the report on ``corpus_dir`` and write ``out_dir/results.md``, ``results.json`` and
    (through ``figures``, drawn into ``out_dir/figures/``) its figures. Returns the ``.md`` path.
    The evaluation with automatic labels is read from ``out_dir/label_eval.json`` (written by
    ``facetraj report --automatic-labels``, which takes about half an hour) when present.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    data = compute_report(corpus_dir, model, progress, ns)
    data.labels = read_label_eval(out / LABEL_EVAL_FILE)
    if figures is not None:
        fig_dir = out / "figures"
        fig_dir.mkdir(exist_ok=True)
        made = figures(data, fig_dir)
        data.figures = {k: Path(os.path.relpath(p, out)).as_posix() for k, p in made.items()}
    md = out / "results.md"
    with atomic_write(md) as tmp:
        tmp.write_text(render_markdown(data), encoding="utf-8")
    with atomic_write(out / "results.json") as tmp:
        tmp.write_text(json.dumps(data.to_json(), indent=1) + "\n", encoding="utf-8")
    for p in (md, out / "results.json"):
        p.chmod(0o644)  # atomic_write's temporary files are private
    log.info("report written to %s", md)
    return md


__all__ = ["FIGURE4_TEXT", "PAPER_TABLE2", "Figure4Data", "FigureMaker", "ReportData", "at_a_glance",
           "compute_report",
           "discussion", "find_utterance", "paper_table1", "render_markdown", "summarise", "sweep_table",
           "table1_agreement", "write_report"]
