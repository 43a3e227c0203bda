"""The codebook inspector: why the frame at the cursor looks as it does (paper eqs 4-8).

The current phone and its context-phone, the top-N context-phones chosen with their n_j scores
(eq 4), the 5N candidate codewords with their distances d_i (eq 5) and weights v_i (eq 6), the
chosen gamma, and the input LSF vector w against its approximation w-hat (eq 7). In the robust
mode (``facetraj_engine.method.selection``) each candidate also shows why it was chosen: its target cost (eq 5
with acoustic context), its label cost (kappa times the label's confidence, when eq 4 did not
choose it) and whether eq 4 chose it; the frame's label confidence is shown above. Every number is
from :func:`facetraj_engine.analysis.inspector.inspect_frame`.
"""

from __future__ import annotations

import logging
from functools import partial

import numpy as np
from matplotlib.figure import Figure
from PyQt6.QtCore import Qt, QTimer, pyqtSignal
from PyQt6.QtWidgets import (
    QFormLayout,
    QLabel,
    QSplitter,
    QTableWidget,
    QVBoxLayout,
    QWidget,
)

from facetraj_app.style import ORIGINAL_COLOR, SYNTH_COLOR
from facetraj_engine.analysis.inspector import FrameInspection, inspect_frame
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import Synthesis

from .common import Canvas, NumberItem, WindowLinks, fill_table, heat_item, text_item

log = logging.getLogger(__name__)

UPDATE_MS = 120


class CodebookInspector(QWidget):
    """Eqs 4-8 at one frame of a synthesis."""

    inspected = pyqtSignal(object)        # the FrameInspection shown

    def __init__(self, model: Model, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.model = model
        self.window_ = window
        self.synthesis: Synthesis | None = None
        self.current: FrameInspection | None = None
        self._shown: Synthesis | None = None
        self._pending: int | None = None
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(UPDATE_MS)
        self._timer.timeout.connect(self._flush)

        self.frame_label = QLabel("-")
        self.phone_label = QLabel("-")
        self.context_label = QLabel("-")
        self.gamma_label = QLabel("-")
        self.error_label = QLabel("-")
        self.sum_label = QLabel("-")
        self.confidence_label = QLabel("-")
        for lab in (self.context_label, self.phone_label):
            lab.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        form = QFormLayout()
        form.addRow("frame:", self.frame_label)
        form.addRow("phone:", self.phone_label)
        form.addRow("context-phone:", self.context_label)
        form.addRow("gamma (eqs 6-7):", self.gamma_label)
        form.addRow("sum v_i:", self.sum_label)
        form.addRow("label confidence:", self.confidence_label)
        form.addRow("LSF error |w - w-hat|_h:", self.error_label)

        self.chosen_table = QTableWidget()
        self.chosen_table.setSortingEnabled(True)
        self.chosen_table.verticalHeader().setVisible(False)
        self.codeword_table = QTableWidget()
        self.codeword_table.setSortingEnabled(True)
        self.codeword_table.verticalHeader().setVisible(False)
        self.canvas = Canvas(6, 3.2)

        split = QSplitter(Qt.Orientation.Vertical)
        top = QWidget()
        tl = QVBoxLayout(top)
        tl.setContentsMargins(0, 0, 0, 0)
        tl.addLayout(form)
        tl.addWidget(QLabel("top-N context-phones (eq 4):"))
        tl.addWidget(self.chosen_table)
        split.addWidget(top)
        mid = QWidget()
        ml = QVBoxLayout(mid)
        ml.setContentsMargins(0, 0, 0, 0)
        ml.addWidget(QLabel("candidate codewords, heaviest first (eqs 5-6):"))
        ml.addWidget(self.codeword_table)
        split.addWidget(mid)
        split.addWidget(self.canvas)
        split.setSizes([260, 300, 260])
        lay = QVBoxLayout(self)
        lay.addWidget(split)

        self.links = WindowLinks()
        if window is not None:
            self.links.connect(window.synthesisChanged, self._from_window)
            self.links.connect(window.cursorMoved, self.set_time)
            self._from_window()

    def close_view(self) -> None:
        """Stop following the window (another model replaces this view)."""
        self.links.close()

    # ------------------------------------------------------------------ input
    def _from_window(self) -> None:
        view = getattr(self.window_, "view", None)
        if view is not None:
            self.set_synthesis(view.synthesis, self.window_.current_time())

    def set_synthesis(self, synthesis: Synthesis | None, time: float = 0.0) -> None:
        self.synthesis = synthesis
        if synthesis is not None:
            self.set_time(time)

    def set_time(self, t: float) -> None:
        """Inspect the frame at ``t`` seconds; updates are coalesced (at most one per
        ``UPDATE_MS``) and wait while the inspector is hidden, so playback is not slowed down."""
        if self.synthesis is None or len(self.synthesis.times) == 0:
            return
        self._pending = int(round(float(t) * self.model.marker_rate))
        if not self._timer.isActive():
            self._timer.start()

    def _flush(self) -> None:
        if self._pending is None:
            return
        if not self.isVisible() and self.current is not None:
            return                       # showEvent flushes
        frame, self._pending = self._pending, None
        self.set_frame(frame)

    def showEvent(self, event) -> None:
        super().showEvent(event)
        self._flush()

    def set_frame(self, frame: int) -> None:
        if self.synthesis is None:
            return
        frame = int(np.clip(frame, 0, len(self.synthesis.times) - 1))
        if self.current is not None and self.current.frame == frame and \
                self.current.time == float(self.synthesis.times[frame]) and self._shown is self.synthesis:
            return
        self._shown = self.synthesis
        self.show_inspection(inspect_frame(self.model, self.synthesis, frame))

    # ------------------------------------------------------------------ display
    def show_inspection(self, ins: FrameInspection) -> None:
        self.current = ins
        self.frame_label.setText(f"{ins.frame}  (t = {ins.time:.3f} s)")
        self.phone_label.setText(ins.phone or "(acoustic-only synthesis: no phone)")
        self.context_label.setText(ins.context or "-")
        self.gamma_label.setText(f"{ins.gamma:.3f}")
        self.error_label.setText(f"{ins.error:.4f}")
        self.sum_label.setText(f"{ins.weight_sum:.6f}")
        rows = [[NumberItem(i + 1, "{:.0f}"), text_item(txt), NumberItem(score, "{:.4f}"),
                 NumberItem(idx, "{:.0f}")] for i, (txt, score, idx) in enumerate(ins.chosen)]
        fill_table(self.chosen_table, ["rank", "context-phone", "n_j", "codebook entry"], rows)
        robust = ins.mode == "robust"
        self.confidence_label.setText(
            f"{ins.confidence:.3f} (1 = the labels count fully)" if robust
            else "- (robust mode only)")
        vmax = max((c.weight for c in ins.codewords), default=1.0)
        rows = [[heat_item(c.weight, 0.0, vmax, "{:.4f}"),
                 NumberItem(c.distance, "{:.3f}"), text_item(c.context),
                 NumberItem(c.position + 1, "{:.0f}"), text_item(c.utterance),
                 NumberItem(c.time, "{:.3f}"), NumberItem(c.index, "{:.0f}")]
                + ([NumberItem(c.target_cost, "{:.3f}"), NumberItem(c.label_cost, "{:.3f}"),
                    text_item("eq 4" if c.from_labels else "acoustic")] if robust else [])
                for c in ins.codewords]
        fill_table(self.codeword_table, ["v_i", "d_i", "context-phone", "codeword (1-5)",
                                         "from utterance", "at (s)", "index i"]
                   + (["target cost", "label cost", "chosen by"] if robust else []), rows)
        self._draw(ins)
        self.inspected.emit(ins)

    def _draw(self, ins: FrameInspection) -> None:
        """The LSF barcodes and the weights (built and drawn off the GUI thread)."""
        self.canvas.rebuild(partial(draw_inspection, ins=ins,
                                    nyquist=self.model.config.audio_rate / 2))


def draw_inspection(fig: Figure, ins: FrameInspection, nyquist: float) -> None:
    """The input LSF vector w against its approximation w-hat as barcodes on a frequency axis
    (closely spaced pairs mark the formants), and the candidates' weights as bars."""
    fig.clear()
    ax, axw = fig.subplots(1, 2, gridspec_kw={"width_ratios": [3, 2]})
    fig.set_layout_engine("constrained")
    ax.vlines(ins.lsf_hz, 0.52, 0.98, color=ORIGINAL_COLOR, lw=1.6)
    ax.vlines(ins.lsf_hat_hz, 0.02, 0.48, color=SYNTH_COLOR, lw=1.6)
    ax.set_yticks([0.25, 0.75], ["w-hat (eq 7)", "w (input)"], fontsize=7)
    ax.set_ylim(0, 1)
    ax.set_xlim(0, nyquist)
    ax.set_xlabel("LSF frequency (Hz)", fontsize=8)
    ax.set_title(f"LSF vector at {ins.time:.3f} s", fontsize=9)
    ax.tick_params(labelsize=7)
    w = [c.weight for c in ins.codewords]
    axw.bar(np.arange(1, len(w) + 1), w, color=SYNTH_COLOR)
    axw.set_xlabel("codeword (heaviest first)", fontsize=8)
    axw.set_ylabel("v_i", fontsize=8)
    axw.set_title(f"weights, gamma = {ins.gamma:.2f}", fontsize=9)
    axw.tick_params(labelsize=7)
