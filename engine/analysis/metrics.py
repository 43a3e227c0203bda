"""The metrics view's numbers: the paper's Table 2 and the N sweep (Figure 5) as rows and CSV,
from an :class:`~facetraj_engine.evaluation.scores.EvalResult`; the per-sensor table (r and RMSE of
every sensor coordinate of the method and the baselines side by side,
:mod:`facetraj_engine.evaluation.sensors`)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..evaluation.scores import ConditionScores, EvalResult
from ..evaluation.sensors import TableRow, condition_columns, table_rows
from .common import write_csv

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


@dataclass(kw_only=True)
class Table2Row(ConditionScores):
    """One row of Table 2: the condition, its three mean correlations (the fields of
    :class:`~facetraj_engine.evaluation.scores.ConditionScores`), a row ``name``, the number of
    utterances, and the synthesized closures' precision and recall against the talker's own lips
    (:mod:`facetraj_engine.evaluation.closed_lips`)."""

    name: str
    utterances: int
    closure_precision: float = float("nan")
    closure_recall: float = float("nan")


def table2_rows(result: EvalResult) -> list[Table2Row]:
    """Table 2 rows, ordered as the paper (train before test, triangular before spline),
    phonetic rows before acoustic-only ones."""
    rows = []
    for r in result.table():
        count = sum(1 for s in result.scores if (s.split, s.mode, s.smoothing, s.n_context_phones)
                    == (r["split"], r["mode"], r["smoothing"], r["n_context_phones"]))
        rows.append(Table2Row(**r, name=condition_name(r["split"], r["smoothing"], r["mode"]),
                              utterances=count))
    rank = {"train": 0, "test": 1}
    srank = {"triangular": 0, "spline": 1}
    rows.sort(key=lambda r: (r.mode != "phonetic", rank.get(r.split, 2), srank.get(r.smoothing, 2),
                             r.n_context_phones))
    return rows


def write_table2_csv(path: str | os.PathLike[str], result: EvalResult, overwrite: bool = True) -> Path:
    """Write Table 2 (plus acoustic-only rows) as CSV."""
    rows = table2_rows(result)
    return write_csv(path, ["condition", "split", "mode", "smoothing", "N", "whole_face",
                            "lower_lip", "upper_lip", "utterances", "closure_precision",
                            "closure_recall"],
                     ([r.name, r.split, r.mode, r.smoothing, r.n_context_phones, r.whole_face,
                       r.lower_lip, r.upper_lip, r.utterances, r.closure_precision,
                       r.closure_recall] for r in rows), overwrite)


@dataclass
class SweepCurve:
    """Mean correlation against N for one split (Figure 5)."""

    split: str
    ns: np.ndarray
    whole_face: np.ndarray
    lower_lip: np.ndarray
    upper_lip: np.ndarray


def sweep_curves(result: EvalResult, smoothing: str = "triangular") -> list[SweepCurve]:
    """The N sweep per split from a :func:`~facetraj_engine.evaluation.scores.sweep_n` result."""
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
    return write_csv(path, ["split", "N", "whole_face", "lower_lip", "upper_lip"], rows, overwrite)


def sensor_rows(results: list[EvalResult], split: str, smoothing: str = "triangular"
                ) -> tuple[list[str], list[TableRow]]:
    """The per-sensor table of ``results`` (the method's and the baselines') on ``split``: the
    conditions' names, and the rows (:func:`facetraj_engine.evaluation.sensors.table_rows`)."""
    cols = condition_columns(results, split, smoothing)
    return [c[0] for c in cols], table_rows(cols)


def write_sensor_csv(path: str | os.PathLike[str], results: list[EvalResult], split: str,
                     smoothing: str = "triangular", overwrite: bool = True) -> Path:
    """Write the per-sensor table as CSV: a row per coordinate, r and RMSE (mm) per condition."""
    names, rows = sensor_rows(results, split, smoothing)
    header = ["row", "role", *(f"{n} {what}" for n in names for what in ("r", "rmse_mm"))]
    return write_csv(path, header, ([r.name, r.role, *(v for pair in zip(r.r, r.rmse_mm, strict=True)
                                                        for v in pair)] for r in rows), overwrite)


__all__ = ["SMOOTHING_NAMES", "SweepCurve", "Table2Row", "condition_name", "sensor_rows",
           "sweep_curves", "table2_rows", "write_sensor_csv", "write_sweep_csv", "write_table2_csv"]
