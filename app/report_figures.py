"""The figures of the results report (issue 7), drawn with matplotlib's Agg canvas (no Qt, no
pyplot state, so it is safe inside the app and on a headless machine).

``make_report(corpus_dir, out_dir)`` is what ``facetraj report CORPUS -o DOCS_DIR`` runs: it
computes the report with :func:`facetraj_engine.report.write_report` and draws

* ``results_figure5.png``: correlation against N for train and test (the paper's Figure 5);
* ``results_figure4.png``: waveform, upper and lower lip y, original vs triangular vs spline
  synthesis, speech/silence dots (the paper's Figure 4);
* ``results_comparison.png``: Table 2 beside the paper's, acoustic-only and the baselines.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from facetraj_engine.evaluation.paper import PAPER_TABLE2, TABLE2_N
from facetraj_engine.evaluation.scores import METRICS
from facetraj_engine.method.model import Model
from facetraj_engine.report import ComparisonRow, ReportData, write_report

log = logging.getLogger(__name__)

DPI = 120
DARK = "#1f2a44"
LIGHT = "#8fb3de"
ORIGINAL = "#000000"
TRAIN_C = "#c0392b"
TEST_C = "#2471a3"
LABELS = {"whole_face": "whole face", "lower_lip": "lower lip", "upper_lip": "upper lip"}


def _save(fig: Figure, path: Path) -> Path:
    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=DPI)
    return path


def figure5(data: ReportData, path: Path) -> Path:
    """Correlation (triangular smoothing) against N, train and test, whole face solid and lips
    thin; the paper's N = 3 figures as markers."""
    sw = data.sweep
    ns = sw.ns
    fig = Figure(figsize=(9.0, 4.2))
    ax = fig.add_subplot()
    for split, colour in (("train", TRAIN_C), ("test", TEST_C)):
        curves = sw.curves[split]
        ax.plot(ns, curves["whole_face"], "-o", color=colour, lw=2, ms=4,
                label=f"{split}, whole face")
        ax.plot(ns, curves["lower_lip"], "--", color=colour, lw=1, label=f"{split}, lower lip")
        ax.plot(ns, curves["upper_lip"], ":", color=colour, lw=1, label=f"{split}, upper lip")
        paper = PAPER_TABLE2[(split, "triangular")][0]
        ax.plot([TABLE2_N], [paper], "*", color=colour, ms=12, mec="k", mew=0.5,
                label=f"paper, {split} whole face (N = {TABLE2_N})")
    ax.set_xlabel("N, visually most similar context-phones searched")
    ax.set_ylabel("correlation, original vs synthesized")
    ax.set_xticks(ns)
    ax.grid(alpha=0.3)
    ax.set_title("Correlation against N (cf. the paper's Figure 5)")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    return _save(fig, path)


def figure4(data: ReportData, path: Path) -> Path | None:
    """Waveform on top, then upper and lower lip centre y: original (dotted), spline (dark solid),
    triangular (light); dots at mid-height on speech frames (the paper's Figure 4)."""
    f4 = data.figure4
    if f4 is None:
        return None
    fig = Figure(figsize=(9.0, 7.0))
    axes = fig.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [1, 1.4, 1.4]})
    t_audio = np.arange(len(f4.audio)) / f4.sample_rate
    axes[0].plot(t_audio, f4.audio, color="0.3", lw=0.4)
    axes[0].set_ylabel("speech")
    peak = float(np.abs(f4.audio).max() or 1.0)
    axes[0].set_ylim(-1.1 * peak, 1.35 * peak)
    for seg in f4.phones:
        if seg.label and seg.label not in ("sil", "sp", ""):
            axes[0].text((seg.start + seg.end) / 2, 0.97, seg.label, ha="center", va="top",
                         fontsize=6, color="0.25", transform=axes[0].get_xaxis_transform())
    where = f"{f4.utterance}, {f4.split} split, N = 3"
    axes[0].set_title(f"\"{f4.text}\" ({where})" if f4.text else where, fontsize=9)
    for ax, name, traces in ((axes[1], "upper lip y (mm)", f4.upper_lip),
                             (axes[2], "lower lip y (mm)", f4.lower_lip)):
        ax.plot(f4.times, traces["triangular"], color=LIGHT, lw=2.2, label="triangular")
        ax.plot(f4.times, traces["spline"], color=DARK, lw=1.4, label="spline")
        ax.plot(f4.times, traces["original"], ":", color=ORIGINAL, lw=1.6, label="original")
        vals = np.concatenate([v[np.isfinite(v)] for v in traces.values()])
        lo, hi = (float(vals.min()), float(vals.max())) if vals.size else (0.0, 1.0)
        mid = (lo + hi) / 2
        ax.set_ylim(lo - 0.05 * (hi - lo), hi + 0.3 * (hi - lo))   # headroom for the legend
        ax.plot(f4.times[f4.speech], np.full(int(f4.speech.sum()), mid), ".", color="0.4", ms=2,
                label="speech frames")
        ax.set_ylabel(name)
        ax.grid(alpha=0.25)
    for ax, key in ((axes[1], "upper_lip"), (axes[2], "lower_lip")):
        txt = ", ".join(f"{sm} r = {c[key]:.2f}" for sm, c in f4.correlations.items())
        ax.text(0.01, 0.03, txt, transform=ax.transAxes, fontsize=7, color="0.2")
    axes[1].legend(fontsize=7, ncol=4, loc="upper left")
    axes[2].set_xlabel("time (s)")
    fig.tight_layout()
    return _save(fig, path)


def comparison(data: ReportData, path: Path) -> Path:
    """Grouped bars: whole face / lower lip / upper lip on test (triangular) for the paper's
    numbers, ours, acoustic-only and the two baselines; train shown as thin outlines."""
    methods: list[tuple[str, ComparisonRow | None]] = []
    names = {"phonetic": "ours, N = 3", "acoustic": "acoustic-only", "viseme": "viseme lookup",
             "ridge": "ridge (LSF)"}
    for mode, label in names.items():
        methods.append((label, data.row(mode)))
    fig = Figure(figsize=(8.0, 4.2))
    ax = fig.add_subplot()
    x = np.arange(len(METRICS))
    width = 0.8 / (len(methods) + 1)
    paper = PAPER_TABLE2[("test", "triangular")]
    ax.bar(x - 0.4 + width / 2, paper, width, color="0.75", edgecolor="k", lw=0.5, label="paper")
    colours = ["#2471a3", "#27ae60", "#d68910", "#8e44ad"]
    for k, (label, row) in enumerate(methods):
        if row is None:
            continue
        vals = [getattr(row, m) for m in METRICS]
        err = [row.std(m) or 0.0 for m in METRICS]
        ax.bar(x - 0.4 + width * (k + 1.5), vals, width, yerr=err, capsize=2,
               color=colours[k % len(colours)], label=label, error_kw={"lw": 0.6})
    ax.set_xticks(x, [LABELS[m] for m in METRICS])
    ax.set_ylabel("correlation on test (triangular)")
    lo = min([0.0, *(v for _, r in methods if r for v in (getattr(r, m) for m in METRICS)
                     if np.isfinite(v))])     # 0 when every value is NaN (found by make fuzz)
    ax.set_ylim(lo, 1.05)
    ax.axhline(0, color="k", lw=0.5)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=7, ncol=5, loc="upper center", bbox_to_anchor=(0.5, -0.08))
    ax.set_title("Held-out correlation: the paper, ours, and simpler methods (± 1 sd over utterances)",
                 fontsize=9)
    fig.tight_layout()
    return _save(fig, path)


def make_figures(data: ReportData, fig_dir: Path) -> dict[str, Path]:
    """Draw every report figure into ``fig_dir`` (an :data:`facetraj_engine.report.FigureMaker`)."""
    fig_dir = Path(fig_dir)
    fig_dir.mkdir(parents=True, exist_ok=True)
    out: dict[str, Path] = {}
    out["figure5"] = figure5(data, fig_dir / "results_figure5.png")
    f4 = figure4(data, fig_dir / "results_figure4.png")
    if f4 is not None:
        out["figure4"] = f4
    out["comparison"] = comparison(data, fig_dir / "results_comparison.png")
    return out


def make_report(corpus_dir: str | os.PathLike[str], out_dir: str | os.PathLike[str],
                model: Model | None = None, progress: Callable[[float, str], None] | None = None,
                ns: Iterable[int] = range(1, 11), **options) -> Path:
    """Write ``out_dir/results.md``, ``out_dir/results.json`` and ``out_dir/figures/results_*.png``
    for the corpus in ``corpus_dir`` (trained on its train split unless ``model`` is given).
    Returns the path of ``results.md``. ``options``: ``workers``, ``skip``
    (:func:`facetraj_engine.report.write_report`)."""
    return write_report(corpus_dir, out_dir, model=model, progress=progress, ns=ns,
                        figures=make_figures, **options)
