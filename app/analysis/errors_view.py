"""Error analysis: which phones synthesize worst, which utterances, which segments.

The view runs :func:`facetraj_engine.analysis.errors.error_report` in a background worker and shows
the RMS lip error (mm) per phone, worst first, with its frame count (and the correlation where a
phone has enough frames for one to mean something), a sortable per-utterance list and the worst
segments; a click on an utterance or a segment jumps there (utterance and time). :class:`LipErrorPanel` adds
``|original - synthesized|`` of the lips to the time-aligned stack with the worst segments of
the current utterance highlighted.
"""

from __future__ import annotations

import logging
from functools import partial
from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure
from PyQt6.QtCore import Qt, pyqtSignal
from PyQt6.QtWidgets import (
    QComboBox,
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QPushButton,
    QSpinBox,
    QSplitter,
    QTableWidget,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from facetraj_app.window_frame import FillScrollArea
from facetraj_engine.analysis.common import subset_corpus
from facetraj_engine.analysis.errors import (
    MIN_CORRELATION_FRAMES,
    ErrorReport,
    error_report,
    lip_error,
    segment_errors,
    worst_segments,
    write_error_csv,
)
from facetraj_engine.io.corpus import Corpus
from facetraj_engine.method.model import Model

from ..tier_labels import Span, StackedLabels
from .common import (
    Canvas,
    NumberItem,
    WindowLinks,
    bar_labels,
    export_with_dialog,
    fill_table,
    heat_item,
    report_error,
    stop_own_tasks,
    task_runner,
    text_item,
)

log = logging.getLogger(__name__)

#: the lip error panel's curves (not the original/synthesized colours: both are errors)
UPPER_ERROR_COLOR, LOWER_ERROR_COLOR = "#7048e8", "#0c8599"
SPLITS = {"test": ("test",), "train": ("train",), "train + test": ("train", "test")}


#: the height of one bar of the per-phone chart (px): its label at 7-8 pt (a laptop's dock
#: labelled every other bar at 6 px); the chart scrolls when its phones need more room
BAR_PX = 14


def chart_height(n_bars: int) -> int:
    """The least height (px) of a per-phone chart of ``n_bars`` bars: every bar labelled.

    >>> chart_height(34)
    615
    """
    return int(n_bars * BAR_PX / 0.8) + 20


def draw_phone_chart(fig: Figure, phones: list) -> None:
    """Per-phone RMS lip error (mm) as horizontal bars, the worst at the top, each phone named
    with its frame count (a phone of few frames is one to read with care); coloured like the
    table's cells; constrained layout keeps the title and the x label inside."""
    fig.clear()
    fig.set_layout_engine("constrained")
    ax = fig.add_subplot(111)
    phones = sorted((p for p in phones if p.rms == p.rms), key=lambda p: p.rms)
    if not phones:
        ax.text(0.5, 0.5, "no phone has a lip error", ha="center", va="center",
                transform=ax.transAxes, color="#555555")
        ax.set_axis_off()
        return
    rms = np.array([p.rms for p in phones])
    y = np.arange(len(phones))
    lo, hi = float(rms.min()), float(rms.max())
    shade = (rms - lo) / (hi - lo) if hi > lo else np.zeros_like(rms)
    ax.barh(y, rms, color=colormaps["YlOrRd"](0.15 + 0.75 * shade), edgecolor="#555555", lw=0.4)
    labels, size = bar_labels(fig, [f"{p.phone} ({p.frames})" for p in phones])
    ax.set_yticks(y, labels, fontsize=size)
    ax.set_ylim(-0.6, len(phones) - 0.4)
    ax.set_xlim(0.0, 1.08 * hi)
    ax.set_xlabel("RMS lip error (mm), original vs synthesized", fontsize=8)
    ax.set_title("Per phone, worst at the top (frames)", fontsize=9)
    ax.tick_params(axis="x", labelsize=7)
    ax.grid(axis="x", alpha=0.3)


def closures_line(report: ErrorReport) -> str:
    """The closures against the talker's own lips, in a sentence (issue 46; the definitions in
    :data:`CLOSURES_TIP`)."""
    c, talker = report.closures, report.talker
    if c is None or talker is None or not np.isfinite(talker.closed):
        return ""
    return (f"Closed lips against the talker's (within 1 mm of {talker.closed:.1f} mm): "
            f"precision {_percent(c.precision)}, recall {_percent(c.recall)} "
            f"({c.talker} closed frames).")


#: What the closed-lips figures mean (the status line's and the table columns' tooltip).
CLOSURES_TIP = ("A frame's lips are closed when their aperture is within 1 mm of the talker's "
                "closed aperture: the median of its lips' minima at its labelled /p b m/, else the "
                "1st percentile of its speech frames. Precision: of the synthesized closed frames, "
                "the share closed in the original; recall: of the original's closed frames, the "
                "share closed in the synthesis (speech frames, as the correlations).")


def _percent(x: float) -> str:
    return "–" if not np.isfinite(x) else f"{100 * x:.0f} %"


class ErrorView(QWidget):
    """Per-phone, per-utterance and worst-segment errors over a corpus."""

    reportReady = pyqtSignal(object)
    jumpRequested = pyqtSignal(str, float)       # utterance id, time (s)

    def __init__(self, model: Model, corpus: Corpus, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.model = model
        self.corpus = corpus
        self.window_ = window
        self.tasks = task_runner(self, window)
        self.report: ErrorReport | None = None
        self._pending_seek: tuple[str, float] | None = None

        self.splits = QComboBox()
        self.splits.addItems(list(SPLITS))
        if not corpus.info.test:                # a corpus without a test split: its training one
            self.splits.setCurrentText("train")
        self.per_split = QSpinBox()
        self.per_split.setRange(0, 10000)
        self.per_split.setSpecialValueText("all")
        self.run_btn = QPushButton("Compute")
        self.run_btn.clicked.connect(self.start)
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        csv_btn = QPushButton("Export CSV…")
        csv_btn.clicked.connect(self._export_csv)
        top = QHBoxLayout()                 # two short rows: they fit a dock of 420 px
        top.addWidget(QLabel("split:"))
        top.addWidget(self.splits)
        top.addWidget(QLabel("utterances:"))
        top.addWidget(self.per_split)
        top.addStretch(1)
        second = QHBoxLayout()
        second.addWidget(self.run_btn)
        second.addWidget(self.progress, 1)
        second.addWidget(csv_btn)

        self.phone_table = QTableWidget()
        self.utt_table = QTableWidget()
        self.worst_table = QTableWidget()
        for t in (self.phone_table, self.utt_table, self.worst_table):
            t.setSortingEnabled(True)
            t.verticalHeader().setVisible(False)
            t.setSelectionBehavior(QTableWidget.SelectionBehavior.SelectRows)
        self.utt_table.cellClicked.connect(self._utt_clicked)
        self.worst_table.cellClicked.connect(self._worst_clicked)
        self.tabs = QTabWidget()
        self.phone_chart = Canvas(5, 5)
        chart_scroll = FillScrollArea()         # as tall as its bars need, scrolling in the dock
        chart_scroll.setWidget(self.phone_chart)
        per_phone = QSplitter(Qt.Orientation.Vertical)     # the chart under the table
        per_phone.addWidget(self.phone_table)
        per_phone.addWidget(chart_scroll)
        per_phone.setStretchFactor(0, 2)
        per_phone.setStretchFactor(1, 3)
        per_phone.setSizes([240, 360])          # the table's rows in view, the chart under them
        per_phone.setChildrenCollapsible(False)
        self.tabs.addTab(per_phone, "Per phone")
        self.tabs.addTab(self.utt_table, "Per utterance")
        self.tabs.addTab(self.worst_table, "Worst segments")
        self.status = QLabel("Compute synthesizes every utterance of the split and compares it with "
                             "the original (lip markers).")
        self.status.setWordWrap(True)
        lay = QVBoxLayout(self)
        lay.addLayout(top)
        lay.addLayout(second)
        lay.addWidget(self.status)
        lay.addWidget(self.tabs, 1)
        self.jumpRequested.connect(self._jump)
        self.links = WindowLinks()
        if window is not None:
            self.links.connect(window.synthesisChanged, self._after_load)

    # ------------------------------------------------------------------ work
    def start(self) -> None:
        model = self.model
        corpus = subset_corpus(self.corpus, int(self.per_split.value()) or None)
        splits = SPLITS[self.splits.currentText()]
        config = getattr(self.window_, "synth_config", None)
        self.run_btn.setEnabled(False)
        self.tasks.run(lambda p: error_report(model, corpus, splits, config, progress=p),
                       self._done, "Error analysis", on_progress=self._on_progress, on_error=self._failed)

    def _on_progress(self, fraction: float, message: str) -> None:
        self.progress.setValue(int(1000 * fraction))
        self.status.setText(message)

    def _failed(self, exc: BaseException) -> None:
        self.run_btn.setEnabled(True)
        report_error(self, "Error analysis", exc)

    def _done(self, report: ErrorReport) -> None:
        self.run_btn.setEnabled(True)
        self.set_report(report)
        self.reportReady.emit(report)

    # ------------------------------------------------------------------ display
    def set_report(self, report: ErrorReport) -> None:
        self.report = report
        finite = [p.rms for p in report.phones if p.rms == p.rms]
        rms_lo, rms_max = (min(finite), max(finite)) if finite else (0.0, 1.0)
        rows = [[text_item(p.phone), heat_item(p.rms, rms_lo, rms_max, "{:.2f}", "YlOrRd"),
                 NumberItem(p.frames, "{:.0f}"), NumberItem(p.segments, "{:.0f}"),
                 heat_item(p.correlation, 0.0, 1.0, "{:.3f}", "RdYlGn")] for p in report.phones]
        fill_table(self.phone_table, ["phone", "RMS error (mm)", "frames", "segments",
                                      f"r (lips y; {MIN_CORRELATION_FRAMES}+ frames)"], rows)
        self._draw_phone_chart(report)
        finite = [u.rms for u in report.utterances if u.rms == u.rms]
        rms_ulo, rms_u = (min(finite), max(finite)) if finite else (0.0, 1.0)
        rows = [[text_item(u.utterance), text_item(u.split),
                 *(heat_item(getattr(u, m), 0.0, 1.0, "{:.3f}", "RdYlGn")
                   for m in ("whole_face", "lower_lip", "upper_lip")),
                 heat_item(u.rms, rms_ulo, rms_u, "{:.2f}"), text_item(u.worst_label),
                 NumberItem(u.worst_time, "{:.2f}"), NumberItem(u.worst_error, "{:.2f}"),
                 *(heat_item(v, 0.0, 1.0, "{:.2f}", "RdYlGn")
                   for v in (u.closure_precision, u.closure_recall))]
                for u in report.utterances]
        fill_table(self.utt_table, ["utterance", "split", "whole face r", "lower lip r", "upper lip r",
                                    "RMS (mm)", "worst phone", "at (s)", "its error (mm)",
                                    "closed precision", "closed recall"], rows)
        rows = [[text_item(s.utterance), text_item(s.label), NumberItem(s.start, "{:.3f}"),
                 NumberItem(s.end, "{:.3f}"),
                 heat_item(s.error, report.worst[-1].error, report.worst[0].error, "{:.2f}")]
                for s in report.worst]
        fill_table(self.worst_table, ["utterance", "phone", "start (s)", "end (s)", "mean lip error (mm)"],
                   rows)
        self.status.setText(f"{len(report.utterances)} utterances, {len(report.phones)} phones. "
                            f"{closures_line(report)} Click an utterance or a segment to go there.")
        self.status.setToolTip(CLOSURES_TIP)
        for col in (9, 10):
            self.utt_table.horizontalHeaderItem(col).setToolTip(CLOSURES_TIP)

    def _draw_phone_chart(self, report: ErrorReport) -> None:
        """Per-phone RMS error as horizontal bars (built and drawn off the GUI thread)."""
        self.phone_chart.setMinimumHeight(chart_height(sum(p.rms == p.rms for p in report.phones)))
        self.phone_chart.rebuild(partial(draw_phone_chart, phones=list(report.phones)))

    def _utt_clicked(self, row: int, _col: int) -> None:
        utt = self.utt_table.item(row, 0).text()
        t = self.utt_table.item(row, 7)
        self.jumpRequested.emit(utt, float(t.value) if isinstance(t, NumberItem) else 0.0)

    def _worst_clicked(self, row: int, _col: int) -> None:
        utt = self.worst_table.item(row, 0).text()
        start = self.worst_table.item(row, 2)
        self.jumpRequested.emit(utt, float(start.value) if isinstance(start, NumberItem) else 0.0)

    # ------------------------------------------------------------------ navigation
    def _jump(self, utt: str, t: float) -> None:
        w = self.window_
        if w is None:
            return
        view = getattr(w, "view", None)
        if view is not None and view.utterance.name == utt:
            w.seek(t)
            return
        self._pending_seek = (utt, t)
        w.set_utterance(utt)

    def _after_load(self) -> None:
        if self._pending_seek is None:
            return
        view = getattr(self.window_, "view", None)
        if view is not None and view.utterance.name == self._pending_seek[0]:
            t = self._pending_seek[1]
            self._pending_seek = None
            self.window_.seek(t)

    def close_view(self) -> None:
        """Stop following the window (another model replaces this view)."""
        self.links.close()

    def closeEvent(self, event) -> None:
        stop_own_tasks(self, self.tasks)
        super().closeEvent(event)

    # ------------------------------------------------------------------ export
    def export_csv(self, path: str | Path) -> Path:
        if self.report is None:
            raise ValueError("compute the errors first")
        return write_error_csv(path, self.report)

    def _export_csv(self) -> None:
        export_with_dialog(self, "Export per-utterance errors", "errors.csv", "CSV (*.csv)",
                           self.export_csv)


class LipErrorPanel:
    """Timeline panel: ``|original - synthesized|`` of the upper and lower lip (mm), the worst
    segments of the utterance shaded and labelled."""

    title = "lip error"
    height = 1.0

    def __init__(self, model: Model, worst: int = 3):
        self.model = model
        self.worst = worst
        self.last_segments = []
        self.labels: StackedLabels | None = None     # the worst segments' labels of the last draw

    def draw(self, ax, view) -> None:
        ax.set_ylabel("lip error\n(mm)", fontsize=8)
        if view.original is None:
            ax.text(0.5, 0.5, "no original markers", transform=ax.transAxes, ha="center",
                    va="center", color="#888888", fontsize=8)
            return
        err = lip_error(self.model, view.original, view.synthesis.markers)
        t = view.times[: len(err)]
        ax.plot(t, err[:, 0], color=UPPER_ERROR_COLOR, lw=1.1, label="error, upper lip")
        ax.plot(t, err[:, 1], color=LOWER_ERROR_COLOR, lw=1.1, label="error, lower lip")
        segs = worst_segments(segment_errors(view.utterance.phones, view.times, err,
                                             view.utterance.name), self.worst)
        self.last_segments = segs
        for s in segs:
            ax.axvspan(s.start, s.end, color="#e03131", alpha=0.15, lw=0)
        # each label whole, over its segment, a row lower where it would touch another
        self.labels = StackedLabels(ax, [Span(s.start, s.end, f"{s.label} {s.error:.1f}", 0.0,
                                              "#c92a2a") for s in segs])
        ax.add_artist(self.labels)
        top = float(np.nanmax(err)) if np.isfinite(err).any() else 1.0
        ax.set_ylim(0, 1.35 * max(top, 0.1))    # the worst segments' labels above the curves
