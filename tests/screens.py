"""Pictures for the GUI tests: Qt images as arrays, a widget's place on the screen as the X
server shows it (3-D views included), and a heartbeat that measures how long the event loop
stalls."""

from __future__ import annotations

import time

import numpy as np
from PyQt6.QtCore import QElapsedTimer, QObject, QPoint, QTimer
from PyQt6.QtGui import QGuiApplication, QImage
from PyQt6.QtWidgets import QWidget


def image_array(image: QImage) -> np.ndarray:
    """``(h, w, 3)`` uint8 RGB of a QImage."""
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    ptr = image.constBits()
    ptr.setsize(image.sizeInBytes())
    rows = np.frombuffer(ptr, np.uint8).reshape(image.height(), image.bytesPerLine())
    return rows[:, : 3 * image.width()].reshape(image.height(), image.width(), 3).copy()


def on_screen(widget: QWidget) -> np.ndarray:
    """What the screen shows where ``widget`` is (the X server's pixels: an OpenGL view's too)."""
    p = widget.mapToGlobal(QPoint(0, 0))
    pix = QGuiApplication.primaryScreen().grabWindow(0, p.x(), p.y(), widget.width(), widget.height())
    return image_array(pix.toImage())


def place_in(shot: np.ndarray, widget: QWidget, top: QWidget) -> np.ndarray:
    """The part of ``shot`` (a picture of ``top``) where ``widget`` is."""
    p = widget.mapTo(top, QPoint(0, 0))
    return shot[p.y():p.y() + widget.height(), p.x():p.x() + widget.width()]


class Heartbeat(QObject):
    """A 10 ms timer that records the longest gap between its ticks: how long the event loop
    was held up (a stall) while it ran; and, for the same gaps, how much of it the GUI thread
    spent working (its CPU time: the part that is the program's, not the machine's load)."""

    def __init__(self, interval_ms: int = 10):
        super().__init__()
        self.timer = QTimer(self)
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self._beat)
        self.clock = QElapsedTimer()
        self.last = 0
        self.last_cpu = 0.0
        self.longest = 0            # ms, wall time
        self.longest_cpu = 0        # ms, the GUI thread's CPU time within one gap

    def start(self) -> None:
        self.clock.start()
        self.last, self.longest, self.longest_cpu = 0, 0, 0
        self.last_cpu = time.thread_time()
        self.timer.start()

    def _beat(self) -> None:
        now, cpu = self.clock.elapsed(), time.thread_time()
        self.longest = max(self.longest, now - self.last)
        self.longest_cpu = max(self.longest_cpu, int(round(1000 * (cpu - self.last_cpu))))
        self.last, self.last_cpu = now, cpu

    def stop(self) -> int:
        """Stop; the longest gap in ms (wall time)."""
        self._beat()
        self.timer.stop()
        return self.longest
