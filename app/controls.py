"""The main window's controls: the bars above and below the 3-D view (camera and display
options; the transport), the loop range, keyboard shortcuts and the File-menu dialogs.

:class:`ViewBar` drives a :class:`~facetraj_app.view3d.FaceView` directly; :class:`TransportBar` only emits
signals, which the main window wires to the playback clock.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PyQt6.QtCore import Qt, pyqtSignal
from PyQt6.QtGui import QColor, QIcon, QKeySequence, QPainter, QPixmap, QShortcut
from PyQt6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFileDialog,
    QFrame,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QSlider,
    QStyle,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from .face_scene import CAMERA_PRESETS, CLOSE_UP
from .flow_layout import FlowLayout, flow_row
from .style import ORIGINAL_COLOR, SYNTH_COLOR
from .timeline import Timeline
from .transport import PlaybackClock
from .view3d import FaceView

SPEEDS = (1.0, 0.5, 0.25)
#: between the title's first line and the details (``facetraj_app.viewer_model.view_title``)
TITLE_SEPARATOR = "    ·    "
#: the camera buttons' texts (short: the bar fits a narrow 3-D view)
CAMERA_LABELS = {"three-quarter": "¾", CLOSE_UP: "lips"}
#: their tooltips
CAMERA_TIPS = {"three-quarter": "camera: three-quarter view",
               CLOSE_UP: "close-up of the lips, front on: each face's lips alone, as large as the "
                         "view allows (a closure judged on a laptop screen too)"}
#: the read-out the time label is sized for (``MainWindow._show_time`` writes it); a longer one
#: (a file over 100 s) widens it once
TIME_TEMPLATE = "00.000 / 00.000 s  frame 0000  /xxx/"
#: the frame slider's least width: narrower, the transport bar puts it on a row of its own
SLIDER_LEAST_PX = 160


def colour_dot(colour: str, size: int = 14) -> QIcon:
    """A filled circle of ``colour``: the legend of a marker set, on its check box."""
    pix = QPixmap(size, size)
    pix.fill(QColor(0, 0, 0, 0))
    painter = QPainter(pix)
    painter.setRenderHint(QPainter.RenderHint.Antialiasing)
    painter.setPen(QColor(colour).darker(130))
    painter.setBrush(QColor(colour))
    painter.drawEllipse(1, 1, size - 2, size - 2)
    painter.end()
    return QIcon(pix)


class ViewBar(QWidget):
    """Camera presets, which point sets (each check box with its colour: the legend) and the
    surface to show; in rows as many as the 3-D view's width needs (:class:`FlowLayout`)."""

    def __init__(self, face: FaceView, parent: QWidget | None = None):
        super().__init__(parent)
        self.face = face
        lay = FlowLayout(self, spacing=6, margins=(4, 0, 4, 0))
        self.camera_buttons: dict[str, QToolButton] = {}
        for name in CAMERA_PRESETS:
            b = QToolButton()
            b.setText(CAMERA_LABELS.get(name, name))
            b.setToolTip(CAMERA_TIPS.get(name, f"camera: {name}"))
            b.setCheckable(True)
            b.setAutoExclusive(True)
            b.clicked.connect(lambda _c=False, n=name: face.set_camera(n))
            self.camera_buttons[name] = b
        lay.add(flow_row(list(self.camera_buttons.values())))
        self.camera_buttons[face.preset].setChecked(True)
        self.side_by_side = QCheckBox("side by side")
        self.side_by_side.toggled.connect(face.set_side_by_side)
        # the check boxes of the two point sets carry their colours: they are the legend too
        self.show_original = QCheckBox("original")
        self.show_synth = QCheckBox("synthesized")
        for cb, colour, what in ((self.show_original, ORIGINAL_COLOR, "the recorded markers"),
                                 (self.show_synth, SYNTH_COLOR, "the synthesized markers")):
            cb.setIcon(colour_dot(colour))
            cb.setChecked(True)
            cb.setToolTip(f"show {what} (this colour in the 3-D view; lines: lip contours)")
        for cb in (self.show_original, self.show_synth):
            cb.toggled.connect(lambda _c: face.set_sets_visible(self.show_original.isChecked(),
                                                                self.show_synth.isChecked()))
        self._original_wanted = True
        self._surface_wanted = True
        self.surface = QCheckBox("surface")
        self.surface.setChecked(True)
        self.surface.toggled.connect(face.set_surface)
        for w in (self.show_original, self.show_synth, self.side_by_side, self.surface):
            w.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            lay.add(w)

    def set_has_original(self, has: bool) -> None:
        """An utterance without original markers (a recording opened for synthesis): the
        "original" box off and unticked, saying why; with them again, as the user left it."""
        box = self.show_original
        if has == box.isEnabled():
            return
        box.blockSignals(True)
        if has:
            box.setChecked(self._original_wanted)
            box.setToolTip("show the recorded markers (this colour in the 3-D view; lines: lip "
                           "contours)")
        else:
            self._original_wanted = box.isChecked()
            box.setChecked(False)
            box.setToolTip("this recording has no original markers")
        box.setEnabled(has)
        box.blockSignals(False)

    def set_planar(self, planar: bool) -> None:
        """Midsagittal (2-D) markers or articulograph sensors: the profile camera, and no face
        surface to offer: the "surface" box off and unticked (it stayed ticked, greyed, as if a
        surface were drawn); a face again, as the user left it."""
        box = self.surface
        if planar == box.isEnabled():
            box.blockSignals(True)          # the scene keeps the user's choice for a face
            if planar:
                self._surface_wanted = box.isChecked()
                box.setChecked(False)
            else:
                box.setChecked(self._surface_wanted)
            box.blockSignals(False)
            box.setEnabled(not planar)
        box.setToolTip("midsagittal (2-D) markers or articulograph sensors: no face surface to "
                       "draw" if planar else "the synthesized face as a surface through its markers")
        if planar:
            self.set_camera("profile")

    def set_camera(self, name: str) -> None:
        """Use camera preset ``name`` and check its button."""
        self.face.set_camera(name)
        if name in self.camera_buttons:
            self.camera_buttons[name].setChecked(True)


class TitleBar(QWidget):
    """The title over the panels: two lines of fixed height (what is shown; how it was made), each
    elided to the width, so that no title widens the window or changes the panels' height (a
    title wrapping onto a second line resized the timeline, which then drew anew)."""

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.heading = QLabel("")
        self.heading.setStyleSheet("font-size: 15px; font-weight: 600;")
        self.details = QLabel("")
        self.details.setStyleSheet("color: #333333;")
        lay = QVBoxLayout(self)
        lay.setContentsMargins(6, 2, 6, 2)
        lay.setSpacing(0)
        for label in (self.heading, self.details):
            label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
            lay.addWidget(label)
        self._texts = ("", "")

    def setText(self, text: str) -> None:
        """The title: its first line, then the rest (split at the first "    ·    ")."""
        head, _, rest = text.partition(TITLE_SEPARATOR)
        self._texts = (head, rest)
        self.setToolTip(text.replace(TITLE_SEPARATOR, "\n"))
        self._elide()

    def text(self) -> str:
        """The whole title (as given to :meth:`setText`)."""
        return TITLE_SEPARATOR.join(t for t in self._texts if t)

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self._elide()

    def _elide(self) -> None:
        for label, text in zip((self.heading, self.details), self._texts, strict=True):
            width = max(20, self.width() - 12)
            label.setText(label.fontMetrics().elidedText(text, Qt.TextElideMode.ElideRight, width))


class NoticeBar(QFrame):
    """A hint over the panels that stays until closed (or replaced; a hint about one utterance,
    its ``owner``, until another is shown): a sentence, and a button that does what it suggests
    (e.g. *Import its folder…* for markers the model cannot show)."""

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("notice")
        self.setStyleSheet("#notice { background: #fff4d6; border: 1px solid #e0c36a; }")
        self.text = QLabel("")
        self.text.setWordWrap(True)
        self.text.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.button = QPushButton("")
        close = QToolButton()
        close.setText("×")
        close.setToolTip("hide this note")
        close.setAutoRaise(True)
        close.clicked.connect(self.hide)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(6, 2, 2, 2)
        lay.addWidget(self.text, 1)
        lay.addWidget(self.button)
        lay.addWidget(close)
        self._action: Callable[[], object] | None = None
        self.owner = ""
        self.button.clicked.connect(self._run)
        self.hide()

    def show_notice(self, text: str, action_text: str = "",
                    action: Callable[[], object] | None = None, owner: str = "") -> None:
        self.text.setText(text)
        self._action = action
        self.owner = owner
        self.button.setText(action_text)
        self.button.setVisible(bool(action_text and action))
        self.show()

    def utterance_shown(self, name: str) -> None:
        """Another utterance is shown: a hint about the one before goes (MOCHA's note stayed up
        over every utterance after it)."""
        if self.owner and name != self.owner:
            self.hide()

    def _run(self) -> None:
        self.hide()
        if self._action is not None:
            self._action()


class TransportBar(QWidget):
    """Play / stop / frame steps, the frame slider, the time read-out, speed and loop; in rows as
    many as the width needs (:class:`FlowLayout`: the slider takes the rest of its row)."""

    playClicked = pyqtSignal()
    stopClicked = pyqtSignal()
    stepClicked = pyqtSignal(int)           # frames
    speedChanged = pyqtSignal(float)

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        lay = FlowLayout(self, spacing=6, margins=(4, 0, 4, 0))
        SP = QStyle.StandardPixmap
        self.play_button = self._button(SP.SP_MediaPlay, "play / pause (space)", self.playClicked.emit)
        lay.add(flow_row([
            self.play_button,
            self._button(SP.SP_MediaStop, "stop", self.stopClicked.emit),
            self._button(SP.SP_MediaSeekBackward, "previous frame (left)", lambda: self.stepClicked.emit(-1)),
            self._button(SP.SP_MediaSeekForward, "next frame (right)", lambda: self.stepClicked.emit(1))]))
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        lay.add(self.slider, stretch=SLIDER_LEAST_PX)
        self.time_label = QLabel("0.000 s")
        self.time_label.setStyleSheet("font-family: monospace;")
        # a fixed size: a new text every frame then repaints the label without laying out the
        # bars and the splitter around it again (a label whose size hint may change does)
        self.time_label.ensurePolished()
        width = self.time_label.fontMetrics().horizontalAdvance(TIME_TEMPLATE)
        self.time_label.setFixedSize(width, self.time_label.sizeHint().height())
        lay.add(self.time_label)
        self.speed = QComboBox()
        for s in SPEEDS:
            self.speed.addItem(f"{s:g}x", s)
        self.speed.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.speed.setToolTip("playback speed")
        self.speed.currentIndexChanged.connect(lambda _i: self.speedChanged.emit(self.speed.currentData()))
        self.loop_box = QCheckBox("loop")
        self.loop_box.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.loop_box.setToolTip("loop the selected range (drag on the panels to select; Esc clears)")
        # the 3-D view over the panels' room too, as a video player's full-screen button (a
        # laptop screen: the faces two or three times as tall); the window connects it
        # (``PanelSplit.enlarge``)
        self.enlarge = QToolButton()
        self.enlarge.setText("⤢")
        self.enlarge.setCheckable(True)
        self.enlarge.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.enlarge.setToolTip("enlarge the 3-D view: it takes the panels' room too (press again "
                                "for the panels)")
        lay.add(flow_row([self.speed, self.loop_box, self.enlarge], spacing=6))

    def _button(self, icon: QStyle.StandardPixmap, tip: str, slot) -> QToolButton:
        b = QToolButton()
        b.setIcon(self.style().standardIcon(icon))
        b.setAutoRaise(False)
        b.setToolTip(tip)
        b.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        b.clicked.connect(lambda _c=False: slot())
        return b

    def set_playing(self, playing: bool) -> None:
        icon = QStyle.StandardPixmap.SP_MediaPause if playing else QStyle.StandardPixmap.SP_MediaPlay
        self.play_button.setIcon(self.style().standardIcon(icon))

    def set_frames(self, n_frames: int) -> None:
        self.slider.blockSignals(True)
        self.slider.setRange(0, max(n_frames - 1, 0))
        self.slider.blockSignals(False)

    def show_frame(self, frame: int, text: str) -> None:
        """Move the slider (without signalling a seek) and set the read-out; a widget whose
        value is unchanged is not touched (no repaint)."""
        if self.slider.value() != frame:
            self.slider.blockSignals(True)
            self.slider.setValue(frame)
            self.slider.blockSignals(False)
        if self.time_label.text() != text:
            self.time_label.setText(text)
            width = self.time_label.fontMetrics().horizontalAdvance(text)
            if width > self.time_label.width():
                self.time_label.setFixedWidth(width + 8)


def playback_shortcuts(window) -> list[QShortcut]:
    """The main window's keys (space, arrows, shift+arrows, Home/End, Esc; see ``KEYS_HELP``)."""
    K, M = Qt.Key, Qt.KeyboardModifier
    bindings = [
        (QKeySequence(K.Key_Space), window.toggle_play),
        (QKeySequence(K.Key_Left), lambda: window.step_frames(-1)),
        (QKeySequence(K.Key_Right), lambda: window.step_frames(1)),
        (QKeySequence(M.ShiftModifier | K.Key_Left), lambda: window.step_phone(-1)),
        (QKeySequence(M.ShiftModifier | K.Key_Right), lambda: window.step_phone(1)),
        (QKeySequence(K.Key_Home), lambda: window.seek(0.0)),
        (QKeySequence(K.Key_End), lambda: window.seek(window.clock.duration)),
        (QKeySequence(K.Key_Escape), window.loop.clear),
    ]
    return add_shortcuts(window, bindings)


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


def ask_recordings_folder(parent: QWidget) -> tuple[Path] | None:
    path = QFileDialog.getExistingDirectory(parent, "Open a folder of recordings (synthesized with "
                                                    "the model in use)")
    return (Path(path),) if path else None


def ask_screenshot_path(parent: QWidget) -> tuple[Path] | None:
    path, _ = QFileDialog.getSaveFileName(parent, "Save a screenshot", "facetraj.png", "PNG (*.png)")
    return (Path(path),) if path else None
