"""The Live window's phones (issue 27): a rolling phone tier under the lip panels (the phones the
recognizer has settled, confidence as shading, /p b m/ in red), the current latency, the voice
match and what live mode adapts to the voice, the switch between "phones + acoustics" and
acoustic-only, "Open recording..." (a file through live mode), and the take's phones saved as a
TextGrid beside it.

:class:`LatencyMeter` and :class:`PhoneView` are plain objects (tested without a display);
:class:`PhoneTier` draws a :class:`PhoneView`; :class:`PhonePanel` puts it all in the window.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PyQt6.QtCore import QRectF, Qt
from PyQt6.QtGui import QColor, QPainter
from PyQt6.QtWidgets import QComboBox, QLabel, QSizePolicy, QWidget

from facetraj_engine.data import PhoneSegment
from facetraj_engine.labels.phoneset import SILENCE
from facetraj_engine.method.closure import BILABIALS

if TYPE_CHECKING:       # the recognizer is imported with the first take, not with the app
    from facetraj_engine.labels.provenance import Labels
    from facetraj_engine.streaming.live import LiveStream
    from facetraj_engine.streaming.recognizer import RunningCmn

#: the switch's choices
PHONES, ACOUSTIC = "phones + acoustics", "acoustic-only"
#: the tier's colours: phones, /p b m/ (the lips close), silence
COLOURS = {"phone": (31, 119, 180), "bilabial": (214, 39, 40), "sil": (160, 160, 160)}
TIER_TIP = ("phones recognized as they are spoken (settled by the recognizer): the darker, the "
            "more certain; red: /p b m/, where the lips close")


class LatencyMeter:
    """How late the face is: for each frame shown, the wall time since the audio at the
    frame's time arrived (:meth:`arrived` records the audio clock at each poll). The median of
    the last ``keep`` frames is :attr:`current_ms`.

    >>> m = LatencyMeter()
    >>> m.arrived(0.5, wall=10.0); m.arrived(1.0, wall=10.5)
    >>> m.shown(0.8, wall=10.7)          # the audio at 0.8 s came with the poll at 10.5 s
    >>> round(m.current_ms)
    200
    """

    def __init__(self, keep: int = 60):
        self._polls: deque[tuple[float, float]] = deque(maxlen=400)
        self._latency: deque[float] = deque(maxlen=keep)

    def arrived(self, audio_s: float, wall: float | None = None) -> None:
        """The audio up to ``audio_s`` (take seconds) has arrived at ``wall``."""
        self._polls.append((audio_s, time.perf_counter() if wall is None else wall))

    def shown(self, frame_s: float, wall: float | None = None) -> None:
        """The frame at ``frame_s`` goes on screen at ``wall``."""
        wall = time.perf_counter() if wall is None else wall
        for audio_s, at in self._polls:
            if audio_s >= frame_s:
                self._latency.append(wall - at)
                return

    @property
    def current_ms(self) -> float:
        return 1000 * float(np.median(self._latency)) if self._latency else float("nan")


@dataclass
class PhoneView:
    """What the tier shows: the phones in the last ``shown_s`` seconds before ``end_s`` (the
    newest face frame's time), as boxes ``(x0, x1, label, confidence, kind)`` in [0, 1] of the
    tier's width."""

    shown_s: float
    boxes: list[tuple[float, float, str, float, str]] = field(default_factory=list)

    def set(self, segments: list[PhoneSegment], confidence: np.ndarray, end_s: float) -> None:
        """The boxes of ``segments`` (their ``confidence``) seen from ``end_s``.

        >>> v = PhoneView(4.0)
        >>> v.set([PhoneSegment(0, 1, "sil"), PhoneSegment(1, 3, "m")], np.array([1.0, .5]), 4.0)
        >>> [(b[0], b[1], b[2], b[4]) for b in v.boxes]
        [(0.0, 0.25, 'sil', 'sil'), (0.25, 0.75, 'm', 'bilabial')]
        """
        start = end_s - self.shown_s
        self.boxes = []
        for seg, c in zip(segments, confidence, strict=True):
            a, b = max(seg.start, start), min(seg.end, end_s)
            if b <= a:
                continue
            kind = "sil" if seg.label == SILENCE else "bilabial" if seg.label in BILABIALS else "phone"
            self.boxes.append(((a - start) / self.shown_s, (b - start) / self.shown_s, seg.label,
                               float(c) if np.isfinite(c) else 0.5, kind))


class PhoneTier(QWidget):
    """The rolling phone tier, drawn between ``x0`` and ``x1`` (fractions of its width: the lip
    panels' axes)."""

    def __init__(self, shown_s: float, parent: QWidget | None = None):
        super().__init__(parent)
        self.view = PhoneView(shown_s)
        self.x0, self.x1 = 0.1, 0.95
        self.setMinimumHeight(30)
        self.setMaximumHeight(34)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.setToolTip(TIER_TIP)

    def set_span(self, x0: float, x1: float) -> None:
        self.x0, self.x1 = x0, x1

    def paintEvent(self, _event) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(255, 255, 255))
        left, width = self.x0 * self.width(), (self.x1 - self.x0) * self.width()
        h = self.height() - 2
        p.setPen(QColor(0, 0, 0))
        p.drawText(QRectF(0, 0, left - 6, self.height()),
                   Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter, "phones")
        p.setPen(QColor(200, 200, 200))
        p.drawRect(QRectF(left, 0.5, width, h))
        for a, b, label, conf, kind in self.view.boxes:
            rect = QRectF(left + a * width, 1, max(1.0, (b - a) * width), h)
            p.fillRect(rect, QColor(*COLOURS[kind], int(40 + 215 * np.clip(conf, 0, 1))))
            p.setPen(QColor(255, 255, 255))
            p.drawLine(rect.topRight(), rect.bottomRight())
            # a label only where it fits its box whole (never cut, never over the next one)
            if kind != "sil" and p.fontMetrics().horizontalAdvance(label) + 4 <= rect.width():
                p.setPen(QColor(0, 0, 0) if conf < 0.6 else QColor(255, 255, 255))
                p.drawText(rect, Qt.AlignmentFlag.AlignCenter, label)
        p.end()


class PhonePanel:
    """The phones' part of a :class:`facetraj_app.live.LiveWindow`: the switch and "Open recording..." in
    its toolbar, the tier under its lip panels, latency and voice in its status bar; the take's
    phones kept and saved. The recognizer's running cepstral mean is kept from take to take (a
    microphone session adapts once)."""

    def __init__(self, window, toolbar, layout, phones: bool = True, shown_s: float = 4.0):
        self.window = window
        self.switch = QComboBox()
        self.switch.addItems([PHONES, ACOUSTIC])
        self.switch.setCurrentIndex(0 if phones else 1)
        self.switch.setToolTip("phones + acoustics: phones recognized as they are spoken weigh "
                               "the search and close the lips (about 230 ms behind the voice); "
                               "acoustic-only: the paper's search, the face resting in pauses "
                               "(about 130 ms); for the next take")
        toolbar.addWidget(QLabel(" mode: "))
        toolbar.addWidget(self.switch)
        self.open_action = toolbar.addAction("Open recording...", window.open_dialog)
        self.open_action.setToolTip("play a WAV or FLAC file through live mode")
        self.tier = PhoneTier(shown_s)
        layout.addWidget(self.tier)
        self.latency = LatencyMeter()
        self.latency_label = QLabel()
        self.voice_label = QLabel()
        window.statusBar().addPermanentWidget(self.voice_label)
        window.statusBar().addPermanentWidget(self.latency_label)
        self.cmn: RunningCmn | None = None
        self.finished: LiveStream | None = None     # the last take's stream
        self.labels: Labels | None = None
        self.saved: Path | None = None

    @property
    def phones_on(self) -> bool:
        return self.switch.currentText() == PHONES

    def take_started(self) -> None:
        self.switch.setEnabled(False)
        self.labels = self.finished = None
        self.latency = LatencyMeter()

    def new_stream(self, stream: LiveStream) -> None:
        """Keep the stream's running cepstral mean for the next take."""
        if stream.recognizer is not None:
            self.cmn = stream.recognizer.cmn

    def take_finished(self, stream: LiveStream | None, duration: float) -> None:
        """The take ended: its phones are kept (for :meth:`save`)."""
        self.switch.setEnabled(True)
        self.finished = stream
        if stream is not None and duration > 0:
            self.labels = stream.labels(duration)
        self.refresh(None, duration)

    def refresh(self, stream: LiveStream | None, end_s: float) -> None:
        """The tier up to ``end_s`` (the newest frame's time), the latency and the voice."""
        axes = getattr(self.window, "axes", None)
        if axes:
            box = axes[-1].get_position()
            self.tier.set_span(box.x0, box.x1)
        snap = stream.snapshot(max(0.0, end_s - self.tier.view.shown_s)) if stream else None
        if snap is not None:
            self.tier.view.set(snap.segments, snap.confidence, end_s)
        elif self.labels is not None:
            self.tier.view.set(self.labels.phones, self.labels.confidence, end_s)
        self.tier.update()
        ms = self.latency.current_ms
        self.latency_label.setText(f" latency {ms:.0f} ms " if np.isfinite(ms) else "")
        shown = stream or self.finished
        self.voice_label.setText(voice_text(shown) if shown is not None else "")

    def save(self, path: Path, duration: float, overwrite: bool = False) -> Path | None:
        """The take's phones as a TextGrid at ``path`` (none acoustic-only)."""
        if self.labels is None:
            return None
        from facetraj_engine.io.labelling import write_labels

        write_labels(path, self.labels, duration, overwrite)
        self.saved = path
        return path


def voice_text(stream: LiveStream) -> str:
    """The voice match and what live mode adapts, for the status bar."""
    if stream.recognizer is None:
        return " acoustic-only "
    if stream.recognition_error is not None:
        return f" recognition stopped ({stream.recognition_error}): acoustic-only from there "
    ratio, heard = stream.voice_ratio, stream.heard_s
    if not np.isfinite(ratio):
        return f" voice match: measuring ({heard:.1f} s of speech) "
    return (f" voice match {stream.voice_match:.2f} (D/D0 {ratio:.1f}; label weight x"
            f"{stream.label_scale:.1f}, adapted over {heard:.0f} s of speech) ")
