"""Live mode: the synthesized face follows a microphone (QtMultimedia ``QAudioSource``) or a file
played in real time, through live mode's stream (``facetraj_engine.streaming.live``: phones recognized as
they are spoken, or acoustic-only).

The window shows the 3-D face (synthesized points only), an input level meter, and the upper and
lower lip y of the last few seconds scrolling, with speech/silence dots computed live (the
energy of the 20 ms before each frame against the take's running floor and peak), and under them
the phones (``facetraj_app.live_phones``). Stop keeps the take: its audio, trajectories and phones can be
saved (WAV + C3D/TSV + TextGrid) and opened like any utterance. A device that disappears ends the
take with a message; what was recorded is kept.
"""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.transforms import Bbox
from PyQt6.QtCore import QEvent, QObject, QTimer, pyqtSignal
from PyQt6.QtWidgets import (
    QApplication,
    QComboBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QProgressBar,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.analysis.lips import closed_lips
from facetraj_engine.config import SynthConfig
from facetraj_engine.errors import FacetrajError
from facetraj_engine.io.audio import read_audio, write_audio
from facetraj_engine.io.export import write_trajectories
from facetraj_engine.method.model import Model

from .live_input import MIC_RATE, FileFeeder, InputHealth, InputLost, MicFeeder, input_devices
from .live_phones import PhonePanel
from .plotter_widget import grab_with_3d
from .style import SPEECH_DOT_COLOR, SYNTH_COLOR, TRIANGULAR_COLOR, closed_line
from .view3d import FaceView
from .window_frame import fit_to_screen

log = logging.getLogger(__name__)

#: shown in the window when there is no microphone, and said by ``facetraj live`` (exit 2)
NO_INPUT_DEVICE = ("no audio input device found (is a microphone connected and a sound server "
                   "running?): Open recording... plays a file through live mode")
NO_INPUT_DEVICE_COMMAND = ("no audio input device found (is a microphone connected and a sound "
                           "server running?); use --from-file FILE to play a file through live "
                           "mode (or Open recording... in the app's Live window)")
SHOWN_S = 4.0
#: the input box shows this many characters at least (a file name, a device's description)
DEVICE_BOX_CHARS = 30
#: the Live window's size where the screen has room for it
LIVE_SIZE = (1400, 800)
TICK_MS = 15
PLOT_EVERY_S = 0.2
__all__ = ["MIC_RATE", "FileFeeder", "LiveWindow", "MicFeeder", "input_devices", "run_live"]


class LiveWindow(QMainWindow):
    """The Live window. ``start()`` begins a take from the chosen device (or ``from_file``),
    ``stop()`` ends it; ``save_take(path)`` writes ``path`` (.c3d/.tsv/...), the WAV and (with
    phones) the TextGrid beside it. ``phones``: the mode switch's first setting.
    """

    takeFinished = pyqtSignal()
    closed = pyqtSignal()

    def __init__(self, model: Model, config: SynthConfig | None = None,
                 from_file: tuple[np.ndarray, int] | None = None, block_s: float = 0.01,
                 fast: bool = False, device: str | None = None, phones: bool = True):
        super().__init__()
        self.setWindowTitle("facetraj - live")
        self.model = model
        self.config = config or SynthConfig()
        self.from_file, self.block_s, self.fast = from_file, block_s, fast
        self.stream = None                  # the take's facetraj_engine.streaming.live.LiveStream
        self.feeder: FileFeeder | MicFeeder | None = None
        self.rate = MIC_RATE
        self._new_take()
        self._last_plot = 0.0
        self._timer = QTimer(self)
        self._timer.setInterval(TICK_MS)
        self._timer.timeout.connect(self._tick)

        bar = QToolBar("Live")
        self.addToolBar(bar)
        self.device_box = QComboBox()
        self.devices = [] if from_file is not None else input_devices()
        for d in self.devices:
            self.device_box.addItem(d.description())
        if device:
            names = [d.description() for d in self.devices]
            match = [i for i, n in enumerate(names) if device.lower() in n.lower()]
            if match:
                self.device_box.setCurrentIndex(match[0])
        if from_file is not None:
            self.device_box.insertItem(0, "file")
            self.device_box.setCurrentIndex(0)
        # wide enough for a file's name or a device's ("file: cmu" was all it showed)
        self.device_box.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToContents)
        self.device_box.setMinimumContentsLength(DEVICE_BOX_CHARS)
        bar.addWidget(QLabel(" input: "))
        bar.addWidget(self.device_box)
        self.start_action = bar.addAction("Start", self.start)
        self.stop_action = bar.addAction("Stop", self.stop)
        self.save_action = bar.addAction("Save take...", self._save_dialog)
        self.stop_action.setEnabled(False)
        self.save_action.setEnabled(False)

        central = QWidget()
        lay = QHBoxLayout(central)
        self.face = FaceView(central)
        self.face.set_model(model)
        self.face.set_sets_visible(False, True)
        lay.addWidget(self.face, 3)
        right = QVBoxLayout()
        self.level = QProgressBar()
        self.level.setRange(-60, 0)
        self.level.setValue(-60)
        self.level.setFormat("input %v dB")
        right.addWidget(self.level)
        self._build_panels()
        self.canvas.mpl_connect("draw_event", self._on_full_draw)
        right.addWidget(self.canvas, 1)
        self.phones = PhonePanel(self, bar, right, phones, SHOWN_S)
        lay.addLayout(right, 2)
        self.setCentralWidget(central)
        self.message = QLabel()
        self.statusBar().addWidget(self.message, 1)
        if from_file is None and not self.devices:
            self.message.setText(NO_INPUT_DEVICE)
            self.start_action.setEnabled(False)
        else:
            self.message.setText("press Start")

    def _build_panels(self) -> None:
        """The scrolling upper and lower lip panels, in the main window's colours, with the
        talker's closed lips as a dashed line and a legend above the panels (never over the
        curves)."""
        self.figure = Figure(figsize=(5, 4), layout="constrained")
        self.canvas = FigureCanvasQTAgg(self.figure)
        self.axes = [self.figure.add_subplot(2, 1, k + 1) for k in range(2)]
        self.lines, self.dots = [], []
        smoothing = self.config.smoothing
        line_label = f"synthesized, {smoothing}" if smoothing != "none" else "synthesized"
        line_color = TRIANGULAR_COLOR if smoothing == "triangular" else SYNTH_COLOR
        closed = closed_lips(self.model).markers
        self.closed_y = [float(closed[self.model.upper_lip, 1]), float(closed[self.model.lower_lip, 1])]
        for ax, which, closed_y in zip(self.axes, ("upper", "lower"), self.closed_y, strict=True):
            ax.set_ylabel(f"{which} lip y (mm)", fontsize=8)
            ax.set_xlim(-SHOWN_S, 0.0)
            ax.set_ylim(closed_y - 2.0, closed_y + 8.0)
            ax.tick_params(labelsize=7)
            # the main window's colours (app/style.py); animated: left out of full draws,
            # blitted over the cached background (_plot)
            (line,) = ax.plot([], [], color=line_color, lw=1.6, animated=True, label=line_label)
            (dots,) = ax.plot([], [], ls="none", marker=".", ms=3, color=SPEECH_DOT_COLOR,
                              animated=True, label="speech frames (live energy)")
            closed_handle = closed_line(ax, closed_y)
            self.lines.append(line)
            self.dots.append(dots)
        # the legend: part of the background (drawn with the axes, not per frame), above them
        self.legend = self.figure.legend(
            handles=[Line2D([], [], color=line_color, lw=1.6, label=line_label),
                     Line2D([], [], ls="none", marker=".", ms=5, color=SPEECH_DOT_COLOR,
                            label="speech frames (live energy)"),
                     closed_handle],
            loc="outside upper center", fontsize=7, ncol=2, frameon=False)
        self.axes[1].set_xlabel("time (s, 0 = now)", fontsize=8)
        self._background = None

    # ------------------------------------------------------------------ a file
    def open_recording(self, path: str | Path) -> bool:
        """Play the recording at ``path`` through live mode (a new take); a file that cannot be
        read is said in the status bar."""
        try:
            audio, rate = read_audio(path)
        except (OSError, FacetrajError) as exc:
            self.message.setText(f"could not open the recording: {exc}")
            return False
        self.stop()
        self.from_file = (audio, rate)
        if self.device_box.count() == len(self.devices):
            self.device_box.insertItem(0, "file")
        self.device_box.setItemText(0, f"file: {Path(path).name}")
        self.device_box.setToolTip(str(path))
        self.device_box.setCurrentIndex(0)
        self.start_action.setEnabled(True)
        self.start()
        return True

    def open_dialog(self) -> None:
        name, _ = QFileDialog.getOpenFileName(self, "Play a recording through live mode", "",
                                              "Audio (*.wav *.flac)")
        if name:
            self.open_recording(name)

    # ------------------------------------------------------------------ a take
    def start(self) -> None:
        """Begin a take (the previous one is dropped)."""
        from facetraj_engine.streaming.live import LiveConfig, LiveStream  # the recognizer: with a take


        index = self.device_box.currentIndex() - (self.device_box.count() - len(self.devices))
        try:
            if self.from_file is not None and index < 0:
                audio, rate = self.from_file
                self.feeder = FileFeeder(audio, rate, self.block_s, self.fast)
            elif self.devices:
                self.feeder = MicFeeder(self.devices[max(index, 0)])
            else:
                self.message.setText(NO_INPUT_DEVICE)
                return
            self.rate = self.feeder.rate
            self.stream = LiveStream(self.model, self.rate, self.config,
                                     LiveConfig(phones=self.phones.phones_on), threaded=True,
                                     cmn=self.phones.cmn)
        except (InputLost, ValueError, RuntimeError, OSError) as exc:
            self.message.setText(f"could not start: {exc}")
            self.stream = None
            return
        self.phones.new_stream(self.stream)
        self.phones.take_started()
        self.health = InputHealth(self.rate)
        self._new_take()
        self.start_action.setEnabled(False)
        self.stop_action.setEnabled(True)
        self.save_action.setEnabled(False)
        self.message.setText(f"live: {self.stream.choice.describe()}")
        self._timer.start()

    def _new_take(self) -> None:
        """An empty take, its clock starting now."""
        self.audio: list[np.ndarray] = []
        self.markers: list[np.ndarray] = []
        self.speech: list[bool] = []
        self._energy: list[float] = []
        self._samples = self._frames = 0        # running lengths of the take (no sums per tick)
        self.updates = 0
        self._shown = -1                # the frame on screen
        self._level = -60               # the loudest block (dB) since the meter was last set
        self._t_start = time.perf_counter()

    def stop(self, reason: str = "") -> None:
        """End the take: the last frames come out (the smoothing's lookahead) and it is kept
        (``reason``: why it ended, when not by the user)."""
        self._timer.stop()
        if self.stream is None:
            return
        self.feeder.stop()
        stream, self.stream = self.stream, None
        self._consume(stream.flush())
        self.phones.take_finished(stream, self.take_seconds)
        self._show_due()
        self.start_action.setEnabled(True)
        self.stop_action.setEnabled(False)
        self.save_action.setEnabled(self.n_frames > 0)
        self.message.setText((f"{reason}; " if reason else "") +
                             f"take: {self.take_seconds:.1f} s, {self.n_frames} frames, "
                             f"{self.fps:.0f} face updates/s")
        self.takeFinished.emit()

    def closeEvent(self, event) -> None:
        """The take ends (the recognizer's thread with it), the 3-D view is let go, and
        ``closed`` says so (the main window's Live toggle follows it)."""
        self.stop()
        self.face.close_view()
        super().closeEvent(event)
        self.closed.emit()

    @property
    def n_frames(self) -> int:
        return self._frames

    @property
    def take_seconds(self) -> float:
        return self._samples / float(self.rate)

    @property
    def fps(self) -> float:
        """Face updates per second of the take so far."""
        return self.updates / max(time.perf_counter() - self._t_start, 1e-9)

    def take(self) -> tuple[np.ndarray, int, np.ndarray]:
        """The take's audio, its rate and its synthesized markers ``(T, M, 3)``."""
        audio = np.concatenate(self.audio) if self.audio else np.zeros(0)
        markers = (np.concatenate(self.markers) if self.markers
                   else np.zeros((0, self.model.n_markers, 3)))
        return audio, self.rate, markers

    def save_take(self, path: str | Path, overwrite: bool = False) -> tuple[Path, Path]:
        """Write the take's trajectories to ``path`` (.c3d, .tsv, .csv or .npz), its audio to
        the WAV of the same name and its recognized phones to the TextGrid (with their
        provenance, ``facetraj_app.live_phones``); the first two paths."""
        audio, rate, markers = self.take()
        path = Path(path)
        wav = path.with_suffix(".wav")
        write_audio(wav, audio, rate, overwrite)
        out = write_trajectories(path, markers, self.model.marker_rate, self.model.marker_names,
                                 overwrite=overwrite)
        grid = self.phones.save(path.with_suffix(".TextGrid"), len(audio) / rate, overwrite)
        self.message.setText(f"take saved: {out}, {wav.name}" + (f" and {grid.name}" if grid else ""))
        return out, wav

    def _save_dialog(self) -> None:
        name, _ = QFileDialog.getSaveFileName(self, "Save take", "take.c3d",
                                              "C3D (*.c3d);;TSV (*.tsv)")
        if name:
            try:
                self.save_take(name, overwrite=True)
            except (OSError, FacetrajError) as exc:
                self.message.setText(f"could not save: {exc}")

    # ------------------------------------------------------------------ the clock
    def _tick(self) -> None:
        try:
            block = self.feeder.poll()
        except InputLost as exc:
            self.stop(f"{exc}: the take so far is kept")
            return
        if block is None:
            self.stop()
            return
        try:
            if len(block):
                self.audio.append(block.astype(np.float32))
                self._samples += len(block)
                self.phones.latency.arrived(self.take_seconds)
                self.health.add(block)
                rms = float(np.sqrt(np.mean(block**2)) + 1e-12)
                self._level = max(self._level, int(np.clip(20 * np.log10(rms), -60, 0)))
                self._consume(self.stream.feed(block))
            self._show_due()
        except Exception as exc:        # a slot must not raise (PyQt aborts): end the take
            log.exception("live take stopped")
            self.stop(f"live mode stopped ({exc}): the take so far is kept")

    def _consume(self, frames) -> None:
        """Keep the frames of the take; they are shown when due (:meth:`_show_due`)."""
        if len(frames) == 0:
            return
        self.markers.append(frames.markers)
        self._frames += len(frames.markers)
        self._mark_speech(frames.times)

    def _show_due(self) -> None:
        """Show the frame due now: the stream's delay behind the audio received, so that the
        frames of a batch are shown one after the other at their own times, not all at once."""
        if not self.markers:
            return
        if self.stream is None:                                  # the take ended: the last one
            due = self.n_frames - 1
        else:
            t = self.take_seconds - self.stream.lookahead_s
            due = min(int(np.floor(t * self.model.marker_rate)), self.n_frames - 1)
        if due <= self._shown:
            return
        self._shown = due
        self.phones.latency.shown(due / self.model.marker_rate)
        self.face.synth.set_points(self._frame(due))
        self.face.request_render()
        self.updates += 1
        now = time.perf_counter()
        if now - self._last_plot >= PLOT_EVERY_S or self.stream is None:
            # the panels and the meter together: any repaint beside the OpenGL view recomposes
            # the window (docs/benchmarks.md), so they are not repainted per frame
            self._last_plot = now
            self.level.setValue(self._level)
            self._level = -60
            self._plot()
            self.phones.refresh(self.stream, (self.n_frames - 1) / self.model.marker_rate)
            if self.stream is not None:
                self.message.setText(self.health.message or f"live: {self.stream.choice.describe()}")

    def _frame(self, k: int) -> np.ndarray:
        """Marker frame ``k`` of the take (the last chunks are searched from the end)."""
        end = self.n_frames
        for chunk in reversed(self.markers):
            end -= len(chunk)
            if k >= end:
                return chunk[k - end]
        raise IndexError(k)

    def _mark_speech(self, times: np.ndarray) -> None:
        """Speech/silence of each new frame: the energy (dB) of the 20 ms of audio before it
        against the take's floor and peak so far (5th and 99th percentiles), 30 % up."""
        audio = np.concatenate(self.audio[-20:]) if self.audio else np.zeros(0)
        end_of_audio = self.take_seconds
        n = int(0.02 * self.rate)
        for t in times:
            stop = len(audio) - int(round((end_of_audio - t) * self.rate))
            seg = audio[max(0, stop - n):max(0, stop)]
            self._energy.append(10 * np.log10(np.mean(seg**2) + 1e-12) if len(seg) else -120.0)
        e = np.asarray(self._energy)
        floor, peak = np.percentile(e, [5, 99])
        threshold = floor + 0.3 * (peak - floor)
        self.speech.extend(bool(v > threshold and peak - floor > 6.0) for v in e[-len(times):])

    def _plot(self) -> None:
        """Scroll the lip panels: the lines and dots blitted over the cached axes (a few ms); the
        whole figure is drawn again only when a panel's y range must change (matplotlib's full
        draw with its layout takes 100-250 ms, which would hold up the face)."""
        n = min(self.n_frames, int(SHOWN_S * self.model.marker_rate))
        tail, have = [], 0
        for chunk in reversed(self.markers):            # only the chunks the panels show
            if have >= n:
                break
            tail.append(chunk)
            have += len(chunk)
        markers = np.concatenate(tail[::-1])[-n:]
        t = (np.arange(n) - (n - 1)) / self.model.marker_rate
        speech = np.asarray(self.speech[-n:])
        rescale = False
        for ax, line, dots, k, closed_y in zip(self.axes, self.lines, self.dots,
                                               (self.model.upper_lip, self.model.lower_lip),
                                               self.closed_y, strict=True):
            y = markers[:, k, 1]
            line.set_data(t, y)
            mid = float(np.median(y))
            dots.set_data(t[speech], np.full(int(speech.sum()), mid))
            lo, hi = min(float(y.min()), closed_y), max(float(y.max()), closed_y)
            pad = 0.15 * max(hi - lo, 0.5)
            y0, y1 = ax.get_ylim()
            # outside the axes, or using less than half of them: new limits (and a full draw)
            if lo < y0 or hi > y1 or (hi - lo + 2 * pad) < 0.5 * (y1 - y0):
                ax.set_ylim(lo - pad, hi + pad)
                rescale = True
        if rescale or self._background is None:
            self.canvas.draw_idle()             # _on_full_draw blits the lines
        else:
            self._blit()

    def _on_full_draw(self, _event) -> None:
        self._background = self.canvas.copy_from_bbox(self.figure.bbox)
        self._blit(restore=False)

    def _blit(self, restore: bool = True) -> None:
        if restore:
            self.canvas.restore_region(self._background)
        for ax, line, dots in zip(self.axes, self.lines, self.dots, strict=True):
            ax.draw_artist(line)
            ax.draw_artist(dots)
        # the rectangle of the two axes only (a Qt repaint of that region)
        self.canvas.blit(Bbox.union([ax.bbox for ax in self.axes]))


def run_live(model_loader: Callable[[], Model], config: SynthConfig | None = None,
             from_file: Path | None = None, block_s: float = 0.01, fast: bool = False,
             device: str | None = None, screenshot: str | None = None,
             quit_after: float | None = None, phones: bool = True) -> int:
    """Open the Live window (``facetraj live``) and start a take. No input device and no file:
    :class:`FacetrajError` with :data:`NO_INPUT_DEVICE_COMMAND` (a command must not wait for a
    window nobody asked for; the window itself offers to open a recording). With ``screenshot``,
    the window is saved to that PNG when the file has been played (or after ``quit_after``
    seconds) and closes."""
    from facetraj_engine.threads import one_blas_thread

    from .display import ensure_display, require_display, route_qt_messages

    # what the options name is read first: a bad file or model is an error before any window
    audio = read_audio(from_file) if from_file is not None else None
    model = model_loader()
    if screenshot:
        ensure_display()
    require_display("the Live window (facetraj live without -o)")
    one_blas_thread()       # the stream is synthesized beside the rendering (facetraj_engine.threads)
    route_qt_messages()     # -q: only the one-line error, no Qt sound back-end reports
    app = QApplication.instance() or QApplication(sys.argv[:1])
    if audio is None and not input_devices():
        raise FacetrajError(NO_INPUT_DEVICE_COMMAND)
    window = LiveWindow(model, config, audio, block_s, fast, device, phones)
    fit_to_screen(window, LIVE_SIZE)
    window.show()

    def finish() -> None:
        if screenshot:
            grab_with_3d(window).save(str(screenshot))      # the face as on screen (grab: black)
            print(screenshot)
        app.quit()

    if screenshot or quit_after:
        window.takeFinished.connect(finish)
        if quit_after:
            QTimer.singleShot(int(quit_after * 1000), window.stop)
    QTimer.singleShot(0, window.start)
    app.exec()
    return 0


class LiveToggle(QObject):
    """The window extension of live mode: a "Live" toggle in a toolbar that opens the Live window
    on the main window's model (the microphone; no device: the window says so) and closes it.

    The toggle follows the Live window whichever way it closes (its close button, the toggle,
    the main window closing: that closes the Live window first, so that quitting never leaves it
    open, nor a slot pointing at a deleted toggle)."""

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.live: LiveWindow | None = None
        bar = window.addToolBar("Live")
        bar.setObjectName("live-toolbar")
        self.action = bar.addAction("Live")
        self.action.setCheckable(True)
        self.action.setToolTip("the face follows the microphone (live mode)")
        self.action.toggled.connect(self.toggled)
        window.installEventFilter(self)

    def toggled(self, on: bool) -> None:
        if on and self.live is None:
            if self.window.model is None:
                self.window.show_error("live mode needs a model: wait for training to finish")
                self._set_checked(False)
                return
            self.live = LiveWindow(self.window.model)
            self.live.closed.connect(self._live_closed)
            fit_to_screen(self.live, LIVE_SIZE)
            self.live.show()
        elif not on and self.live is not None:
            self.live.close()                   # closed -> _live_closed

    def _live_closed(self) -> None:
        """The Live window closed (by its close button, the toggle or the main window)."""
        live, self.live = self.live, None
        self._set_checked(False)
        if live is not None:
            live.closed.disconnect(self._live_closed)
            live.deleteLater()

    def _set_checked(self, on: bool) -> None:
        self.action.blockSignals(True)
        self.action.setChecked(on)
        self.action.blockSignals(False)

    def eventFilter(self, obj, event) -> bool:
        if obj is self.window and event.type() == QEvent.Type.Close and self.live is not None:
            self.live.close()                   # the main window closes: the Live window first
        return False


def install(window) -> LiveToggle:
    """Add live mode to the main window (as the extension ``live``)."""
    toggle = LiveToggle(window)
    window.add_extension("live", toggle)
    return toggle
