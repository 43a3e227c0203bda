"""``facetraj_app.figure_canvas.BackgroundCanvas``: a draw that finishes after its canvas was deleted."""

from __future__ import annotations

import threading

import pytest

pytest.importorskip("pytestqt")

from matplotlib.artist import Artist
from matplotlib.figure import Figure
from PyQt6 import sip
from PyQt6.QtWidgets import QVBoxLayout, QWidget

from facetraj_app.figure_canvas import BackgroundCanvas

pytestmark = pytest.mark.gui
WAIT_MS = 60_000           # a hang guard, not a speed limit


class _Gate(Artist):
    """An artist whose drawing waits until the test opens the gate (the draw is then running in
    the drawing thread)."""

    def __init__(self) -> None:
        super().__init__()
        self.entered, self.gate = threading.Event(), threading.Event()

    def draw(self, renderer) -> None:
        self.entered.set()
        self.gate.wait(WAIT_MS / 1000)


def test_a_draw_finishing_after_its_canvas_is_deleted_is_dropped(qtbot):
    """The canvas is deleted (its window closed) while its draw runs; the finished draw reaches
    the GUI thread and is dropped, and the next canvas's draw is taken as usual (an exception in
    the delivery would fail the test: pytest-qt raises what a slot raises)."""
    holder = QWidget()
    qtbot.addWidget(holder)
    layout = QVBoxLayout(holder)
    doomed, survivor = BackgroundCanvas(Figure()), BackgroundCanvas(Figure())
    layout.addWidget(doomed)
    layout.addWidget(survivor)
    holder.resize(400, 400)
    holder.show()
    qtbot.waitExposed(holder)
    qtbot.waitUntil(lambda: not doomed.busy and not survivor.busy, timeout=WAIT_MS)  # first draws
    gate = _Gate()
    doomed.figure.add_artist(gate)
    doomed.draw_idle()
    qtbot.waitUntil(gate.entered.is_set, timeout=WAIT_MS)        # its draw is running
    sip.delete(doomed)
    assert sip.isdeleted(doomed)
    gate.gate.set()
    draws = survivor.draws
    with qtbot.waitSignal(survivor.drawn, timeout=WAIT_MS):       # queued after the doomed one
        survivor.draw_idle()
    assert survivor.draws == draws + 1
