"""Measure: how far apart the lips are, at the cursor and per phone (an extension of the main
window; the numbers from ``app/measure_model.py`` and the engine).

* The **readout** under the window (a bottom toolbar) follows the cursor: the phone and word
  there, the upper and lower lip y and the aperture of the synthesis in 3-D, the original's and
  the difference, and each pinned result's, in mm.
* **Analysis → Measure: lip aperture per phone…** opens a dock with each phone's aperture at its
  minimum and its midpoint, original, synthesized and error, and a column per pinned result (its
  least aperture over the same segment, and this minus it): sortable, filtered by phone
  (``b p m``), exported as CSV; a click goes to the phone's minimum. Under it, **across the
  corpus**: the result on screen and each pin made again (their settings and label sources) on
  every utterance of a split, summed up per phone and written as CSV
  (``facetraj_engine.analysis.phone_compare``).
"""

from __future__ import annotations

from pathlib import Path

from PyQt6.QtCore import QSize, Qt
from PyQt6.QtWidgets import (
    QComboBox,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSizePolicy,
    QSpinBox,
    QTableWidget,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.analysis.articulators import jaw_top
from facetraj_engine.analysis.phone_compare import (
    ComparedPhone,
    Recipe,
    corpus_comparison,
    phone_means,
    write_comparison_csv,
)

from .analysis.common import NumberItem, compact_headers, export_with_dialog, fill_table, text_item
from .measure_model import TABLE_COLUMNS, Measure

#: the table's columns up to the minima's (the pins' columns follow them)
MIN_COLUMNS = 1 + max(i for i, c in enumerate(TABLE_COLUMNS) if c[1].startswith("min_"))
#: the splits a corpus-wide comparison runs over
RUN_SPLITS = {"test": ("test",), "train": ("train",), "train + test": ("test", "train")}


def two_lines(heading: str) -> str:
    r"""A table heading as shown: on two lines, as narrow as its longer line (the columns then
    fit a laptop's dock); a pin's difference column without its "min: " (its pin's column
    beside it says so). The whole heading is the header's tooltip.

    >>> two_lines("min: this − pin 1"), two_lines("start (s)"), two_lines("min: synth."), two_lines("phone")
    ('this −\npin 1', 'start\n(s)', 'min:\nsynth.', 'phone')
    """
    words = heading.removeprefix("min: this − ").split(" ")
    if len(words) < len(heading.split(" ")):
        words = ["this", "−", *words]
    if len(words) < 2:
        return heading
    best = min(range(1, len(words)), key=lambda k: max(len(" ".join(words[:k])), len(" ".join(words[k:]))))
    return " ".join(words[:best]) + "\n" + " ".join(words[best:])


class ApertureTable(QWidget):
    """The per-phone apertures of the utterance on screen: a filter, the table, CSV export."""

    def __init__(self, measure: Measure, seek, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.measure = measure
        self.seek = seek
        self.filter = QLineEdit()
        self.filter.setPlaceholderText("phones to show, e.g. b p m (empty: all)")
        self.filter.setClearButtonEnabled(True)
        self.filter.textChanged.connect(lambda _t: self.refresh())
        self.export_button = QPushButton("Export CSV…")
        self.export_button.clicked.connect(self._export)
        top = QHBoxLayout()
        top.addWidget(QLabel("phones:"))
        top.addWidget(self.filter, 1)
        top.addWidget(self.export_button)
        self.note = QLabel("")
        self.note.setWordWrap(True)
        self.table = QTableWidget()
        self.table.setSortingEnabled(True)
        self.table.verticalHeader().setVisible(False)
        self.table.setSelectionBehavior(QTableWidget.SelectionBehavior.SelectRows)
        self.table.cellClicked.connect(self._clicked)
        self.corpus = CorpusRun(measure, self.filter, window) if window is not None else None
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)          # the table as wide as the dock allows
        lay.addLayout(top)
        lay.addWidget(self.note)
        lay.addWidget(self.table, 1)
        if self.corpus is not None:
            lay.addWidget(self.corpus)
            self.filter.textChanged.connect(lambda _t: self.corpus.show_summary())

    def refresh(self) -> None:
        """The rows of the filter's phones; the headings on two lines, and a column no row has a
        value in left out of view (the words of recognized phones, the original's and the
        errors of a recording without markers), so that a laptop's dock shows the pins' columns
        beside the minima (they were past its edge: 434 of 779 px in view, the word column
        empty)."""
        items = []
        rows = self.measure.rows(self.filter.text())
        for r, mins in zip(rows, self.measure.pin_minima(rows), strict=True):
            row = []
            for _head, attribute, fmt in TABLE_COLUMNS:
                v = getattr(r, attribute)
                row.append(text_item(v) if isinstance(v, str) else NumberItem(v, fmt))
            pinned = [item for m in mins for item in (NumberItem(m, "{:.1f}"),       # each pin's least
                                                      NumberItem(r.min_synthesized - m, "{:+.1f}"))]
            row[MIN_COLUMNS:MIN_COLUMNS] = pinned      # aperture, and this minus it, by the minima
            row[0].setData(Qt.ItemDataRole.UserRole + 1, r.min_time)
            items.append(row)
        heads = [c[0] for c in TABLE_COLUMNS]
        heads[MIN_COLUMNS:MIN_COLUMNS] = self.measure.pin_columns()
        fill_table(self.table, [two_lines(h) for h in heads], items)
        for c, head in enumerate(heads):
            self.table.horizontalHeaderItem(c).setToolTip(head)
        for c in range(self.table.columnCount()):       # no words, no original: no column
            self.table.setColumnHidden(c, bool(items) and not any(row[c].text() for row in items))
        compact_headers(self.table)
        words = any(r.word for r in rows)
        view = self.measure.view
        has_original = view is not None and view.original is not None
        pins = ("; pins: their least aperture over the same segment, and this minus it"
                if self.measure.pins else "; pin a result (Ctrl+P) to compare: a column each")
        self.note.setText("Lip aperture (mm, upper to lower lip centre) at each phone's minimum "
                          "and midpoint, original (orig.) and synthesized (synth.); error = "
                          "synthesized − original" + pins + ". A click on "
                          "a row goes to its minimum." + ("" if has_original or view is None else
                                                          " No original markers here.")
                          + ("" if words or not rows else " No words: the labels are phones alone."))

    def column(self, heading: str) -> int:
        """The table's column of ``heading`` (as ``TABLE_COLUMNS`` and ``pin_columns`` name it)."""
        heads = [self.table.horizontalHeaderItem(c).toolTip() for c in range(self.table.columnCount())]
        return heads.index(heading)

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


class CorpusRun(QGroupBox):
    """The per-phone comparison across the corpus: the result on screen and each pin made again
    (their settings and label sources: ``Measure.recipes``) on the utterances of a split, in the
    window's worker with progress; per phone (the filter's), the mean least aperture of the
    original and of each result; the rows exported as CSV."""

    def __init__(self, measure: Measure, phone_filter: QLineEdit, window):
        super().__init__("Across the corpus: this result and the pins, per phone")
        # (not ``self.window``: a widget's ``window()`` is Qt's, which the dialogs use)
        self.measure, self.phone_filter, self.host = measure, phone_filter, window
        self.rows: list[ComparedPhone] = []
        self.recipes: list[Recipe] = []
        self.split = QComboBox()
        self.split.addItems(list(RUN_SPLITS))
        self.count = QSpinBox()
        self.count.setRange(0, 10000)
        self.count.setValue(10)
        self.count.setSuffix(" utterances")
        self.count.setSpecialValueText("all utterances")
        self.count.setToolTip("utterances of each split (all: the whole split)")
        self.run_button = QPushButton("Run")
        self.run_button.clicked.connect(self.run)
        self.export_button = QPushButton("Export CSV…")
        self.export_button.clicked.connect(self._export)
        self.export_button.setEnabled(False)
        top = QHBoxLayout()                 # short rows: the dock of a laptop shows them whole
        for w in (self.split, self.count, self.run_button):
            top.addWidget(w)
        top.addStretch(1)
        bottom = QHBoxLayout()
        bottom.addStretch(1)
        bottom.addWidget(self.export_button)
        self.summary = QTableWidget()
        self.summary.verticalHeader().setVisible(False)
        self.summary.setMinimumHeight(4 * self.summary.fontMetrics().height() + 30)
        self.note = QLabel("Run: this result and each pin made again, with their settings and "
                           "labels, on each utterance")
        self.note.setWordWrap(True)
        lay = QVBoxLayout(self)
        lay.addLayout(top)
        lay.addWidget(self.note)
        lay.addWidget(self.summary)
        lay.addLayout(bottom)

    def ids(self) -> list[tuple[str, str]]:
        info, n = self.host.corpus.info, self.count.value() or None
        return [(s, u) for s in RUN_SPLITS[self.split.currentText()] for u in getattr(info, s)[:n]]

    def run(self) -> None:
        """Compare the results on the chosen utterances (in a worker; the status bar shows it)."""
        w = self.host
        recipes, ids = self.measure.recipes(), self.ids() if w.corpus is not None else []
        if not recipes or not ids:
            w.show_status("nothing to compare: no result shown or no corpus", 6000)
            return
        model, corpus, texts = w.model, w.corpus, dict(w.state.texts)
        self.run_button.setEnabled(False)

        def done(rows: list[ComparedPhone]) -> None:
            self.run_button.setEnabled(True)
            self.rows, self.recipes = rows, recipes
            self.export_button.setEnabled(bool(rows))
            self.show_summary()
            w.show_status(f"compared {len(recipes)} results at {len(rows)} phone segments of "
                          f"{len({r.utterance for r in rows})} utterances")

        def failed(exc: BaseException) -> None:
            self.run_button.setEnabled(True)
            w.report_error(exc)

        w.run_task(lambda p: list(corpus_comparison(model, corpus, recipes, ids, texts, p)), done,
                   "comparing the results across the corpus", on_error=failed)

    def wanted(self) -> list[str]:
        return self.phone_filter.text().lower().replace(",", " ").replace("/", " ").split()

    def shown_rows(self) -> list[ComparedPhone]:
        wanted = set(self.wanted())
        return [r for r in self.rows if not wanted or r.phone in wanted]

    def show_summary(self) -> None:
        """Per phone of the filter (all without one): segments, and the mean least aperture of
        the original and of each result."""
        if not self.recipes:
            return
        means = phone_means(self.rows, self.wanted())
        items = [[text_item(m.phone), NumberItem(m.segments, "{:.0f}"), NumberItem(m.original, "{:.1f}"),
                  *(NumberItem(v, "{:.1f}") for v in m.results)] for m in means]
        fill_table(self.summary, ["phone", "segments", "original", *(r.name for r in self.recipes)],
                   items)
        utts = len({r.utterance for r in self.rows})
        self.note.setText(f"Mean least aperture (mm) at each phone of {utts} utterances (their own "
                          "labels); the results' settings: hover the table")
        self.summary.setToolTip("\n".join(f"{r.name}: {r.settings}" for r in self.recipes))

    def export_csv(self, path: str | Path) -> Path:
        return write_comparison_csv(path, self.shown_rows(), self.recipes)

    def _export(self) -> None:
        export_with_dialog(self, "Export the comparison across the corpus", "phone_comparison.csv",
                           "CSV (*.csv)", self.export_csv)


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
            self.table = ApertureTable(self.measure, self.window.seek, self.window)
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
