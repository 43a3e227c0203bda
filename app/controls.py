"""The main window's controls: the bars above and below the 3-D view (camera and display
options; the transport), the loop range, keyboard shortcuts and the File-menu dialogs.

:class:`ViewBar` drives a :class:`~app.view3d.FaceView` directly; :class:`TransportBar` only emits
signals, which the main window wires to the playback clock.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PyQt6.QtCore import Qt, pyqtSignal
from PyQt6.QtGui import QKeySequence, QShortcut
from PyQt6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QStyle,
    QToolButton,
    QWidget,
)

from .style import ORIGINAL_COLOR, SYNTH_COLOR
from .timeline import Timeline
from .transport import PlaybackClock
from .view3d import CAMERA_PRESETS, FaceView

SPEEDS = (1.0, 0.5, 0.25)


class ViewBar(QWidget):
    """Camera presets, the marker colour legend, and which point sets / the surface to show."""

    def __init__(self, face: FaceView, parent: QWidget | None = None):
        super().__init__(parent)
        self.face = face
        lay = QHBoxLayout(self)
        lay.setContentsMargins(4, 0, 4, 0)
        lay.addWidget(QLabel("camera:"))
        self.camera_buttons: dict[str, QToolButton] = {}
        for name in CAMERA_PRESETS:
            b = QToolButton()
            b.setText(name)
            b.setCheckable(True)
            b.setAutoExclusive(True)
            b.clicked.connect(lambda _c=False, n=name: face.set_camera(n))
            lay.addWidget(b)
            self.camera_buttons[name] = b
        self.camera_buttons[face.preset].setChecked(True)
        lay.addSpacing(16)
        legend = QLabel(f'<span style="color:{ORIGINAL_COLOR}; font-size:16px">●</span> original &nbsp; '
                        f'<span style="color:{SYNTH_COLOR}; font-size:16px">●</span> synthesized')
        legend.setToolTip("marker colours in the 3-D view (lines: lip contours; surface: the "
                          "synthesized face)")
        lay.addWidget(legend)
        lay.addSpacing(16)
        self.side_by_side = QCheckBox("side by side")
        self.side_by_side.toggled.connect(face.set_side_by_side)
        self.show_original = QCheckBox("show original")
        self.show_original.setChecked(True)
        self.show_synth = QCheckBox("show synthesized")
        self.show_synth.setChecked(True)
        for cb in (self.show_original, self.show_synth):
            cb.toggled.connect(lambda _c: face.set_sets_visible(self.show_original.isChecked(),
                                                                self.show_synth.isChecked()))
        self.surface = QCheckBox("face surface")
        self.surface.setChecked(True)
        self.surface.toggled.connect(face.set_surface)
        for w in (self.show_original, self.show_synth, self.side_by_side, self.surface):
            w.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            lay.addWidget(w)
        lay.addStretch(1)

    def set_camera(self, name: str) -> None:
        """Use camera preset ``name`` and check its button."""
        self.face.set_camera(name)
        if name in self.camera_buttons:
            self.camera_buttons[name].setChecked(True)


class TransportBar(QWidget):
    """Play / stop / frame steps, the frame slider, the time read-out, speed and loop."""

    playClicked = pyqtSignal()
    stopClicked = pyqtSignal()
    stepClicked = pyqtSignal(int)           # frames
    speedChanged = pyqtSignal(float)

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(4, 0, 4, 0)
        SP = QStyle.StandardPixmap
        self.play_button = self._button(lay, SP.SP_MediaPlay, "play / pause (space)", self.playClicked.emit)
        self._button(lay, SP.SP_MediaStop, "stop", self.stopClicked.emit)
        self._button(lay, SP.SP_MediaSeekBackward, "previous frame (left)", lambda: self.stepClicked.emit(-1))
        self._button(lay, SP.SP_MediaSeekForward, "next frame (right)", lambda: self.stepClicked.emit(1))
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        lay.addWidget(self.slider, 1)
        self.time_label = QLabel("0.000 s")
        self.time_label.setMinimumWidth(300)
        self.time_label.setStyleSheet("font-family: monospace;")
        lay.addWidget(self.time_label)
        self.speed = QComboBox()
        for s in SPEEDS:
            self.speed.addItem(f"{s:g}x", s)
        self.speed.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.speed.setToolTip("playback speed")
        self.speed.currentIndexChanged.connect(lambda _i: self.speedChanged.emit(self.speed.currentData()))
        lay.addWidget(self.speed)
        self.loop_box = QCheckBox("loop")
        self.loop_box.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.loop_box.setToolTip("loop the selected range (drag on the panels to select; Esc clears)")
        lay.addWidget(self.loop_box)

    def _button(self, lay: QHBoxLayout, icon: QStyle.StandardPixmap, tip: str, slot) -> QPushButton:
        b = QPushButton(self.style().standardIcon(icon), "")
        b.setToolTip(tip)
        b.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        b.clicked.connect(lambda _c=False: slot())
        lay.addWidget(b)
        return b

    def set_playing(self, playing: bool) -> None:
        icon = QStyle.StandardPixmap.SP_MediaPause if playing else QStyle.StandardPixmap.SP_MediaPlay
        self.play_button.setIcon(self.style().standardIcon(icon))

    def set_frames(self, n_frames: int) -> None:
        self.slider.blockSignals(True)
        self.slider.setRange(0, n_frames - 1)
        self.slider.blockSignals(False)

    def show_frame(self, frame: int, text: str) -> None:
        """Move the slider (without signalling a seek) and set the read-out."""
        self.slider.blockSignals(True)
        self.slider.setValue(frame)
        self.slider.blockSignals(False)
        self.time_label.setText(text)


def add_shortcuts(widget: QWidget,
                  bindings: list[tuple[QKeySequence, Callable[[], object]]]) -> list[QShortcut]:
    """Window-wide keyboard shortcuts on ``widget``."""
    shortcuts = []
    for seq, slot in bindings:
        sc = QShortcut(seq, widget)
        sc.setContext(Qt.ShortcutContext.WindowShortcut)
        sc.activated.connect(slot)
        shortcuts.append(sc)
    return shortcuts


class LoopRange:
    """The loop range: kept by the clock, drawn on the timeline, switched by the loop box; a drag
    on the timeline selects it (and seeks to its start)."""

    def __init__(self, clock: PlaybackClock, timeline: Timeline, box: QCheckBox,
                 seek: Callable[[float], None]):
        self.clock, self.timeline, self.box, self.seek = clock, timeline, box, seek
        box.toggled.connect(self._on_toggled)
        timeline.loopSelected.connect(self.select)

    def select(self, a: float, b: float) -> None:
        self.clock.set_loop(a, b)
        self.box.setChecked(True)
        self.seek(a)

    def clear(self) -> None:
        self.box.setChecked(False)
        self.clock.set_loop(None)
        self.timeline.set_loop(None)

    def _on_toggled(self, on: bool) -> None:
        self.clock.looping = bool(on)
        if not on:
            self.timeline.set_loop(None)
        elif self.clock.loop is not None:
            self.timeline.set_loop(self.clock.loop)


def ask_corpus_folder(parent: QWidget) -> tuple[Path] | None:
    path = QFileDialog.getExistingDirectory(parent, "Open a corpus folder")
    return (Path(path),) if path else None


def ask_audio_and_labels(parent: QWidget) -> tuple[Path, Path | None] | None:
    """An audio file, then its phone labels (Cancel: none, acoustic-only synthesis)."""
    audio, _ = QFileDialog.getOpenFileName(parent, "Open audio for synthesis", "",
                                           "Audio (*.wav *.flac);;All files (*)")
    if not audio:
        return None
    labels, _ = QFileDialog.getOpenFileName(
        parent, "Phone labels (Cancel: acoustic-only synthesis)", str(Path(audio).parent),
        "Labels (*.TextGrid *.lab *.phn);;All files (*)")
    return Path(audio), Path(labels) if labels else None


def ask_screenshot_path(parent: QWidget) -> tuple[Path] | None:
    path, _ = QFileDialog.getSaveFileName(parent, "Save a screenshot", "facetraj.png", "PNG (*.png)")
    return (Path(path),) if path else None
