"""The report's typed rows and the small functions that build them from scores: one method's mean
correlations (:class:`ComparisonRow`, also the rows of Table 2), the N sweep (:class:`SweepTable`),
Table 1's agreement with the paper, and the corpus and model summaries."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..evaluation.scores import METRICS, ConditionScores, EvalResult, UtteranceScore
from ..method.similarity import SimilarRow


@dataclass(kw_only=True)
class ComparisonRow(ConditionScores):
    """One method's correlations on one split and smoothing: the means over utterances (the fields
    of :class:`~facetraj_engine.evaluation.scores.ConditionScores`), their standard deviations over utterances
    (NaN under two utterances), the utterance count ``n`` and the ``method`` as the report names it.
    """

    method: str
    n: int
    whole_face_std: float
    lower_lip_std: float
    upper_lip_std: float

    def std(self, metric: str) -> float:
        """The standard deviation over utterances of ``metric`` (one of ``METRICS``)."""
        return {"whole_face": self.whole_face_std, "lower_lip": self.lower_lip_std,
                "upper_lip": self.upper_lip_std}[metric]

    def to_json(self) -> dict:
        """The row in ``results.json``'s ``comparisons``: each mean followed by its std."""
        return {"method": self.method, "mode": self.mode, "n_context_phones": self.n_context_phones,
                "split": self.split, "smoothing": self.smoothing, "n": self.n,
                **{k: v for m in METRICS for k, v in ((m, getattr(self, m)), (f"{m}_std", self.std(m)))}}

    def table2_json(self) -> dict:
        """The row in ``results.json``'s ``table2`` (the phonetic rows): means, then stds."""
        return {"split": self.split, "smoothing": self.smoothing,
                **{m: getattr(self, m) for m in METRICS},
                **{f"{m}_std": self.std(m) for m in METRICS}, "n": self.n}


def summarise(scores: Iterable[UtteranceScore], method: str | None = None) -> list[ComparisonRow]:
    """Mean, std and count per (mode, N, split, smoothing) of the three metrics; ``method``
    defaults to the mode."""
    groups: dict[tuple, list[UtteranceScore]] = {}
    for s in scores:
        groups.setdefault((s.mode, s.n_context_phones, s.split, s.smoothing), []).append(s)
    rows = []
    for (mode, n, split, sm), rs in groups.items():
        stats: dict[str, float] = {}
        for m in METRICS:
            v = np.array([getattr(r, m) for r in rs], dtype=float)
            v = v[np.isfinite(v)]
            stats[m] = float(v.mean()) if v.size else float("nan")
            stats[f"{m}_std"] = float(v.std(ddof=1)) if v.size > 1 else float("nan")
        rows.append(ComparisonRow(split=split, mode=mode, smoothing=sm, n_context_phones=n,
                                  method=method or mode, n=len(rs), **stats))
    return rows


@dataclass
class SweepTable:
    """Figure 5's numbers: per split (``train``, ``test``) and metric, the mean correlation for each
    N in ``ns`` (triangular smoothing); where the test whole-face curve comes within 0.005 of its
    best, and its best N (``None`` when the curve has no finite value)."""

    ns: list[int]
    curves: dict[str, dict[str, list[float]]]
    test_levels_off_at: int | None = None
    test_best_n: int | None = None

    def to_json(self) -> dict:
        out: dict = {"ns": self.ns, **self.curves}
        if self.test_levels_off_at is not None:
            out["test_levels_off_at"] = self.test_levels_off_at
            out["test_best_n"] = self.test_best_n
        return out


def sweep_table(result: EvalResult, ns: Sequence[int]) -> SweepTable:
    """Figure 5 numbers: per split and metric, the mean correlation for each N (triangular)."""
    ns = list(ns)
    curves = {split: {m: [result.mean(split, "triangular", "phonetic", n)[m] for n in ns]
                      for m in METRICS} for split in ("train", "test")}
    table = SweepTable(ns, curves)
    test = curves["test"]["whole_face"]
    if test and np.isfinite(test).any():
        best = float(np.nanmax(test))
        table.test_levels_off_at = int(next(n for n, v in zip(ns, test, strict=True)
                                            if np.isfinite(v) and v >= best - 0.005))
        table.test_best_n = int(ns[int(np.nanargmax(test))])
    return table


@dataclass
class Table1Agreement:
    """How our Table 1 agrees with the paper's on the phones both have: how many phones have the
    paper's closest phone, and the mean number of the three neighbours both name."""

    phones_compared: int
    same_closest: int
    mean_top3_overlap: float


def table1_agreement(ours: Sequence[SimilarRow],
                     paper: dict[str, list[tuple[str, float]]]) -> Table1Agreement:
    """How our Table 1 agrees with the paper's on the phones both have."""
    common = [r for r in ours if r.phone in paper]
    top1 = sum(r.neighbours[0][0] == paper[r.phone][0][0] for r in common if r.neighbours)
    overlap = [len({n for n, _ in r.neighbours[:3]} & {n for n, _ in paper[r.phone]}) for r in common]
    return Table1Agreement(len(common), int(top1),
                           float(np.mean(overlap)) if overlap else float("nan"))


@dataclass
class GlanceRow:
    """One of the paper's headline claims beside ours (``same`` is ``None`` when ours cannot be
    computed)."""

    claim: str
    paper: str
    ours: str
    same: bool | None


@dataclass
class CorpusSummary:
    """The corpus of the report: folder, name, markers, utterances and minutes per split."""

    root: str
    name: str
    n_markers: int
    marker_rate: float
    n_train: int
    n_test: int
    train_minutes: float
    test_minutes: float
    skipped: dict[str, str] = field(default_factory=dict)   # utterance -> its bad file's message
    labels: dict = field(default_factory=dict)   # phones per kind (facetraj_engine.io.label_census)


@dataclass
class ModelSummary:
    """The model of the report: PCs and their variance, codewords, context-phones, phones, the
    coordinates of the "whole face", its training config and the ridge baseline's lambda."""

    n_pcs: int
    variance_explained: float
    n_codewords: int
    n_context_phones: int
    n_phones: int
    phones: list[str]
    moving_coordinates: int
    config: dict
    ridge_lambda: float


__all__ = ["ComparisonRow", "CorpusSummary", "GlanceRow", "ModelSummary", "SweepTable",
           "Table1Agreement", "summarise", "sweep_table", "table1_agreement"]
