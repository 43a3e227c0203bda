"""Shared pieces of the analysis views: a matplotlib canvas, heat-coloured numeric table cells,
file dialogs for export, and background work (through the window when there is one)."""

from __future__ import annotations

import logging
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.figure import Figure
from PyQt6.QtCore import QEvent, QObject, Qt, QTimer
from PyQt6.QtGui import QColor
from PyQt6.QtWidgets import (
    QFileDialog,
    QMessageBox,
    QSizePolicy,
    QTableWidget,
    QTableWidgetItem,
    QWidget,
)

from app.workers import Progress, Task

log = logging.getLogger(__name__)


class Canvas(FigureCanvasQTAgg):
    """A matplotlib figure in a widget."""

    def __init__(self, width: float = 6, height: float = 4, dpi: int = 100):
        self.figure = Figure(figsize=(width, height), dpi=dpi)
        self.figure.set_facecolor("white")
        super().__init__(self.figure)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)

    def save_png(self, path: str | Path, dpi: int = 150) -> Path:
        path = Path(path)
        self.figure.savefig(path, dpi=dpi, bbox_inches="tight")
        return path


@lru_cache(maxsize=16)
def _cmap(name: str):
    return colormaps[name]          # a copy per lookup: cache it (initialising one is slow)


def heat_color(value: float, lo: float = 0.0, hi: float = 1.0, cmap: str = "YlOrRd") -> QColor:
    """A background colour for ``value`` on ``[lo, hi]`` (NaN: light grey)."""
    if not np.isfinite(value):
        return QColor("#eeeeee")
    x = 0.0 if hi <= lo else float(np.clip((value - lo) / (hi - lo), 0, 1))
    r, g, b, _ = _cmap(cmap)(x)
    return QColor.fromRgbF(r, g, b)


def text_color_for(bg: QColor) -> QColor:
    lum = 0.299 * bg.redF() + 0.587 * bg.greenF() + 0.114 * bg.blueF()
    return QColor("black") if lum > 0.55 else QColor("white")


class NumberItem(QTableWidgetItem):
    """A table cell that shows a formatted number and sorts by its value (NaN last)."""

    def __init__(self, value: float, fmt: str = "{:.3f}"):
        v = float(value)
        super().__init__("" if not np.isfinite(v) else fmt.format(v))
        self.value = v
        self.setData(Qt.ItemDataRole.UserRole, v)
        self.setTextAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        self.setFlags(self.flags() & ~Qt.ItemFlag.ItemIsEditable)

    def __lt__(self, other: QTableWidgetItem) -> bool:
        if isinstance(other, NumberItem):
            a = self.value if np.isfinite(self.value) else np.inf
            b = other.value if np.isfinite(other.value) else np.inf
            return a < b
        return super().__lt__(other)


def text_item(text: str) -> QTableWidgetItem:
    item = QTableWidgetItem(text)
    item.setFlags(item.flags() & ~Qt.ItemFlag.ItemIsEditable)
    return item


def heat_item(value: float, lo: float, hi: float, fmt: str = "{:.2f}", cmap: str = "YlOrRd") -> NumberItem:
    item = NumberItem(value, fmt)
    bg = heat_color(value, lo, hi, cmap)
    item.setBackground(bg)
    item.setForeground(text_color_for(bg))
    return item


def fill_table(table: QTableWidget, header: list[str], rows: list[list[QTableWidgetItem]]) -> None:
    """Replace a table's contents (sorting is switched off while filling)."""
    sorting = table.isSortingEnabled()
    table.setSortingEnabled(False)
    table.clear()
    table.setColumnCount(len(header))
    table.setHorizontalHeaderLabels(header)
    table.setRowCount(len(rows))
    for r, row in enumerate(rows):
        for c, item in enumerate(row):
            table.setItem(r, c, item)
    table.resizeColumnsToContents()
    stretch_columns(table)
    table.setSortingEnabled(sorting)


MAX_TABLE_MIN_WIDTH = 720     # px: a table narrower than this shows all its columns


class _ColumnStretcher(QObject):
    """Keeps a table's columns filling its width: each column gets its contents' width plus an
    equal share of the room left (never less than its contents, so nothing is cut short)."""

    def __init__(self, table: QTableWidget):
        super().__init__(table)
        self.table = table
        self.widths: list[int] = []
        table.installEventFilter(self)

    def apply(self) -> None:
        t = self.table
        if not self.widths or len(self.widths) != t.columnCount():
            return
        room = t.viewport().width() - sum(self.widths)
        extra = max(room, 0) // len(self.widths)
        for c, w in enumerate(self.widths):
            t.setColumnWidth(c, w + extra)

    def eventFilter(self, obj, event) -> bool:
        if event.type() == QEvent.Type.Resize:
            QTimer.singleShot(0, self.apply)      # after the viewport has its new size
        return False


def stretch_columns(table: QTableWidget) -> None:
    """Columns share the table's width (no empty strip on the right), each at least as wide as
    its contents (after ``resizeColumnsToContents``)."""
    stretcher = table.findChild(_ColumnStretcher) or _ColumnStretcher(table)
    stretcher.widths = [table.columnWidth(c) for c in range(table.columnCount())]
    table.horizontalHeader().setStretchLastSection(False)
    # a table of a few columns asks for their whole width (a splitter or dock then shows them all);
    # a wide one (the similarity matrix) scrolls instead
    need = (sum(stretcher.widths) + 2 * table.frameWidth()
            + table.verticalScrollBar().sizeHint().width())
    table.setMinimumWidth(need if need <= MAX_TABLE_MIN_WIDTH else 0)
    stretcher.apply()


def ask_save_path(parent: QWidget, title: str, default: str, filters: str) -> Path | None:
    path, _ = QFileDialog.getSaveFileName(parent, title, default, filters)
    return Path(path) if path else None


def report_error(parent: QWidget, title: str, exc: BaseException) -> None:
    log.error("%s: %s", title, exc)
    QMessageBox.warning(parent, title, str(exc))


def run_background(owner: QWidget, fn: Callable[[Progress], Any], on_done: Callable[[Any], None],
                   on_progress: Callable[[float, str], None] | None = None,
                   on_error: Callable[[BaseException], None] | None = None, label: str = "",
                   window: Any = None) -> Task:
    """Run ``fn(progress)`` in a worker thread; callbacks arrive on the GUI thread.

    With a main ``window`` the work goes through ``window.run_in_background`` (its status bar shows
    it and closing the window stops it); otherwise a :class:`~app.workers.Task` owned by ``owner``
    is kept on the owner so it is not garbage collected while running."""

    def failed(exc: BaseException) -> None:
        if on_error is not None:
            on_error(exc)
        else:
            report_error(owner, label or "background task", exc)

    if window is not None and hasattr(window, "run_in_background"):
        task = window.run_in_background(fn, on_done, label or "analysis", on_error=failed)
        if on_progress is not None:
            task.progress.connect(on_progress)
        return task
    task = Task(fn, label, owner)
    tasks = owner.__dict__.setdefault("_analysis_tasks", [])
    tasks.append(task)

    def finished() -> None:
        if task in tasks:
            tasks.remove(task)

    task.succeeded.connect(on_done)
    task.failed.connect(failed)
    if on_progress is not None:
        task.progress.connect(on_progress)
    task.finished.connect(finished)
    task.start()
    return task


def stop_tasks(owner: QWidget, timeout_ms: int = 5000) -> None:
    """Cancel and join the owner's running tasks (before it closes)."""
    for task in list(owner.__dict__.get("_analysis_tasks", [])):
        task.cancel()
        task.wait(timeout_ms)
