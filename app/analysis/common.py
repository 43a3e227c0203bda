"""Shared pieces of the analysis views: a matplotlib canvas, heat-coloured numeric table cells,
file dialogs for export, and the task runner of a view (the window's when there is one)."""

from __future__ import annotations

import logging
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure
from PyQt6.QtCore import QEvent, QObject, QSize, Qt, QTimer
from PyQt6.QtGui import QColor, QFont, QFontMetrics
from PyQt6.QtWidgets import (
    QFileDialog,
    QMessageBox,
    QSizePolicy,
    QSplitter,
    QStyle,
    QTableWidget,
    QTableWidgetItem,
    QWidget,
)

from facetraj_app.figure_canvas import BackgroundCanvas
from facetraj_app.workers import TaskRunner

log = logging.getLogger(__name__)


class Canvas(BackgroundCanvas):
    """A matplotlib figure in a widget, drawn off the GUI thread (``app/figure_canvas.py``: change
    the figure in ``when_idle``)."""

    def __init__(self, width: float = 6, height: float = 4, dpi: int = 100):
        self.figure = Figure(figsize=(width, height), dpi=dpi)
        self.figure.set_facecolor("white")
        super().__init__(self.figure)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)

    def save_png(self, path: str | Path, dpi: int = 150) -> Path:
        self.finish()                   # a build on its way is part of the picture
        path = Path(path)
        self.figure.savefig(path, dpi=dpi, bbox_inches="tight")
        return path


@lru_cache(maxsize=16)
def _cmap(name: str):
    return colormaps[name]          # a copy per lookup: cache it (initialising one is slow)


NAN_COLOR = "#eeeeee"


def bar_labels(fig: Figure, labels: list[str], share: float = 0.8, max_pt: float = 8.0,
               min_pt: float = 5.0) -> tuple[list[str], float]:
    """The y tick labels of a bar per label on ``fig`` (about ``share`` of its height for the
    bars) and their font size: as large as a bar's height allows (up to ``max_pt``); where even
    ``min_pt`` does not fit a bar, only every second, third, ... label is written (the others
    blank), so that no label is ever drawn over the next.

    >>> f = Figure(figsize=(4, 2), dpi=100)          # 160 px of bars
    >>> bar_labels(f, list("abcd"))[1], bar_labels(f, list("abcdefghijklmnopqrst"))[1]
    (8.0, 5.0)
    >>> bar_labels(f, [str(i) for i in range(40)])[0][:6]      # every third, the top one kept
    ['0', '', '', '3', '', '']
    """
    per_bar_pt = share * fig.get_figheight() * 72.0 / max(len(labels), 1)
    size = max(min_pt, min(max_pt, 0.75 * per_bar_pt))
    step = max(1, int(np.ceil(1.3 * size / per_bar_pt)))
    # counted from the last (the top bar's label, the worst, always shown)
    n = len(labels)
    return [lab if (n - 1 - i) % step == 0 else "" for i, lab in enumerate(labels)], size


def vertical_split(top: QWidget, bottom: QWidget, sizes: tuple[int, int]) -> QSplitter:
    """``top`` over ``bottom`` in a splitter (neither collapsible), shared as ``sizes``."""
    split = QSplitter(Qt.Orientation.Vertical)
    split.addWidget(top)
    split.addWidget(bottom)
    split.setSizes(list(sizes))
    split.setChildrenCollapsible(False)
    return split


def heat_colors(values: np.ndarray, lo: float = 0.0, hi: float = 1.0,
                cmap: str = "YlOrRd") -> tuple[np.ndarray, np.ndarray]:
    """Background colours ``(..., 3)`` in [0, 1] of ``values`` on ``[lo, hi]`` (NaN: light grey)
    and whether each needs dark text: all mapped in one call."""
    values = np.asarray(values, dtype=np.float64)
    finite = np.isfinite(values)
    x = np.clip((values - lo) / (hi - lo), 0.0, 1.0) if hi > lo else np.zeros_like(values)
    rgb = _cmap(cmap)(np.where(finite, x, 0.0))[..., :3]
    rgb[~finite] = QColor(NAN_COLOR).getRgbF()[:3]
    dark_text = rgb @ np.array([0.299, 0.587, 0.114]) > 0.55
    return rgb, dark_text


def heat_color(value: float, lo: float = 0.0, hi: float = 1.0, cmap: str = "YlOrRd") -> QColor:
    """A background colour for ``value`` on ``[lo, hi]`` (NaN: light grey)."""
    rgb, _dark = heat_colors(np.array(value), lo, hi, cmap)
    return QColor.fromRgbF(*rgb)


class NumberItem(QTableWidgetItem):
    """A table cell that shows a formatted number and sorts by its value (NaN last)."""

    def __init__(self, value: float, fmt: str = "{:.3f}"):
        v = float(value)
        text = "" if not np.isfinite(v) else fmt.format(v)
        if text.startswith("-") and not text.strip("-+0.,"):     # no "-0.0": a zero
            text = fmt.format(0.0)
        super().__init__(text)
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
    return heat_items(np.array([[value]]), lo, hi, fmt, cmap)[0][0]


def heat_items(values: np.ndarray, lo: float, hi: float, fmt: str = "{:.2f}",
               cmap: str = "YlOrRd") -> list[list[NumberItem]]:
    """Heat-coloured cells of a 2-D array of values, coloured all at once (one colour map call,
    not one per cell)."""
    values = np.asarray(values, dtype=np.float64)
    rgb, dark_text = heat_colors(values, lo, hi, cmap)
    black, white = QColor("black"), QColor("white")
    rows = []
    for r in range(values.shape[0]):
        row = []
        for c in range(values.shape[1]):
            item = NumberItem(values[r, c], fmt)
            item.setBackground(QColor.fromRgbF(*rgb[r, c]))
            item.setForeground(black if dark_text[r, c] else white)
            row.append(item)
        rows.append(row)
    return rows


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


MAX_TABLE_MIN_WIDTH = 440     # px: a table narrower than this shows all its columns (a wider
                              # one scrolls inside itself: its dock must fit the window)


class _ColumnStretcher(QObject):
    """Keeps a table's columns filling its width: each column gets its contents' width plus an
    equal share of the room left (never less than its contents, so nothing is cut short)."""

    def __init__(self, table: QTableWidget):
        super().__init__(table)
        self.table = table
        self.widths: list[int] = []
        table.installEventFilter(self)
        table.viewport().installEventFilter(self)   # a vertical scroll bar appearing narrows it

    def apply(self) -> None:
        t = self.table
        if not self.widths or len(self.widths) != t.columnCount():
            return
        shown = [c for c in range(t.columnCount()) if not t.isColumnHidden(c)]
        room = t.viewport().width() - sum(self.widths[c] for c in shown)
        extra = max(room, 0) // max(len(shown), 1)
        for c in shown:
            t.setColumnWidth(c, self.widths[c] + extra)

    def eventFilter(self, obj, event) -> bool:
        if event.type() == QEvent.Type.Resize:
            QTimer.singleShot(0, self.apply)      # after the viewport has its new size
        return False


def stretch_columns(table: QTableWidget) -> None:
    """Columns share the table's width (no empty strip on the right), each at least as wide as
    its contents (after ``resizeColumnsToContents``); hidden columns get none of it (called
    again after a column is hidden or shown)."""
    stretcher = table.findChild(_ColumnStretcher) or _ColumnStretcher(table)
    header = table.horizontalHeader()
    stretcher.widths = [max(table.sizeHintForColumn(c), header.sectionSizeHint(c))   # its contents'
                        for c in range(table.columnCount())]
    header.setStretchLastSection(False)
    # a table of a few columns asks for their whole width (a splitter or dock then shows them all);
    # a wide one (the similarity matrix) scrolls instead
    need = (sum(w for c, w in enumerate(stretcher.widths) if not table.isColumnHidden(c))
            + 2 * table.frameWidth() + table.verticalScrollBar().sizeHint().width())
    table.setMinimumWidth(need if need <= MAX_TABLE_MIN_WIDTH else 0)
    stretcher.apply()


#: the room a header keeps for its sort arrow (the style reserves the header's whole height:
#: 30 px and more for a heading on two lines)
SORT_ARROW_PX = 10


def compact_headers(table: QTableWidget) -> None:
    """The table's headings as narrow as their longest line and the sort arrow (each heading's
    ``SizeHintRole``), then its columns fitted again (:func:`stretch_columns`): headings on two
    lines then make narrow columns."""
    header = table.horizontalHeader()
    font = QFont(header.font())
    font.setBold(True)                      # as the header measures its sections
    fm = QFontMetrics(font)
    margin = header.style().pixelMetric(QStyle.PixelMetric.PM_HeaderMargin, None, header)
    for c in range(table.columnCount()):
        item = table.horizontalHeaderItem(c)
        if item is None:
            continue
        lines = item.text().split("\n")
        width = max(fm.horizontalAdvance(line) for line in lines) + 2 * margin + SORT_ARROW_PX
        item.setData(Qt.ItemDataRole.SizeHintRole,
                     QSize(width, fm.lineSpacing() * len(lines) + 2 * margin))
    table.resizeColumnsToContents()
    stretch_columns(table)


def ask_save_path(parent: QWidget, title: str, default: str, filters: str) -> Path | None:
    path, _ = QFileDialog.getSaveFileName(parent, title, default, filters)
    return Path(path) if path else None


def report_error(parent: QWidget, title: str, exc: BaseException) -> None:
    log.error("%s: %s", title, exc)
    QMessageBox.warning(parent, title, str(exc))


def export_with_dialog(parent: QWidget, title: str, default: str, filters: str,
                       write: Callable[[Path], Any]) -> None:
    """Ask for a file name and ``write(path)``; a failure (``OSError``, ``ValueError``) is shown,
    not raised, and a success said in the main window's status bar ("wrote …", as every export
    of the File menu says it). The export buttons of every view go through here."""
    path = ask_save_path(parent, title, default, filters)
    if path:
        try:
            written = write(path)
        except (OSError, ValueError) as exc:
            report_error(parent, "Export failed", exc)
            return
        top = parent.window()
        if hasattr(top, "show_status"):         # the main window (a view may stand alone)
            top.show_status(f"wrote {written if isinstance(written, (str, Path)) else path}")


class WindowLinks:
    """The main window's signals a view follows, undone by :meth:`close` (the view's
    ``close_view``, called when another model replaces the views): a view of the old model never
    receives the new model's results."""

    def __init__(self):
        self.links: list[tuple[Any, Callable]] = []

    def connect(self, signal: Any, slot: Callable) -> None:
        signal.connect(slot)
        self.links.append((signal, slot))

    def close(self) -> None:
        for signal, slot in self.links:
            try:
                signal.disconnect(slot)
            except (TypeError, RuntimeError):      # gone with its sender already
                pass
        self.links.clear()


def task_runner(owner: QWidget, window: Any = None) -> TaskRunner:
    """Where a view runs its background work: the main window's task runner (its status bar shows
    the work and closing the window stops it), or, for a view used on its own, a runner owned by
    the view (stop it with :func:`stop_own_tasks` when the view closes)."""
    tasks = getattr(window, "tasks", None)
    return tasks if isinstance(tasks, TaskRunner) else TaskRunner(owner)


def stop_own_tasks(owner: QWidget, tasks: TaskRunner) -> None:
    """Cancel and join the tasks of a runner the view owns (a window's runner is left alone)."""
    if tasks.parent() is owner:
        tasks.close()
