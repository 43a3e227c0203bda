"""Measure: how far apart the lips are, at the cursor and per phone (an extension of the main
window; the numbers from ``app/measure_model.py`` and the engine).

* The **readout** under the window (a bottom toolbar) follows the cursor: the phone and word
  there, the upper and lower lip y and the aperture of the synthesis in 3-D, the original's and
  the difference, and each pinned result's, in mm.
* **Analysis → Measure: lip aperture per phone…** opens a dock with each phone's aperture at its
  minimum and its midpoint, original, synthesized and error: sortable, filtered by phone
  (``b p m``), exported as CSV; a click goes to the phone's minimum.
"""

from __future__ import annotations

from pathlib import Path

from PyQt6.QtCore import QSize, Qt
from PyQt6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSizePolicy,
    QTableWidget,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.analysis.articulators import jaw_top

from .analysis.common import NumberItem, export_with_dialog, fill_table, text_item
from .measure_model import TABLE_COLUMNS, Measure


class ApertureTable(QWidget):
    """The per-phone apertures of the utterance on screen: a filter, the table, CSV export."""

    def __init__(self, measure: Measure, seek, parent: QWidget | None = None):
        super().__init__(parent)
        self.measure = measure
        self.seek = seek
        self.filter = QLineEdit()
        self.filter.setPlaceholderText("phones to show, e.g. b p m (empty: all)")
        self.filter.setClearButtonEnabled(True)
        self.filter.textChanged.connect(lambda _t: self.refresh())
        export = QPushButton("Export CSV…")
        export.clicked.connect(self._export)
        top = QHBoxLayout()
        top.addWidget(QLabel("phones:"))
        top.addWidget(self.filter, 1)
        top.addWidget(export)
        self.note = QLabel("")
        self.note.setWordWrap(True)
        self.table = QTableWidget()
        self.table.setSortingEnabled(True)
        self.table.verticalHeader().setVisible(False)
        self.table.setSelectionBehavior(QTableWidget.SelectionBehavior.SelectRows)
        self.table.cellClicked.connect(self._clicked)
        lay = QVBoxLayout(self)
        lay.addLayout(top)
        lay.addWidget(self.note)
        lay.addWidget(self.table, 1)

    def refresh(self) -> None:
        items = []
        for r in self.measure.rows(self.filter.text()):
            row = []
            for _head, attribute, fmt in TABLE_COLUMNS:
                v = getattr(r, attribute)
                row.append(text_item(v) if isinstance(v, str) else NumberItem(v, fmt))
            row[0].setData(Qt.ItemDataRole.UserRole + 1, r.min_time)
            items.append(row)
        fill_table(self.table, [c[0] for c in TABLE_COLUMNS], items)
        view = self.measure.view
        has_original = view is not None and view.original is not None
        self.note.setText("Lip aperture (mm, upper to lower lip centre marker) of each phone at its "
                          "minimum and midpoint; error = synthesized − original. Click a row to go "
                          "to the phone's minimum." + ("" if has_original or view is None else
                                                       " This recording has no original markers."))

    def _clicked(self, row: int, _col: int) -> None:
        item = self.table.item(row, 0)
        t = item.data(Qt.ItemDataRole.UserRole + 1) if item is not None else None
        if t is not None:
            self.seek(float(t))

    def export_csv(self, path: str | Path) -> Path:
        return self.measure.write_csv(path, self.filter.text())

    def _export(self) -> None:
        export_with_dialog(self, "Export the apertures per phone", "apertures.csv", "CSV (*.csv)",
                           self.export_csv)


class _Readout(QLabel):
    """The readout's label: it asks the toolbar for a modest width whatever its text (its text
    wraps within what it gets), so that a long readout never widens the window."""

    def sizeHint(self) -> QSize:
        return QSize(320, super().sizeHint().height())

    def minimumSizeHint(self) -> QSize:
        return QSize(120, super().minimumSizeHint().height())


class MeasureTools:
    """The readout (a bottom toolbar) and the per-phone table's dock, following the window."""

    def __init__(self, window):
        self.window = window
        self.measure = Measure()
        self._jaw_top: tuple = (None, float("nan"))
        bar = QToolBar("Measure")
        bar.setObjectName("measure-toolbar")
        bar.setMovable(False)
        # two lines of fixed height whatever the text (no relayout as the cursor moves), as wide
        # as the window gives it (a long readout never widens the window)
        self.readout = _Readout("")
        self.readout.setWordWrap(True)
        self.readout.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.readout.setFixedHeight(2 * self.readout.fontMetrics().lineSpacing() + 4)
        self.readout.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.readout.setToolTip("at the cursor: the lips of the synthesis in 3-D, the original's and "
                                "each pin's (mm); the aperture is upper to lower lip centre marker; "
                                "for articulograph sensors also the tongue tip's height and the jaw "
                                "opening (below the talker's highest jaw position)")
        bar.addWidget(QLabel(" Measure: "))
        bar.addWidget(self.readout)
        window.addToolBar(Qt.ToolBarArea.BottomToolBarArea, bar)
        self.table: ApertureTable | None = None
        self.dock = None
        self.action = window.menu("Analysis").addAction("Measure: lip aperture per phone…",
                                                          self.open_table)
        window.cursorMoved.connect(self._cursor)
        try:            # after each new result and each change of the pins shown (their apertures)
            window.extension("compare").changed.connect(self._new_result)
        except KeyError:                        # no pins: after each new result
            window.synthesisChanged.connect(self._new_result)

    def _new_result(self) -> None:
        w = self.window
        if w.model is None:
            return
        if self._jaw_top[0] is not w.model:          # the talker's highest jaw, once per model
            self._jaw_top = (w.model, jaw_top(w.model) if w.model.roles.articulograph else float("nan"))
        self.measure.set_view(w.view, w.model.upper_lip, w.model.lower_lip, w.pins.shown(w.view),
                              w.model.roles, self._jaw_top[1])
        self._cursor(w.current_time())
        if self.table is not None:
            self.table.refresh()

    def _cursor(self, t: float) -> None:
        text = self.measure.readout_text(t)
        if text != self.readout.text():
            self.readout.setText(text)

    def open_table(self) -> ApertureTable:
        """Show the per-phone table's dock (made on first use)."""
        if self.table is None:
            self.table = ApertureTable(self.measure, self.window.seek)
            self.dock = self.window.add_dock(self.table, "Measure")
        self.table.refresh()
        self.dock.show()
        self.dock.raise_()
        return self.table


def install(window) -> MeasureTools:
    """Add Measure to ``window``; also ``window.extension("measure")``."""
    tools = MeasureTools(window)
    window.add_extension("measure", tools)
    return tools
