"""Metrics: the paper's Table 2 (train / test x triangular / spline; whole face, lower lip, upper
lip) plus acoustic-only rows, and the N sweep (Figure 5), each computed by the engine in a
background worker with progress; with Table 2 the per-sensor table (r and RMSE in mm of every
sensor coordinate, as articulatory-inversion papers tabulate them, with the viseme and ridge
baselines beside the method: :mod:`facetraj_engine.evaluation.sensors`). Export CSV (Table 2, per
sensor, sweep) and PNG (the two plots).
"""

from __future__ import annotations

import logging
from functools import partial
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from PyQt6.QtCore import pyqtSignal
from PyQt6.QtGui import QColor
from PyQt6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QPushButton,
    QSpinBox,
    QStackedWidget,
    QTableWidget,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.analysis.common import subset_corpus
from facetraj_engine.analysis.metrics import (
    SweepCurve,
    Table2Row,
    sensor_rows,
    sweep_curves,
    table2_rows,
    write_sensor_csv,
    write_sweep_csv,
    write_table2_csv,
)
from facetraj_engine.evaluation.baselines import fit_and_score
from facetraj_engine.evaluation.paper import TABLE2_N, table2_value
from facetraj_engine.evaluation.scores import METRICS, EvalResult, sweep_n, table2
from facetraj_engine.io.corpus import Corpus
from facetraj_engine.method.model import Model

from ..flow_layout import FlowLayout, flow_row
from .common import (
    Canvas,
    NumberItem,
    export_with_dialog,
    fill_table,
    heat_item,
    report_error,
    stop_own_tasks,
    task_runner,
    text_item,
)

log = logging.getLogger(__name__)

METRIC_NAMES = {"whole_face": "Whole Face", "lower_lip": "Lower Lip", "upper_lip": "Upper Lip"}


def _paper(row: Table2Row) -> tuple[float, float, float]:
    """The paper's Table 2 value of this condition (phonetic, N = 3), else NaN."""
    if row.mode != "phonetic" or row.n_context_phones != TABLE2_N:
        return (float("nan"),) * 3
    return table2_value(row.split, row.smoothing)


def _short(row: Table2Row) -> str:
    """A compact bar label in lines: split, smoothing, acoustic-only (eight of them fit a
    laptop's dock: "acoustic" ran into its neighbours)."""
    smooth = {"triangular": "tri.", "spline": "spl."}.get(row.smoothing, row.smoothing)
    return f"{row.split}\n{smooth}" + ("\nac." if row.mode != "phonetic" else "")


def draw_metrics(fig: Figure, rows: list[Table2Row], curves: list[SweepCurve]) -> None:
    """Table 2 as grouped bars (one group per condition, a bar per measure, the legend above the
    plot) over the N sweep (Figure 5), one under the other so that each has the dock's width;
    constrained layout keeps every label inside."""
    fig.clear()
    fig.set_layout_engine("constrained")
    ax1, ax2 = fig.subplots(2, 1, height_ratios=[1, 1])
    if rows:
        x = np.arange(len(rows))
        width = 0.27
        for k, m in enumerate(METRICS):
            ax1.bar(x + (k - 1) * width, [getattr(r, m) for r in rows], width, label=METRIC_NAMES[m])
        ax1.set_xticks(x, [_short(r) for r in rows], fontsize=7)
        ax1.set_ylim(0, 1.0)
        ax1.legend(fontsize=7, ncol=3, loc="lower center", bbox_to_anchor=(0.5, 1.0),
                   frameon=False, title="Table 2: mean correlation on speech frames",
                   title_fontsize=8)
    else:
        ax1.text(0.5, 0.5, "Compute Table 2", ha="center", va="center", transform=ax1.transAxes,
                 color="#888888")
        ax1.set_title("Table 2: mean correlation on speech frames", fontsize=8)
    ax1.set_ylabel("correlation r", fontsize=8)
    if rows:
        ax1.set_xlabel("tri., spl.: triangular, spline smoothing; ac.: acoustic only", fontsize=7)
    ax1.tick_params(labelsize=7)
    figure5 = "Figure 5: correlation against N (triangular)"
    if curves:
        for c in curves:
            style = "-o" if c.split == "test" else "--s"
            ax2.plot(c.ns, c.whole_face, style, ms=4, label=f"{c.split} (whole face)")
        # above the plot, as Table 2's: never over the curves
        ax2.legend(fontsize=7, ncol=2, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False,
                   title=figure5, title_fontsize=8)
        ax2.set_xticks(curves[0].ns)
    else:
        ax2.text(0.5, 0.5, "Run N sweep", ha="center", va="center", transform=ax2.transAxes,
                 color="#888888")
        ax2.set_title(figure5, fontsize=8)
    ax2.set_xlabel("N (context-phones searched)", fontsize=8)
    ax2.set_ylabel("correlation r", fontsize=8)
    ax2.tick_params(labelsize=7)


class MetricsView(QWidget):
    """Table 2 and the N sweep for a model and corpus."""

    table2Done = pyqtSignal()
    sweepDone = pyqtSignal()

    def __init__(self, model: Model, corpus: Corpus, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.model = model
        self.corpus = corpus
        self.window_ = window
        self.tasks = task_runner(self, window)
        self.table2_result: EvalResult | None = None
        self.baseline_result: EvalResult | None = None
        self.sweep_result: EvalResult | None = None
        self.rows: list[Table2Row] = []
        self.curves: list[SweepCurve] = []

        self.per_split = QSpinBox()
        self.per_split.setRange(0, 10000)
        self.per_split.setSpecialValueText("all")
        self.per_split.setToolTip("utterances per split (all: the whole corpus)")
        self.acoustic = QCheckBox("acoustic-only rows")
        self.acoustic.setChecked(True)
        self.baselines = QCheckBox("baselines")
        self.baselines.setChecked(True)
        self.baselines.setToolTip("the viseme lookup and the ridge regression, fitted on the "
                                  "training split, in the per-sensor table")
        self.max_n = QSpinBox()
        self.max_n.setRange(1, 30)
        self.max_n.setValue(10)
        self.run_table2 = QPushButton("Compute Table 2")
        self.run_table2.clicked.connect(self.start_table2)
        self.run_sweep = QPushButton("Run N sweep, N = 1 to")
        self.run_sweep.clicked.connect(self.start_sweep)
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.status = QLabel("")
        self.status.setWordWrap(True)
        exp = [("Table 2 CSV…", "export Table 2 as CSV", self._export_table2),
               ("per sensor CSV…", "export the per-sensor table as CSV", self._export_sensors),
               ("N sweep CSV…", "export the N sweep as CSV", self._export_sweep),
               ("PNG…", "export the two plots as a PNG image", self._export_png)]

        self.table = QTableWidget()
        self.table.setSortingEnabled(False)             # ours, each followed by the paper's
        self.table.verticalHeader().setVisible(False)
        self.table.verticalHeader().setDefaultSectionSize(self.table.fontMetrics().height() + 6)
        self.sensor_table = QTableWidget()          # r and RMSE per sensor coordinate
        self.sensor_table.setSortingEnabled(False)
        self.sensor_table.verticalHeader().setVisible(False)
        self.sensor_table.verticalHeader().setDefaultSectionSize(self.table.fontMetrics().height() + 6)
        # Table 2 or the per-sensor table in the same place (the numbers' tab), chosen above it
        self.tables = QStackedWidget()
        self.tables.addWidget(self.table)
        self.tables.addWidget(self.sensor_table)
        self.table_choice = QComboBox()
        self.table_choice.addItems(["Table 2", "per sensor"])
        self.table_choice.setToolTip("Table 2, or r and RMSE (mm) of every sensor coordinate "
                                     "(triangular smoothing)")
        self.table_choice.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToContents)
        self.table_choice.currentIndexChanged.connect(self.tables.setCurrentIndex)
        self.canvas = Canvas(6, 5.2)
        self.canvas.setMinimumHeight(300)
        # the plots and the tables in tabs: each has the dock's height (in a laptop's dock the
        # table took the room and Figure 5 was 30 px tall)
        self.tabs = QTabWidget()
        self.tabs.addTab(self.canvas, "Plots: Table 2, Figure 5")
        self.tabs.addTab(self._numbers(), "Numbers: Table 2, per sensor")
        lay = QVBoxLayout(self)
        lay.addWidget(self._options(exp))
        lay.addWidget(self.tabs, 1)
        self._draw()

    def _numbers(self) -> QWidget:
        """The numbers' tab: the table chooser over Table 2 or the per-sensor table."""
        tab = QWidget()
        row = QHBoxLayout()
        row.addWidget(QLabel("table:"))
        row.addWidget(self.table_choice)
        row.addStretch(1)
        lay = QVBoxLayout(tab)
        lay.setContentsMargins(0, 2, 0, 0)
        lay.addLayout(row)
        lay.addWidget(self.tables, 1)
        return tab

    def _options(self, exports: list) -> QGroupBox:
        """The run options, the progress and export, in rows that wrap to the dock's width
        (:class:`FlowLayout`: on a laptop "baselines" and "PNG…" were past the dock's edge, the
        plots beside them cut)."""
        opts = QGroupBox("Run")
        options = FlowLayout(spacing=8, row_spacing=4)
        options.add(flow_row([QLabel("utterances per split:"), self.per_split]))
        options.add(self.acoustic)
        options.add(self.baselines)
        options.add(self.run_table2)
        options.add(flow_row([self.run_sweep, self.max_n]))
        buttons = FlowLayout(spacing=6, row_spacing=4)      # one row in a laptop's dock
        for text, tip, slot in exports:
            b = QPushButton(text)
            b.setToolTip(tip)
            b.clicked.connect(slot)
            buttons.add(b)
        lay = QVBoxLayout(opts)
        lay.addLayout(options)
        lay.addWidget(self.progress)
        lay.addWidget(self.status)
        lay.addLayout(buttons)
        return opts

    # ------------------------------------------------------------------ work
    def _subset(self) -> Corpus:
        return subset_corpus(self.corpus, int(self.per_split.value()) or None)

    def _busy(self, busy: bool) -> None:
        self.run_table2.setEnabled(not busy)
        self.run_sweep.setEnabled(not busy)

    def _on_progress(self, fraction: float, message: str) -> None:
        self.progress.setValue(int(1000 * fraction))
        self.status.setText(message)

    def _failed(self, exc: BaseException) -> None:
        self._busy(False)
        self.status.setText("failed")
        report_error(self, "Metrics", exc)

    def start_table2(self) -> None:
        """Table 2 (and the baselines, when asked) in the background."""
        corpus, model, acoustic = self._subset(), self.model, self.acoustic.isChecked()
        baselines = self.baselines.isChecked()

        def work(p) -> tuple[EvalResult, EvalResult | None]:
            share = 0.7 if baselines else 1.0
            res = table2(model, corpus, acoustic=acoustic, progress=lambda f, m: p(share * f, m))
            if not baselines:
                return res, None
            _, scores = fit_and_score(model, corpus, progress=lambda f, m: p(share + 0.3 * f, m))
            return res, EvalResult(scores)

        self._busy(True)
        self.tasks.run(work, self._table2_done, "Table 2", on_progress=self._on_progress,
                       on_error=self._failed)

    def start_sweep(self) -> None:
        corpus, model = self._subset(), self.model
        ns = tuple(range(1, int(self.max_n.value()) + 1))
        self._busy(True)
        self.tasks.run(lambda p: sweep_n(model, corpus, ns, progress=p),
                       self._sweep_done, "N sweep", on_progress=self._on_progress, on_error=self._failed)

    def _table2_done(self, results: tuple[EvalResult, EvalResult | None]) -> None:
        self._busy(False)
        self.set_table2(*results)
        self.table2Done.emit()

    def _sweep_done(self, result: EvalResult) -> None:
        self._busy(False)
        self.set_sweep(result)
        self.sweepDone.emit()

    # ------------------------------------------------------------------ display
    def set_table2(self, result: EvalResult, baselines: EvalResult | None = None) -> None:
        """Our Table 2 rows, each phonetic N = 3 row followed by the paper's (grey): six columns
        that fit the dock (the paper's values had three columns of their own, past its edge);
        the per-sensor table of the same conditions and the ``baselines``."""
        self.table2_result, self.baseline_result = result, baselines
        self._fill_sensors()
        self.rows = table2_rows(result)
        head = ["condition", "whole face r", "lower lip r", "upper lip r", "N", "utterances"]
        rows = []
        for r in self.rows:
            rows.append([text_item(r.name), *(heat_item(getattr(r, m), 0.4, 1.0, "{:.4f}", "RdYlGn")
                                              for m in METRICS),
                         NumberItem(r.n_context_phones, "{:.0f}"), NumberItem(r.utterances, "{:.0f}")])
            paper = _paper(r)
            if np.isfinite(paper).all():
                rows.append([text_item("   the paper, same condition"),
                             *(NumberItem(v, "{:.2f}") for v in paper),
                             NumberItem(TABLE2_N, "{:.0f}"), text_item("")])
                for item in rows[-1]:
                    item.setForeground(QColor("#666666"))
        fill_table(self.table, head, rows)
        self.table.resizeRowsToContents()
        self.status.setText(f"Table 2: {len(self.rows)} conditions (its numbers: the second tab; "
                            "grey: the paper's)")
        self._draw()

    def sensor_split(self) -> str:
        """The split of the per-sensor table: the test split, else the training one."""
        has_test = self.table2_result is not None and any(
            s.split == "test" for s in self.table2_result.scores)
        return "test" if has_test else "train"

    def _results(self) -> list[EvalResult]:
        return [r for r in (self.table2_result, self.baseline_result) if r is not None]

    def _fill_sensors(self) -> None:
        """The per-sensor table (triangular smoothing): a row per coordinate, r and RMSE (mm)
        per condition; the paper's three correlations first."""
        names, rows = sensor_rows(self._results(), self.sensor_split())
        head = ["row", "role", *(f"{n}\n{w}" for n in names for w in ("r", "RMSE mm"))]
        def r_item(value: float, role: str):        # a reference sensor's r is noise: no heat
            return (NumberItem(value, "{:.3f}") if role == "reference"
                    else heat_item(value, 0.4, 1.0, "{:.3f}", "RdYlGn"))

        items = [[text_item(r.name), text_item(r.role),
                  *(item for rv, ev in zip(r.r, r.rmse_mm, strict=True)
                    for item in (r_item(rv, r.role), NumberItem(ev, "{:.2f}")))]
                 for r in rows]
        fill_table(self.sensor_table, head, items)
        self.sensor_table.resizeColumnsToContents()
        self.table_choice.setItemText(1, f"per sensor ({self.sensor_split()})")

    def set_sweep(self, result: EvalResult) -> None:
        self.sweep_result = result
        self.curves = sweep_curves(result)
        self.status.setText("N sweep done")
        self._draw()

    def _draw(self) -> None:
        """Both plots, built and drawn off the GUI thread."""
        self.canvas.rebuild(partial(draw_metrics, rows=list(self.rows), curves=list(self.curves)))

    def closeEvent(self, event) -> None:
        stop_own_tasks(self, self.tasks)
        super().closeEvent(event)

    # ------------------------------------------------------------------ export
    def export_table2_csv(self, path: str | Path) -> Path:
        if self.table2_result is None:
            raise ValueError("compute Table 2 first")
        return write_table2_csv(path, self.table2_result)

    def export_sensor_csv(self, path: str | Path) -> Path:
        if self.table2_result is None:
            raise ValueError("compute Table 2 first")
        return write_sensor_csv(path, self._results(), self.sensor_split())

    def export_sweep_csv(self, path: str | Path) -> Path:
        if self.sweep_result is None:
            raise ValueError("run the N sweep first")
        return write_sweep_csv(path, self.sweep_result)

    def export_png(self, path: str | Path) -> Path:
        self.canvas.draw()
        return self.canvas.save_png(path)

    def _export_table2(self) -> None:
        export_with_dialog(self, "Export Table 2", "table2.csv", "CSV (*.csv)", self.export_table2_csv)

    def _export_sensors(self) -> None:
        export_with_dialog(self, "Export the per-sensor table", "per_sensor.csv", "CSV (*.csv)",
                           self.export_sensor_csv)

    def _export_sweep(self) -> None:
        export_with_dialog(self, "Export N sweep", "n_sweep.csv", "CSV (*.csv)", self.export_sweep_csv)

    def _export_png(self) -> None:
        export_with_dialog(self, "Export plots", "metrics.png", "PNG image (*.png)", self.export_png)
