"""The utterance browser: train and test groups, each utterance with its lip correlations (filled
in as the background evaluation delivers them) and a filter box."""

from __future__ import annotations

import logging
import math

from PyQt6.QtCore import Qt, QTimer, pyqtSignal
from PyQt6.QtWidgets import (
    QHeaderView,
    QLineEdit,
    QStyledItemDelegate,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from .elided import distinct_names
from .viewer_model import normalise_text

log = logging.getLogger(__name__)

__all__ = ["UtteranceBrowser", "normalise_text"]

ID_ROLE = Qt.ItemDataRole.UserRole
#: how an item's text is elided where it does not fit (default: at its end)
ELIDE_ROLE = Qt.ItemDataRole.UserRole + 1


class _ElideDelegate(QStyledItemDelegate):
    """Draws an item's text elided as its ``ELIDE_ROLE`` says (an opened recording's name in
    the middle: its end tells it apart)."""

    def initStyleOption(self, option, index) -> None:
        super().initStyleOption(option, index)
        mode = index.data(ELIDE_ROLE)
        if mode is not None:
            option.textElideMode = Qt.TextElideMode(mode)


class UtteranceBrowser(QWidget):
    """A filterable tree of the corpus utterances."""

    utteranceSelected = pyqtSignal(str)

    #: the score columns: the correlation r of each lip centre's y, original vs synthesized
    COLUMNS = ("utterance", "lower lip r", "upper lip r")

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.filter = QLineEdit(self)
        self.filter.setPlaceholderText("filter: id or words")
        self.filter.setClearButtonEnabled(True)
        self.tree = QTreeWidget(self)
        self.tree.setColumnCount(len(self.COLUMNS))
        self.tree.setHeaderLabels(list(self.COLUMNS))
        self.tree.setRootIsDecorated(True)
        self.tree.setUniformRowHeights(True)
        self.tree.setAlternatingRowColors(True)
        self.tree.setItemDelegateForColumn(0, _ElideDelegate(self.tree))
        header = self.tree.header()
        header.setStretchLastSection(False)
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.Stretch)
        for c in (1, 2):
            header.setSectionResizeMode(c, QHeaderView.ResizeMode.Fixed)
            self.tree.setColumnWidth(c, self.tree.fontMetrics().horizontalAdvance(self.COLUMNS[c]) + 16)
        self.setMinimumWidth(260)
        for c, what in ((1, "lower"), (2, "upper")):
            self.tree.headerItem().setToolTip(
                c, f"correlation of the {what} lip centre y, original vs synthesized, on speech frames "
                   "(paper Table 2), with the current synthesis settings")
        lay = QVBoxLayout(self)
        lay.setContentsMargins(2, 2, 2, 2)
        lay.addWidget(self.filter)
        lay.addWidget(self.tree)
        self.items: dict[str, QTreeWidgetItem] = {}
        self.texts: dict[str, str] = {}
        self.groups: dict[str, QTreeWidgetItem] = {}
        self.filter.textChanged.connect(self.apply_filter)
        self.tree.currentItemChanged.connect(self._on_current)

    def populate(self, splits: dict[str, list[str]], texts: dict[str, str]) -> None:
        """Fill the tree: ``splits`` maps group name (train, test) to utterance ids."""
        self.tree.blockSignals(True)
        self.tree.clear()
        self.items.clear()
        self.groups.clear()
        self.texts = dict(texts)
        for split, ids in splits.items():
            group = QTreeWidgetItem([f"{split} ({len(ids)})", "", ""])
            group.setFlags(Qt.ItemFlag.ItemIsEnabled)
            font = group.font(0)
            font.setBold(True)
            group.setFont(0, font)
            self.tree.addTopLevelItem(group)
            self.groups[split] = group
            for utt_id in ids:
                text = texts.get(utt_id, "")
                item = QTreeWidgetItem([f"{utt_id}  {text}" if text else utt_id, "…", "…"])
                item.setData(0, ID_ROLE, utt_id)
                item.setToolTip(0, f"{utt_id}: {text}" if text else utt_id)
                for c in (1, 2):
                    item.setTextAlignment(c, Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
                group.addChild(item)
                self.items[utt_id] = item
            group.setExpanded(True)
        self.tree.blockSignals(False)
        self.apply_filter(self.filter.text())

    def add_external(self, utt_id: str) -> None:
        """Add an utterance opened from files (no original markers) to an "opened" group. Names
        that start alike show the part that tells them apart (``distinct_names``; elided in the
        middle where still too long), the whole name in the tooltip: three ARCTIC files read
        ``cmu_arctic_us_ae...`` alike."""
        group = self.groups.get("opened")
        if group is None:
            group = QTreeWidgetItem(["opened", "", ""])
            group.setFlags(Qt.ItemFlag.ItemIsEnabled)
            self.tree.addTopLevelItem(group)
            self.groups["opened"] = group
        if utt_id not in self.items:
            item = QTreeWidgetItem([utt_id, "–", "–"])
            item.setData(0, ID_ROLE, utt_id)
            item.setData(0, ELIDE_ROLE, Qt.TextElideMode.ElideMiddle)
            item.setToolTip(0, utt_id)
            group.addChild(item)
            self.items[utt_id] = item
        names = [str(group.child(k).data(0, ID_ROLE)) for k in range(group.childCount())]
        for k, shown in enumerate(distinct_names(names).values()):
            group.child(k).setText(0, shown)
        group.setExpanded(True)

    def set_current(self, utt_id: str) -> None:
        item = self.items.get(utt_id)
        if item is None:
            return
        self.tree.blockSignals(True)
        self.tree.setCurrentItem(item)
        self.tree.scrollToItem(item, QTreeWidget.ScrollHint.PositionAtCenter)
        self.tree.blockSignals(False)

    def restore_current(self, utt_id: str) -> None:
        """Make ``utt_id`` current again once the click (or key) that chose another has been
        handled: set inside it, the view's own selection would follow the click."""
        QTimer.singleShot(0, lambda: self.set_current(utt_id))

    def set_scores(self, utt_id: str, lower: float, upper: float) -> None:
        item = self.items.get(utt_id)
        if item is None:
            return
        for col, v in ((1, lower), (2, upper)):
            item.setText(col, "–" if v is None or not math.isfinite(v) else f"{v:.3f}")
            item.setForeground(col, self.palette().text())
            item.setToolTip(col, "")

    def show_scores(self, scores: dict[str, tuple[float, float]]) -> None:
        """The scores known for the present settings; the others keep what they show, greyed
        (computed with other settings), or "…" (not yet computed)."""
        stale = self.palette().placeholderText()
        for utt_id, item in self.items.items():
            if utt_id in scores:
                self.set_scores(utt_id, *scores[utt_id])
            elif item.text(1) not in ("–", "…"):
                for col in (1, 2):
                    item.setForeground(col, stale)
                    item.setToolTip(col, "computed with other settings; the present ones' follows")

    def apply_filter(self, text: str) -> None:
        words = normalise_text(text).split()
        for utt_id, item in self.items.items():
            hay = f"{utt_id.lower()} {normalise_text(self.texts.get(utt_id, ''))}"
            item.setHidden(not all(w in hay for w in words))

    def _on_current(self, current: QTreeWidgetItem | None, _previous) -> None:
        if current is None:
            return
        utt_id = current.data(0, ID_ROLE)
        if utt_id:
            self.utteranceSelected.emit(str(utt_id))
