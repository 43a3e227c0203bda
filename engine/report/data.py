"""Everything in the report (:class:`ReportData`), the Figure-4 example, the paper's headline
claims beside ours (:func:`at_a_glance`) and the JSON of all numbers."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .. import __version__
from ..data import PhoneSegment
from ..evaluation.label_eval import LabelEval
from ..evaluation.paper import LEVELS_OFF_AT_N, PAPER_TABLE2
from ..evaluation.scores import METRICS
from ..evaluation.voice_eval import VoiceEval
from ..method.similarity import SimilarRow
from .rows import (
    ComparisonRow,
    CorpusSummary,
    GlanceRow,
    ModelSummary,
    SweepTable,
    table1_agreement,
)
from .text import fmt


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

    def to_json(self) -> dict:
        """Its numbers, the arrays left out."""
        return {"utterance": self.utterance, "text": self.text, "split": self.split,
                "found": self.found, "duration_s": len(self.audio) / self.sample_rate,
                "speech_frames": int(self.speech.sum()), "correlations": self.correlations}


@dataclass
class ReportData:
    """Everything in the report.

    Attributes
    ----------
    corpus : corpus folder and summary (name, utterances and minutes per split).
    model : model summary (PCs, variance explained, codewords, context-phones, phones, config).
    table1 : our top-3 similar phones; ``paper_table1`` the paper's.
    table2 : the phonetic rows (N = 3) of ``comparisons``.
    comparisons : one row per method, split and smoothing.
    sweep : the N sweep (Figure 5, triangular).
    figure4 : the Figure-4 example (``None`` when the corpus has no test utterance).
    labels : the automatic-label section (``facetraj_engine.report.labels.label_section``), ``None``
        when the corpus has no transcripts.
    figures : figure name -> path relative to the report folder (filled by the figures callable).
    timings : seconds per stage.
    """

    corpus: CorpusSummary
    model: ModelSummary
    table1: list[SimilarRow]
    paper_table1: dict[str, list[tuple[str, float]]]
    table2: list[ComparisonRow]
    comparisons: list[ComparisonRow]
    sweep: SweepTable
    figure4: Figure4Data | None
    labels: dict | None = None
    timings: dict[str, float] = field(default_factory=dict)
    figures: dict[str, str] = field(default_factory=dict)
    created: str = ""
    label_eval: LabelEval | None = None    # every mode with automatic labels
                                           # (facetraj_engine.evaluation.label_eval)
    voice_eval: VoiceEval | None = None    # acoustic-only from a second voice
                                           # (facetraj_engine.evaluation.voice_eval)
    closure_eval: dict | None = None       # lips that close (facetraj_engine.evaluation.closure_eval)
    sensors: dict | None = None            # per sensor coordinate (facetraj_engine.report.sensors)

    def row(self, mode: str, split: str = "test", smoothing: str = "triangular") -> ComparisonRow | None:
        """The comparison row of one mode (``phonetic``, ``acoustic``, ``acoustic-indexed``,
        ``viseme``, ``ridge``), split and smoothing."""
        for r in self.comparisons:
            if r.mode == mode and r.split == split and r.smoothing == smoothing:
                return r
        return None

    def table2_row(self, split: str, smoothing: str = "triangular") -> ComparisonRow | None:
        """Our Table 2 row of one split and smoothing."""
        return next((r for r in self.table2 if r.split == split and r.smoothing == smoothing), None)

    def to_json(self) -> dict:
        """All numbers of the report (arrays of the Figure-4 example left out)."""
        return _finite({
            "created": self.created, "facetraj": __version__, "corpus": asdict(self.corpus),
            "model": asdict(self.model),
            "table1": [{"phone": r.phone, "neighbours": [list(n) for n in r.neighbours]}
                       for r in self.table1],
            "table2": [r.table2_json() for r in self.table2],
            "paper_table2": [{"split": sp, "smoothing": sm, **dict(zip(METRICS, v, strict=True))}
                             for (sp, sm), v in PAPER_TABLE2.items()],
            "comparisons": [r.to_json() for r in self.comparisons], "sweep": self.sweep.to_json(),
            "figure4": self.figure4.to_json() if self.figure4 is not None else None,
            "table1_agreement": asdict(table1_agreement(self.table1, self.paper_table1)),
            "at_a_glance": [asdict(g) for g in at_a_glance(self)],
            "timings_s": self.timings, "figures": self.figures, "labels": self.labels,
            "automatic_labels": self.label_eval.to_json()["summary"] if self.label_eval else None,
            "second_voice": self.voice_eval.to_json()["summary"] if self.voice_eval else None,
            "closure": self.closure_eval, "sensors": self.sensors,
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


# ---------------------------------------------------------------------- at a glance
#: the Table 2 numbers of the at-a-glance table: (split, metric), triangular smoothing
GLANCE_TABLE2 = (("train", "whole_face"), ("test", "whole_face"), ("test", "lower_lip"),
                 ("test", "upper_lip"))


def _table2_claims(data: ReportData) -> list[GlanceRow]:
    """Table 2's headline numbers (triangular), ours within ± 0.05 of the paper's."""
    rows = []
    for split, metric in GLANCE_TABLE2:
        paper = PAPER_TABLE2[(split, "triangular")][METRICS.index(metric)]
        r = data.table2_row(split)
        v = getattr(r, metric) if r else float("nan")
        rows.append(GlanceRow(f"{metric.replace('_', ' ')}, {split} (triangular)", f"{paper:.2f}",
                              fmt(v, 2), None if not math.isfinite(v) else abs(v - paper) <= 0.05))
    return rows


def _sweep_claims(sw: SweepTable) -> list[GlanceRow]:
    """Figure 5: where the held-out curve levels off, and whether the training curve falls."""
    if sw.test_levels_off_at is None:
        return []
    n = sw.test_levels_off_at
    rows = [GlanceRow("held-out curve against N levels off at", f"N = {LEVELS_OFF_AT_N}",
                      f"N = {n}", n == LEVELS_OFF_AT_N)]
    trw = sw.curves["train"]["whole_face"]
    if len(trw) > 1 and math.isfinite(trw[0]) and math.isfinite(trw[-1]):
        rows.append(GlanceRow("training curve falls as N grows (by more than 0.005)", "yes",
                              f"{trw[0]:.3f} (N = {sw.ns[0]}) -> {trw[-1]:.3f} (N = {sw.ns[-1]})",
                              trw[-1] < trw[0] - 0.005))
    return rows


def _smoothing_claim(data: ReportData) -> list[GlanceRow]:
    """Triangular above spline smoothing on test, in all three measures."""
    tr, sp = data.table2_row("test", "triangular"), data.table2_row("test", "spline")
    if not (tr and sp):
        return []
    better = all(getattr(tr, m) >= getattr(sp, m) for m in METRICS)
    return [GlanceRow("triangular above spline (test, all three measures)", "yes",
                      "yes" if better else "no", better)]


def at_a_glance(data: ReportData) -> list[GlanceRow]:
    """The paper's headline claims beside ours."""
    return [*_table2_claims(data), *_sweep_claims(data.sweep), *_smoothing_claim(data)]


__all__ = ["GLANCE_TABLE2", "Figure4Data", "FigureMaker", "ReportData", "at_a_glance"]
