"""Kinematics as phoneticians measure them, as panels of the time-aligned stack.

Lip aperture (upper-to-lower lip distance), lip width (corner to corner), protrusion (forward
displacement of the lips from the neutral face) and the tangential velocity of any marker, each for
the original (dotted blue) and the synthesized (orange) trajectories. On the velocity panel the
gesture landmarks (onset, peak velocity, maximum constriction, release peak velocity, offset) are
found by the engine with an adjustable threshold (20 % of the peak by default), for original and
synthesized alike; :class:`KinematicsControls` lists them with the timing error of each landmark,
draws those errors beside the table as bars (one per row) and exports TSV and a TextGrid point
tier.
"""

from __future__ import annotations

import logging
from functools import partial
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from PyQt6.QtCore import Qt, pyqtSignal
from PyQt6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSplitter,
    QTableWidget,
    QVBoxLayout,
    QWidget,
)

from facetraj_app.style import ORIGINAL_COLOR, SYNTH_COLOR, closed_line
from facetraj_engine.analysis.lips import ClosedLips
from facetraj_engine.evaluation.kinematics import (
    LABIAL_PHONES,
    LANDMARKS,
    GestureMeasurement,
    LandmarkError,
    landmark_rows,
    mean_abs_timing_error,
    measure_gestures,
    model_lip_measures,
    write_landmarks_textgrid,
    write_landmarks_tsv,
)
from facetraj_engine.method.model import Model

from .common import (
    Canvas,
    NumberItem,
    WindowLinks,
    bar_labels,
    export_with_dialog,
    fill_table,
    text_item,
)

log = logging.getLogger(__name__)

LANDMARK_MARKERS = {"onset": "^", "pvel": "o", "maxc": "v", "pvel2": "o", "offset": "s"}
#: Bar colours of the timing-error chart: the synthesized landmark late / early.
LATE_COLOR, EARLY_COLOR = "#e8590c", "#1c7ed6"
#: Below this width the chart goes under the table instead of beside it (px).
SIDE_BY_SIDE_WIDTH = 900
MEASURES = {
    "aperture": ("lip aperture", "aperture\n(mm)"),
    "width": ("lip width", "width\n(mm)"),
    "protrusion": ("lip protrusion", "protrusion\n(mm)"),
}


class LipMeasurePanel:
    """Timeline panel: one lip measure (``aperture``, ``width`` or ``protrusion``)."""

    height = 0.9

    def __init__(self, model: Model, measure: str, closed: ClosedLips | None = None):
        if measure not in MEASURES:
            raise ValueError(f"unknown lip measure {measure!r}")
        self.model = model
        self.measure = measure
        self.title = MEASURES[measure][0]
        # the aperture at the talker's closures (``closed``: the distance the 3-D view's mouth
        # shuts at), drawn as a reference
        self.closed = (getattr(model_lip_measures(model, closed.markers[None]), measure)[0]
                       if measure == "aperture" and closed is not None else None)

    def draw(self, ax, view) -> None:
        syn = getattr(model_lip_measures(self.model, view.synthesis.markers), self.measure)
        ax.set_ylabel(MEASURES[self.measure][1], fontsize=8)
        if not np.isfinite(syn).any():          # the lip width of a set without two corners
            ax.text(0.5, 0.5, f"no {self.title}: the markers have no pair of lip corners",
                    transform=ax.transAxes, ha="center", va="center", color="#888888", fontsize=8)
            return
        t = view.times[: len(syn)]
        ax.plot(t, syn, color=SYNTH_COLOR, lw=1.3, label="synthesized (3-D view's)")
        if view.original is not None:
            orig = getattr(model_lip_measures(self.model, view.original), self.measure)
            ax.plot(view.times[: len(orig)], orig, color=ORIGINAL_COLOR, lw=1.3, ls=(0, (2, 1.5)),
                    label="original")
        if self.closed is not None:
            closed_line(ax, self.closed)


class KinematicsControls(QWidget):
    """The velocity panel's settings (marker, threshold, smoothing, gesture phones), the landmark
    table with timing errors, and export."""

    changed = pyqtSignal()
    measured = pyqtSignal(object)           # the GestureMeasurement

    def __init__(self, model: Model, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.model = model
        self.window_ = window
        self.view = None
        self.measurement: GestureMeasurement | None = None
        self._key = None

        self.marker = QComboBox()
        self.marker.addItems(model.marker_names)
        self.marker.setCurrentIndex(model.lower_lip)
        self.threshold = QDoubleSpinBox()
        self.threshold.setRange(1, 90)
        self.threshold.setValue(20)
        self.threshold.setSuffix(" % of peak")
        self.smooth = QDoubleSpinBox()
        self.smooth.setRange(0, 50)
        self.smooth.setValue(15)
        self.smooth.setSuffix(" ms")
        self.smooth.setToolTip("light Gaussian smoothing of the positions before differencing (SD)")
        self.phones = QLineEdit(" ".join(LABIAL_PHONES))
        self.phones.setToolTip("gestures are searched around the segments of these phones")
        for w in (self.marker,):
            w.currentIndexChanged.connect(self._changed)
        for w in (self.threshold, self.smooth):
            w.valueChanged.connect(self._changed)
        self.phones.editingFinished.connect(self._changed)
        form = QFormLayout()
        form.addRow("marker:", self.marker)
        form.addRow("threshold:", self.threshold)
        form.addRow("smoothing:", self.smooth)
        form.addRow("gesture phones:", self.phones)

        self.table = QTableWidget()
        self.table.setSortingEnabled(True)
        self.table.verticalHeader().setVisible(False)
        self.summary = QLabel("")
        self.summary.setWordWrap(True)
        tsv = QPushButton("Export TSV…")
        tsv.clicked.connect(self._export_tsv)
        tg = QPushButton("Export TextGrid…")
        tg.clicked.connect(self._export_textgrid)
        buttons = QHBoxLayout()
        buttons.addWidget(tsv)
        buttons.addWidget(tg)
        buttons.addStretch(1)
        self.chart = Canvas(4, 5)
        self.chart.setMinimumSize(240, 220)
        self.split = QSplitter(Qt.Orientation.Horizontal)
        self.split.addWidget(self.table)
        self.split.addWidget(self.chart)
        self.split.setStretchFactor(0, 3)
        self.split.setStretchFactor(1, 2)
        self.split.setChildrenCollapsible(False)
        lay = QVBoxLayout(self)
        lay.addLayout(form)
        lay.addWidget(self.summary)
        lay.addWidget(self.split, 1)
        lay.addLayout(buttons)
        self.rows: list[LandmarkError] = []

        self.panel = VelocityPanel(self)
        self.links = WindowLinks()
        if window is not None:
            # undone by close_view (another model replaces the view: a lambda kept calling its
            # deleted widgets with the new model's results)
            self.links.connect(window.synthesisChanged, self._window_result)
            if window.view is not None:
                self.set_view(window.view)

    # ------------------------------------------------------------------ settings
    @property
    def marker_index(self) -> int:
        return self.marker.currentIndex()

    @property
    def threshold_fraction(self) -> float:
        return float(self.threshold.value()) / 100.0

    @property
    def smooth_s(self) -> float:
        return float(self.smooth.value()) / 1000.0

    @property
    def gesture_labels(self) -> list[str]:
        return self.phones.text().split()

    def _changed(self) -> None:
        if self.view is not None:
            self.measure(self.view)
        self.changed.emit()
        tl = getattr(self.window_, "timeline", None)
        if tl is not None and self.panel in tl.panels:
            tl.relayout(tl.xlim(), soon=True)

    # ------------------------------------------------------------------ measuring
    def _window_result(self) -> None:
        self.set_view(self.window_.view)

    def close_view(self) -> None:
        """Stop following the window (another model replaces this view)."""
        self.links.close()

    def set_view(self, view) -> None:
        self.view = view
        if view is not None:
            self.measure(view)

    def measure(self, view) -> GestureMeasurement:
        """The engine's gesture measurement for ``view`` with the current settings (cached)."""
        key = (id(view), self.marker_index, self.threshold_fraction, self.smooth_s,
               tuple(self.gesture_labels))
        if key == self._key and self.measurement is not None:
            return self.measurement
        m = measure_gestures(view.synthesis.markers, view.original, self.marker_index, view.rate,
                             view.utterance.phones, self.gesture_labels, self.threshold_fraction,
                             self.smooth_s, t0=float(view.times[0]))
        self._key = key
        self.measurement = m
        self._fill(m)
        self.measured.emit(m)
        return m

    def _fill(self, m: GestureMeasurement) -> None:
        self.rows = landmark_rows(m)
        table = [[NumberItem(r.gesture, "{:.0f}"), text_item(r.label), text_item(r.landmark),
                  NumberItem(r.original, "{:.3f}"), NumberItem(r.synthesized, "{:.3f}"),
                  NumberItem(1000 * r.error, "{:+.0f}")] for r in self.rows]
        if m.v_original is not None:
            mae = mean_abs_timing_error(m.pairs())
            self.summary.setText("mean |timing error| (ms): " + ", ".join(
                f"{k} {1000 * v:.0f}" for k, v in mae.items()))
        else:
            self.summary.setText("no original markers: synthesized landmarks only")
        fill_table(self.table, ["gesture", "phone", "landmark", "original (s)", "synthesized (s)",
                                "error (ms)"], table)
        self._draw_chart(m)

    def _draw_chart(self, m: GestureMeasurement) -> None:
        """The timing error of every landmark row as a horizontal bar (synthesized minus original,
        ms; late to the right), in the table's order from the top (built and drawn off the GUI
        thread)."""
        self.chart.rebuild(partial(draw_timing_chart, rows=list(self.rows),
                                   has_original=m.v_original is not None))

    def resizeEvent(self, event) -> None:
        """The chart beside the table when there is room, under it when the dock is narrow."""
        super().resizeEvent(event)
        wide = self.width() >= SIDE_BY_SIDE_WIDTH
        want = Qt.Orientation.Horizontal if wide else Qt.Orientation.Vertical
        if self.split.orientation() != want:
            self.split.setOrientation(want)

    # ------------------------------------------------------------------ export
    def _sources(self) -> dict:
        m = self.measurement
        if m is None:
            raise ValueError("no utterance measured yet")
        out = {}
        if m.v_original is not None:
            out["original"] = m.original
        out["synthesized"] = m.synthesized
        return out

    def export_tsv(self, path: str | Path) -> Path:
        return write_landmarks_tsv(path, self._sources(), self.model.marker_names[self.marker_index])

    def export_textgrid(self, path: str | Path) -> Path:
        return write_landmarks_textgrid(path, self._sources(), self.view.utterance.duration)

    def _export(self, title: str, default: str, filters: str, fn) -> None:
        name = self.view.utterance.name if self.view is not None else "landmarks"
        export_with_dialog(self, title, f"{name}_{default}", filters, fn)

    def _export_tsv(self) -> None:
        self._export("Export landmarks", "landmarks.tsv", "TSV (*.tsv)", self.export_tsv)

    def _export_textgrid(self) -> None:
        self._export("Export landmarks as TextGrid", "landmarks.TextGrid", "TextGrid (*.TextGrid)",
                     self.export_textgrid)


def draw_timing_chart(fig: Figure, rows: list[LandmarkError], has_original: bool) -> None:
    """The landmark timing errors as horizontal bars, or why there are none."""
    fig.clear()
    ax = fig.add_subplot(111)
    rows = [r for r in rows if np.isfinite(r.error)]
    if not rows:
        why = ("no original markers:\nno timing errors to show" if not has_original else
               "no gestures found around\nthe gesture phones")
        ax.text(0.5, 0.5, why, ha="center", va="center", transform=ax.transAxes,
                color="#555555", fontsize=10)
        ax.set_axis_off()
        return
    ms = np.array([1000 * r.error for r in rows])
    y = np.arange(len(rows))[::-1]
    ax.barh(y, ms, color=[LATE_COLOR if e > 0 else EARLY_COLOR for e in ms],
            edgecolor="#555555", lw=0.4, height=0.75)
    labels, size = bar_labels(fig, [f"{r.gesture} {r.label} {r.landmark}" for r in rows])
    ax.set_yticks(y, labels, fontsize=size)
    ax.set_ylim(-0.6, len(rows) - 0.4)
    lim = max(10.0, float(np.abs(ms).max()) * 1.1)
    ax.set_xlim(-lim, lim)
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_xlabel("synthesized − original (ms)\n← early    late →", fontsize=8)
    ax.tick_params(axis="x", labelsize=8)
    ax.set_title("Landmark timing error", fontsize=10)
    ax.grid(axis="x", alpha=0.3)
    fig.set_layout_engine("constrained")   # laid out again at every draw: resizes keep the labels in


class VelocityPanel:
    """Timeline panel: tangential velocity of the chosen marker with its gesture landmarks
    (original above, synthesized below each gesture) and the threshold levels."""

    height = 1.2

    def __init__(self, controls: KinematicsControls):
        self.controls = controls

    @property
    def title(self) -> str:
        return f"tangential velocity {self.controls.model.marker_names[self.controls.marker_index]}"

    def draw(self, ax, view) -> None:
        m = self.controls.measure(view)
        ax.plot(m.times, m.v_synthesized, color=SYNTH_COLOR, lw=1.2, label="synthesized (3-D view's)")
        sets = [(m.synthesized, SYNTH_COLOR, 0.08)]
        if m.v_original is not None:
            ax.plot(m.times, m.v_original, color=ORIGINAL_COLOR, lw=1.2, ls=(0, (2, 1.5)),
                    label="original")
            sets.insert(0, (m.original, ORIGINAL_COLOR, 0.92))
        xt = ax.get_xaxis_transform()
        for gestures, color, y in sets:
            if not gestures:
                continue
            # one artist per landmark kind and per line kind (NaN separates the gestures)
            spans = [x for g in gestures for x in (g.onset, g.offset, np.nan)]
            ax.plot(spans, [y if np.isfinite(x) else np.nan for x in spans], color=color, lw=0.8,
                    alpha=0.7, transform=xt, clip_on=True)
            for k in LANDMARKS:
                times = [getattr(g, k) for g in gestures]
                ax.plot(times, [y] * len(times), LANDMARK_MARKERS[k], color=color, ms=4.5, transform=xt,
                        clip_on=True, mfc=color if k in ("pvel", "pvel2", "maxc") else "none", ls="none")
            lx, ly = [], []
            for g in gestures:
                on, off = m.levels(g)
                lx += [g.onset, g.pvel, np.nan, g.pvel2, g.offset, np.nan]
                ly += [on, on, np.nan, off, off, np.nan]
            ax.plot(lx, ly, color=color, lw=0.6, alpha=0.6)
        ax.set_ylabel(f"{self.controls.model.marker_names[m.marker]}\nspeed (mm/s)", fontsize=8)
        ax.set_ylim(bottom=0)           # the curves' names: in the timeline's legend row
