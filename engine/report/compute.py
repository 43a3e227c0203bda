"""Computing the report (:func:`compute_report`): Table 1, Table 2 with the acoustic-only rows,
the indexed acoustic-only search, the N sweep, the baselines and the Figure-4 example, on a
corpus's own train/test split. One function per stage."""

from __future__ import annotations

import datetime as dt
import logging
import os
import re
import time
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from ..config import SynthConfig
from ..evaluation.baselines import Baselines, fit_and_score
from ..evaluation.paper import FIGURE4_TEXT, paper_table1
from ..evaluation.scores import (
    EvalResult,
    UtteranceScore,
    default_workers,
    evaluate,
    moving_coordinates,
    speech_mask,
    sweep_n,
    table2,
    trajectory_correlations,
)
from ..fanout import Skips
from ..io.corpus import Corpus, load_corpus
from ..method.model import Model
from ..method.pipeline import resmooth, synthesize
from ..method.similarity import top_similar
from ..method.training import train
from ..progress import Progress
from .data import Figure4Data, ReportData
from .rows import ComparisonRow, CorpusSummary, ModelSummary, summarise, sweep_table
from .sensors import sensor_section

log = logging.getLogger(__name__)


# ---------------------------------------------------------------------- Figure 4
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
    res = synthesize(model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(closure=False),
                     n_frames=utt.n_frames, source=utt.name)
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


# ---------------------------------------------------------------------- the stages
def _stage(progress: Progress, lo: float, hi: float) -> Progress:
    def inner(fraction: float, message: str) -> None:
        progress(lo + (hi - lo) * fraction, message)
    return inner


@contextmanager
def _timed(timings: dict[str, float], stage: str) -> Iterator[None]:
    """Time the ``with`` block into ``timings[stage]`` (seconds)."""
    t = time.perf_counter()
    yield
    timings[stage] = time.perf_counter() - t


def _baselines(model: Model, corpus: Corpus, progress: Progress, workers: int = 1
               ) -> tuple[Baselines, list[UtteranceScore]]:
    """The two baselines fitted on the training split and scored on both
    (:func:`facetraj_engine.evaluation.baselines.fit_and_score`)."""
    return fit_and_score(model, corpus, ("train", "test"), _stage(progress, 0.8, 0.95), workers)


def comparison_rows(paper_modes: EvalResult, indexed: EvalResult, indexed_config: SynthConfig,
                    baselines: Baselines, baseline_scores: Sequence[UtteranceScore]) -> list[ComparisonRow]:
    """The comparison rows, each method named: the paper's method with labels and without (the
    whole-codebook search), the indexed acoustic-only search, and the two baselines."""
    rows = []
    for r in summarise(paper_modes.scores):
        r.method = f"phonetic (N = {r.n_context_phones})" if r.mode == "phonetic" else "acoustic-only"
        rows.append(r)
    for r in summarise(indexed.scores):
        r.mode = "acoustic-indexed"
        r.method = (f"acoustic-only, indexed (K = {indexed_config.acoustic_prefilter} nearest, "
                    f"the default search)")
        rows.append(r)
    names = {"viseme": "viseme lookup (labels, no acoustics)",
             "ridge": f"ridge regression (LSFs of frames t-{baselines.context}..t+{baselines.context})"}
    for r in summarise(baseline_scores):
        r.method = names[r.mode]
        rows.append(r)
    return rows


def _minutes(corpus: Corpus, ids: Sequence[str]) -> float:
    """Total audio minutes of utterances (from the file headers when soundfile can, else loaded)."""
    total = 0.0
    for utt_id in ids:
        try:
            import soundfile

            from ..io.corpus import audio_path

            total += soundfile.info(str(audio_path(corpus.root, utt_id))).duration
        except Exception:  # any reader problem: load it the normal way
            total += corpus.utterance(utt_id).duration
    return total / 60.0


def corpus_summary(corpus: Corpus) -> CorpusSummary:
    """The corpus's folder, name, markers, utterances and minutes per split, and how its labels
    were made, phone by phone (:func:`facetraj_engine.io.label_census.label_census`)."""
    from ..io.label_census import label_census

    info = corpus.info
    return CorpusSummary(
        root=str(corpus.root), name=info.name, n_markers=len(info.marker_names),
        marker_rate=info.marker_rate, n_train=len(info.train), n_test=len(info.test),
        train_minutes=_minutes(corpus, info.train), test_minutes=_minutes(corpus, info.test),
        labels=label_census(corpus).to_json())


def model_summary(model: Model, baselines: Baselines) -> ModelSummary:
    """The model's size, its "whole face" coordinates, its config and the ridge baseline's lambda."""
    return ModelSummary(
        n_pcs=model.pca.n_components, variance_explained=float(model.pca.explained_ratio.sum()),
        n_codewords=int(model.codebook.lsf.shape[0]), n_context_phones=model.codebook.n_contexts,
        n_phones=len(model.phones), phones=model.phones,
        moving_coordinates=int(len(moving_coordinates(model))), config=model.config.to_dict(),
        ridge_lambda=baselines.ridge.lam)


def _automatic_labels(corpus: Corpus, model: Model, comparisons: list[ComparisonRow],
                      progress: Progress) -> dict:
    """The automatic-label section (``facetraj_engine.report.labels``), with the MOCHA-TIMIT sample in
    ``../shared`` beside the repository when it is there."""
    from .labels import MOCHA_SAMPLE, label_section

    mocha = Path(__file__).resolve().parents[3] / "shared" / MOCHA_SAMPLE[0]
    return label_section(corpus, model, comparisons, mocha if mocha.is_dir() else None, progress)


def compute_report(corpus_dir: str | os.PathLike[str], model: Model | None = None,
                   progress: Progress | None = None, ns: Iterable[int] = range(1, 11),
                   labels_section: bool = True, workers: int | None = None,
                   skip: Skips | None = None) -> ReportData:
    """Compute every number of the report on the corpus's own train/test split.

    Trains a model on the train split when ``model`` is ``None``. The training and the
    evaluations run in ``workers`` processes (default every core, :func:`default_workers`); their
    scores equal a serial run's. With ``labels_section`` and a corpus with transcripts, adds the
    automatic-label section (PocketSphinx; slow on the first run, then cached). A bad file stops
    the report with its error; with ``skip`` its utterance is left out of every number (and
    named in the corpus summary).
    """
    progress = progress or (lambda f, m: None)
    workers = workers or default_workers()
    corpus = load_corpus(corpus_dir)
    ns = list(ns)
    timings: dict[str, float] = {}
    if model is None:
        with _timed(timings, "train"):
            model = train(corpus, progress=_stage(progress, 0.0, 0.1), workers=workers, skip=skip)
    rows1 = top_similar(model.similarity(), model.phones, 3)          # Table 1 (eqs 1-3)
    with _timed(timings, "table2_and_acoustic"):                         # N = 3, both smoothings
        res2 = table2(model, corpus, acoustic=True, progress=_stage(progress, 0.1, 0.45),
                      workers=workers, skip=skip)
    corpus = corpus.without(skip.bad if skip else ())   # table2 has read every utterance
    indexed = SynthConfig(mode="acoustic", closure=False)   # the default search, without the step
    with _timed(timings, "acoustic_indexed"):
        res_ix = evaluate(model, corpus, ("train", "test"), [indexed], ("triangular", "spline"),
                          progress=_stage(progress, 0.45, 0.47), workers=workers)
    with _timed(timings, "sweep_n"):                                     # Figure 5
        res5 = sweep_n(model, corpus, ns, progress=_stage(progress, 0.47, 0.8),
                       workers=workers)
    with _timed(timings, "baselines"):
        base, base_scores = _baselines(model, corpus, progress, workers)
    with _timed(timings, "figure4"):
        progress(0.96, "Figure 4")
        fig4 = figure4_data(model, corpus)
    comparisons = comparison_rows(res2, res_ix, indexed, base, base_scores)
    sensors = sensor_section(model, res2, res_ix, base_scores, "test" if corpus.info.test else "train")
    labels = None
    if labels_section and corpus.info.test and (corpus.data_root / f"{corpus.info.test[0]}.txt").exists():
        with _timed(timings, "automatic_labels"):
            labels = _automatic_labels(corpus, model, comparisons, _stage(progress, 0.97, 0.995))
    summary = corpus_summary(corpus)
    summary.skipped = dict(skip.bad) if skip else {}
    progress(1.0, "done")
    return ReportData(corpus=summary, model=model_summary(model, base), table1=rows1,
                      paper_table1=paper_table1(),
                      table2=[r for r in comparisons if r.mode == "phonetic"],
                      comparisons=comparisons, sweep=sweep_table(res5, ns), figure4=fig4,
                      labels=labels, timings=timings, sensors=sensors,
                      created=f"{dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC")


__all__ = ["comparison_rows", "compute_report", "corpus_summary", "figure4_data", "find_utterance",
           "model_summary"]
