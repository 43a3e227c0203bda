"""The review list (a dock, Edit → Review list): the segments of the labels on screen most worth a
look, ranked (``facetraj_engine.analysis.label_review``: /p b m/ whose synthesized lips stay open,
other consonants whose lips shut, phones unlike the talker's, phones their maker doubted), made
again from every new result, so that a corrected phone leaves it. Enter (or a double click) on a
row selects that phone in the label editor and moves the cursor there."""

from __future__ import annotations

from PyQt6.QtCore import QObject, Qt, pyqtSignal
from PyQt6.QtGui import QKeySequence
from PyQt6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QLabel,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.analysis.label_review import ReviewItem, counts, review
from facetraj_engine.evaluation.closure import lip_aperture
from facetraj_engine.labels.editing import PHONES, shown

from .label_session import labels_from_utterance

COLUMNS = ("phone", "at (s)", "why", "")


class ReviewList(QWidget):
    """The table of :class:`ReviewItem` rows; ``jump(row)`` on Enter or a double click."""

    jump = pyqtSignal(int)

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.summary = QLabel("")
        self.summary.setWordWrap(True)
        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels(list(COLUMNS))
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.verticalHeader().setVisible(False)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setStretchLastSection(True)
        self.table.itemActivated.connect(lambda item: self.jump.emit(item.row()))
        self.table.setToolTip("the segments most worth a look, ranked; Enter or a double click "
                              "selects one on the phones row")
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.addWidget(self.summary)
        lay.addWidget(self.table)
        self.items: list[ReviewItem] = []

    def keyPressEvent(self, event) -> None:
        if event.key() in (Qt.Key.Key_Return, Qt.Key.Key_Enter) and self.table.currentRow() >= 0:
            self.jump.emit(self.table.currentRow())
            return
        super().keyPressEvent(event)

    def show_items(self, items: list[ReviewItem], note: str = "") -> None:
        """The rows, the current one kept where it is the same segment."""
        current = self.table.currentRow()
        was = self.items[current] if 0 <= current < len(self.items) else None
        self.items = list(items)
        self.table.setRowCount(len(items))
        for r, it in enumerate(items):
            for c, text in enumerate((shown(it.segment.label), f"{it.segment.start:.3f}",
                                      it.reason, it.detail)):
                cell = QTableWidgetItem(text)
                if c == 1:
                    cell.setTextAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
                self.table.setItem(r, c, cell)
        if was is not None:
            keep = next((r for r, it in enumerate(items) if it.segment == was.segment), 0)
            self.table.setCurrentCell(keep, 0)
        parts = ", ".join(f"{n} {why}" for why, n in counts(items).items())
        self.summary.setText(note or (f"{len(items)} to look at: {parts}" if items else
                                      "nothing to look at: no segment the lips or the labels' "
                                      "maker doubt"))


class LabelReview(QObject):
    """The review list of ``window``'s labels on screen, following the label ``editor``."""

    def __init__(self, window, editor):
        super().__init__(window)
        self.window, self.editor = window, editor
        self.list = ReviewList()
        self.list.jump.connect(self.go_to)
        self.dock = None                # made when first opened (no dock tabbed with the views')
        self.action = editor.menu.addAction("Review list (where to look first)", self.open)
        self.action.setShortcut(QKeySequence("Ctrl+R"))
        window.synthesisChanged.connect(self.refresh)
        editor.sessionChanged.connect(self.refresh)

    def open(self) -> None:
        """Show the review list's dock (made on first use)."""
        if self.dock is None:
            self.dock = self.window.add_dock(self.list, "Review labels")
        self.dock.show()
        self.dock.raise_()
        self.refresh()
        self.list.table.setFocus()
        if self.list.table.currentRow() < 0 and self.list.items:
            self.list.table.setCurrentCell(0, 0)

    def refresh(self) -> None:
        """The list of the labels on screen (the editor's when it is editing them)."""
        w = self.window
        view, model = w.view, w.model
        if self.dock is None or not self.dock.isVisible():
            return                      # made again when shown
        if view is None or model is None or not view.utterance.phones:
            self.list.show_items([], "no phone labels on screen")
            return
        s = self.editor.session
        labels = s.doc.labels_now() if s is not None and s.matches(view) else \
            labels_from_utterance(view.utterance)
        closed = model.closure.closed if model.closure is not None else float("nan")
        talker = None if view.original is None else \
            lip_aperture(view.original, model.upper_lip, model.lower_lip)
        items = review(labels, view.times, lip_aperture(view.shown, model.upper_lip, model.lower_lip),
                       closed, talker)
        self.list.show_items(items)

    def go_to(self, row: int) -> None:
        """Select the phone of ``row`` on the phones row, the cursor at its start (the time axis
        moved to it when it is out of view)."""
        if not 0 <= row < len(self.list.items):
            return
        it = self.list.items[row]
        seg, tl = it.segment, self.window.timeline
        lo, hi = tl.xlim()
        if not (lo <= seg.start and seg.end <= hi):
            width = hi - lo
            tl.set_xlim(0.5 * (seg.start + seg.end) - width / 2, 0.5 * (seg.start + seg.end) + width / 2)
        self.window.seek(seg.start + 1e-6)
        self.editor.select(PHONES, it.index)
        self.window.timeline.canvas.setFocus(Qt.FocusReason.OtherFocusReason)
        self.window.show_status(f"{shown(seg.label)} at {seg.start:.3f} s: {it.reason} "
                                f"({it.detail})", 8000)


def install(window) -> LabelReview:
    """The review list; after ``label_editing.install``. Also ``window.extension("review")``."""
    rev = LabelReview(window, window.extension("labels"))
    window.add_extension("review", rev)
    return rev


__all__ = ["LabelReview", "ReviewList", "install"]
