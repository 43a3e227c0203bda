"""The facetraj main window.

Window contract (used by the analysis views, ``app.analysis.install(window)``)
==============================================================================

``MainWindow(QMainWindow)`` exposes

Attributes
    ``model: Model`` (``None`` until the first model is loaded or trained),
    ``corpus: Corpus | None``,
    ``view: UtteranceView | None`` (the current utterance, its synthesis and derived tracks; see
    ``app/state.py``), ``synth_config: SynthConfig`` (the settings the view was synthesized with),
    ``plotter`` (the pyvistaqt ``QtInteractor`` of the 3-D view), ``timeline`` (the time-aligned
    panel stack, ``app/timeline.py``) and ``analysis_menu`` (the ``QMenu`` "Analysis").

Signals
    ``utteranceChanged(str)`` after a new utterance is shown (``view`` already updated);
    ``cursorMoved(float)`` the cursor time in seconds, at most once per displayed frame;
    ``synthesisChanged()`` after every (re)synthesis, once ``view`` is updated.

Methods
    ``set_utterance(utt_id)``, ``seek(t)``, ``current_time() -> float``,
    ``add_dock(widget, title, area=Qt.DockWidgetArea.RightDockWidgetArea) -> QDockWidget``,
    ``run_in_background(fn, on_done, progress_label, on_error=None, on_partial=None) -> Task``:
    runs ``fn(progress)`` in a worker thread (``progress(fraction, message)`` drives the status
    bar's progress bar; ``progress.partial(obj)`` delivers ``on_partial(obj)``), then calls
    ``on_done(result)`` on the GUI thread; an exception goes to ``on_error(exc)`` or an error
    dialog.

Timeline panels
    ``timeline.add_panel(panel)`` / ``timeline.remove_panel(panel)``; a panel is any object with
    ``title: str``, ``height: float`` (relative) and ``draw(ax, view: UtteranceView) -> None``.
    The timeline re-lays out its figure (shared time axis, blitted cursor) and redraws every panel
    whenever the view changes.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from PyQt6.QtCore import QEvent, QPoint, Qt, QTimer, pyqtSignal
from PyQt6.QtGui import QAction, QImage, QKeySequence, QPainter, QShortcut
from PyQt6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDockWidget,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QMenu,
    QMessageBox,
    QProgressBar,
    QPushButton,
    QSlider,
    QSplitter,
    QStyle,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from engine.config import SynthConfig
from engine.corpus import Corpus, load_corpus
from engine.data import Utterance
from engine.errors import FacetrajError
from engine.evaluation import evaluate_utterance, trajectory_correlations
from engine.formats import read_audio, read_labels
from engine.model import Model

from .browser import UtteranceBrowser, normalise_text
from .cache import load_or_train
from .settings_panel import SynthSettingsPanel
from .state import UtteranceView, build_view
from .style import ORIGINAL_COLOR, SYNTH_COLOR
from .timeline import LipPanel, PhoneTierPanel, SpectrogramPanel, Timeline, WaveformPanel
from .transport import PlaybackClock
from .view3d import CAMERA_PRESETS, FaceView
from .workers import Progress, Task

log = logging.getLogger(__name__)

DEFAULT_SENTENCE = "Tornadoes often destroy acres of farm land"
SPEEDS = (1.0, 0.5, 0.25)


def _phone_at(view: UtteranceView | None, t: float) -> str:
    if view is None:
        return ""
    for seg in view.utterance.phones:
        if seg.start <= t < seg.end:
            return seg.label
    return ""


class MainWindow(QMainWindow):
    """Speech plays while original and synthesized face points move, with the lip trajectories."""

    utteranceChanged = pyqtSignal(str)
    cursorMoved = pyqtSignal(float)
    synthesisChanged = pyqtSignal()
    modelReady = pyqtSignal()
    busyChanged = pyqtSignal(bool)
    correlationsDone = pyqtSignal()

    def __init__(self, corpus_path: Path | None = None, model_path: Path | None = None,
                 utterance: str | None = None, start_time: float | None = None,
                 use_audio: bool | None = None, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("facetraj — speech-driven 3-D face point trajectories")
        self.model: Model | None = None
        self.corpus: Corpus | None = None
        self.view: UtteranceView | None = None
        self.synth_config = SynthConfig()
        self.texts: dict[str, str] = {}
        self.external: dict[str, Utterance] = {}
        self._pending_utterance = utterance
        self._pending_time = start_time
        self._tasks: list[Task] = []
        self._synth_generation = 0
        # the latest utterance asked for: (loader, split, is it a new utterance not shown yet)
        self._request: tuple[Callable[[], Utterance], str, bool] | None = None
        self._corr_task: Task | None = None
        self._latency = 0.0          # running estimate of one frame update (s)
        self.stats: list[tuple[float, int, float, float]] | None = None   # benchmark hook
        self.displayed_frame = -1
        self._closing = False
        self._frame_pending: tuple[float, int] | None = None   # (tick time, frame) until flushed
        self.clock = PlaybackClock(self, use_audio=use_audio)
        self.clock.playingChanged.connect(self._on_playing_changed)

        self._build_widgets()
        self._build_menus()
        self._build_shortcuts()
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.setInterval(5)
        self._timer.timeout.connect(self._tick)
        if corpus_path is not None:
            QTimer.singleShot(0, lambda: self.open_corpus(Path(corpus_path), model_path))

    # ================================================================== construction
    def _build_widgets(self) -> None:
        self.face = FaceView(self)
        self.plotter = self.face.plotter
        self.plotter.interactor.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.timeline = Timeline(self)
        for panel in (WaveformPanel(), SpectrogramPanel(), PhoneTierPanel(),
                      LipPanel(self, "upper"), LipPanel(self, "lower")):
            self.timeline.panels.append(panel)
        self.timeline.seekRequested.connect(self._on_timeline_seek)
        self.timeline.loopSelected.connect(self._on_loop_selected)

        self.title = QLabel("")
        self.title.setStyleSheet("font-size: 15px; font-weight: 600; padding: 2px 6px;")
        top = QWidget()
        tl = QVBoxLayout(top)
        tl.setContentsMargins(0, 0, 0, 0)
        tl.setSpacing(2)
        tl.addWidget(self._build_view_bar())
        tl.addWidget(self.face, 1)
        tl.addWidget(self._build_transport())

        bottom = QWidget()
        bl = QVBoxLayout(bottom)
        bl.setContentsMargins(0, 0, 0, 0)
        bl.setSpacing(0)
        bl.addWidget(self.title)
        bl.addWidget(self.timeline, 1)

        split = QSplitter(Qt.Orientation.Vertical)
        split.addWidget(top)
        split.addWidget(bottom)
        split.setStretchFactor(0, 1)
        split.setStretchFactor(1, 1)
        split.setSizes([480, 520])
        split.setChildrenCollapsible(False)
        self.splitter = split
        self.setCentralWidget(split)

        self.browser = UtteranceBrowser(self)
        self.browser.utteranceSelected.connect(self.set_utterance)
        self.browser_dock = self._dock(self.browser, "Utterances", Qt.DockWidgetArea.LeftDockWidgetArea)
        self.settings = SynthSettingsPanel(self.synth_config, self)
        self.settings.configChanged.connect(self.set_synth_config)
        self.settings_dock = self._dock(self.settings, "Synthesis settings",
                                        Qt.DockWidgetArea.LeftDockWidgetArea)
        self.resizeDocks([self.browser_dock], [400], Qt.Orientation.Horizontal)
        self._extra_docks: dict[Qt.DockWidgetArea, QDockWidget] = {}

        self.status_label = QLabel("")
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setFixedWidth(300)
        self.progress.setVisible(False)
        self.statusBar().addWidget(self.status_label, 1)
        self.statusBar().addPermanentWidget(self.progress)

    def _build_view_bar(self) -> QWidget:
        bar = QWidget()
        lay = QHBoxLayout(bar)
        lay.setContentsMargins(4, 0, 4, 0)
        lay.addWidget(QLabel("camera:"))
        self.camera_buttons: dict[str, QToolButton] = {}
        for name in CAMERA_PRESETS:
            b = QToolButton()
            b.setText(name)
            b.setCheckable(True)
            b.setAutoExclusive(True)
            b.clicked.connect(lambda _c=False, n=name: self.face.set_camera(n))
            lay.addWidget(b)
            self.camera_buttons[name] = b
        self.camera_buttons[self.face.preset].setChecked(True)
        lay.addSpacing(16)
        legend = QLabel(f'<span style="color:{ORIGINAL_COLOR}; font-size:16px">●</span> original &nbsp; '
                        f'<span style="color:{SYNTH_COLOR}; font-size:16px">●</span> synthesized')
        legend.setToolTip("marker colours in the 3-D view (lines: lip contours; surface: the "
                          "synthesized face)")
        lay.addWidget(legend)
        lay.addSpacing(16)
        self.side_by_side = QCheckBox("side by side")
        self.side_by_side.toggled.connect(self.face.set_side_by_side)
        self.show_original = QCheckBox("show original")
        self.show_original.setChecked(True)
        self.show_synth = QCheckBox("show synthesized")
        self.show_synth.setChecked(True)
        for cb in (self.show_original, self.show_synth):
            cb.toggled.connect(lambda _c: self.face.set_sets_visible(self.show_original.isChecked(),
                                                                     self.show_synth.isChecked()))
        self.surface = QCheckBox("face surface")
        self.surface.setChecked(True)
        self.surface.toggled.connect(self.face.set_surface)
        for w in (self.show_original, self.show_synth, self.side_by_side, self.surface):
            w.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            lay.addWidget(w)
        lay.addStretch(1)
        return bar

    def _build_transport(self) -> QWidget:
        bar = QWidget()
        lay = QHBoxLayout(bar)
        lay.setContentsMargins(4, 0, 4, 0)
        st = self.style()

        def button(icon: QStyle.StandardPixmap, tip: str, slot: Callable[[], None]) -> QPushButton:
            b = QPushButton(st.standardIcon(icon), "")
            b.setToolTip(tip)
            b.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            b.clicked.connect(lambda _c=False: slot())
            lay.addWidget(b)
            return b

        self.play_button = button(QStyle.StandardPixmap.SP_MediaPlay, "play / pause (space)",
                                  self.toggle_play)
        button(QStyle.StandardPixmap.SP_MediaStop, "stop", self.stop)
        button(QStyle.StandardPixmap.SP_MediaSeekBackward, "previous frame (left)",
               lambda: self.step_frames(-1))
        button(QStyle.StandardPixmap.SP_MediaSeekForward, "next frame (right)", lambda: self.step_frames(1))
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.slider.valueChanged.connect(self._on_slider)
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
        self.speed.currentIndexChanged.connect(lambda _i: self.clock.set_speed(self.speed.currentData()))
        lay.addWidget(self.speed)
        self.loop_box = QCheckBox("loop")
        self.loop_box.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.loop_box.setToolTip("loop the selected range (drag on the panels to select; Esc clears)")
        self.loop_box.toggled.connect(self._on_loop_toggled)
        lay.addWidget(self.loop_box)
        return bar

    def _dock(self, widget: QWidget, title: str, area: Qt.DockWidgetArea) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(title)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                         | QDockWidget.DockWidgetFeature.DockWidgetClosable)
        self.addDockWidget(area, dock)
        return dock

    def _build_menus(self) -> None:
        mb = self.menuBar()
        file_menu = mb.addMenu("&File")
        self.action_open_corpus = QAction("Open &corpus folder…", self)
        self.action_open_corpus.triggered.connect(self._menu_open_corpus)
        self.action_open_audio = QAction("Open &audio (+ labels) for synthesis…", self)
        self.action_open_audio.triggered.connect(self._menu_open_audio)
        self.action_screenshot = QAction("Save &screenshot…", self)
        self.action_screenshot.triggered.connect(self._menu_screenshot)
        quit_action = QAction("&Quit", self)
        quit_action.setShortcut(QKeySequence.StandardKey.Quit)
        quit_action.triggered.connect(self.close)
        for a in (self.action_open_corpus, self.action_open_audio, self.action_screenshot):
            file_menu.addAction(a)
        file_menu.addSeparator()
        file_menu.addAction(quit_action)
        view_menu = mb.addMenu("&View")
        view_menu.addAction(self.browser_dock.toggleViewAction())
        view_menu.addAction(self.settings_dock.toggleViewAction())
        reset = QAction("Show the whole utterance", self)
        reset.triggered.connect(self.timeline.reset_zoom)
        view_menu.addAction(reset)
        self.view_menu = view_menu
        self.analysis_menu: QMenu = mb.addMenu("&Analysis")
        help_menu = mb.addMenu("&Help")
        keys = QAction("Keys", self)
        keys.triggered.connect(lambda: QMessageBox.information(self, "Keys", KEYS_HELP))
        help_menu.addAction(keys)

    def _build_shortcuts(self) -> None:
        K, M = Qt.Key, Qt.KeyboardModifier
        bindings = [
            (QKeySequence(K.Key_Space), self.toggle_play),
            (QKeySequence(K.Key_Left), lambda: self.step_frames(-1)),
            (QKeySequence(K.Key_Right), lambda: self.step_frames(1)),
            (QKeySequence(M.ShiftModifier | K.Key_Left), lambda: self.step_phone(-1)),
            (QKeySequence(M.ShiftModifier | K.Key_Right), lambda: self.step_phone(1)),
            (QKeySequence(K.Key_Home), lambda: self.seek(0.0)),
            (QKeySequence(K.Key_End), lambda: self.seek(self.clock.duration)),
            (QKeySequence(K.Key_Escape), self.clear_loop),
        ]
        self._shortcuts = []
        for seq, slot in bindings:
            sc = QShortcut(seq, self)
            sc.setContext(Qt.ShortcutContext.WindowShortcut)
            sc.activated.connect(slot)
            self._shortcuts.append(sc)

    # ================================================================== public API (contract)
    def add_dock(self, widget: QWidget, title: str,
                 area: Qt.DockWidgetArea = Qt.DockWidgetArea.RightDockWidgetArea) -> QDockWidget:
        """Add ``widget`` as a dock; docks added to the same area are tabbed together."""
        dock = self._dock(widget, title, area)
        previous = self._extra_docks.get(area)
        if previous is not None:
            self.tabifyDockWidget(previous, dock)
        self._extra_docks[area] = dock
        self.view_menu.addAction(dock.toggleViewAction())
        return dock

    def run_in_background(self, fn: Callable[[Progress], Any], on_done: Callable[[Any], None],
                          progress_label: str, on_error: Callable[[BaseException], None] | None = None,
                          on_partial: Callable[[Any], None] | None = None) -> Task:
        """Run ``fn(progress)`` in a worker thread; ``on_done(result)`` on the GUI thread."""
        task = Task(fn, progress_label, self)
        if self._closing:            # never start work once the window is closing
            return task
        task.progress.connect(lambda f, m: self._on_task_progress(task, f, m))
        task.succeeded.connect(lambda r: self._safe(on_done, r))
        task.failed.connect(lambda e: self._safe(on_error, e) if on_error else self._report_error(e))
        if on_partial is not None:
            task.partial.connect(lambda obj: self._safe(on_partial, obj))
        task.finished.connect(lambda: self._on_task_finished(task))
        self._tasks.append(task)
        self._update_busy(progress_label)
        task.start()
        return task

    def set_utterance(self, utt_id: str) -> None:
        """Show utterance ``utt_id`` (of the corpus, or opened from files): loaded and synthesized in
        the background; ``utteranceChanged`` follows."""
        if self.model is None:
            self._pending_utterance = utt_id
            return
        if utt_id in self.external:
            utt, split = self.external[utt_id], "external"
            self._synthesize(lambda: utt, split, new_utterance=True)
            return
        if self.corpus is None:
            return
        info = self.corpus.info
        if utt_id not in info.ids:
            self._report_error(FacetrajError(f"{utt_id}: no such utterance in {self.corpus.root}"))
            return
        split = "test" if utt_id in info.test else "train"
        corpus = self.corpus
        self._synthesize(lambda: corpus.utterance(utt_id), split, new_utterance=True)

    def seek(self, t: float) -> None:
        """Move the clock, the cursor and the 3-D frame to ``t`` seconds."""
        self.clock.seek(t)
        self._show_time(self.clock.time(), force=True)

    def current_time(self) -> float:
        return self.clock.time()

    # ================================================================== corpus and model
    def open_corpus(self, path: Path, model_path: Path | None = None) -> None:
        """Open a corpus folder; its model is loaded from ``model_path``, the cache, or trained."""
        try:
            corpus = load_corpus(path)
        except FacetrajError as exc:
            self._report_error(exc)
            return

        def work(progress: Progress) -> tuple[Model, dict[str, str]]:
            texts = {}
            for utt_id in corpus.info.ids:
                p = corpus.data_root / f"{utt_id}.txt"
                if p.exists():
                    texts[utt_id] = p.read_text(encoding="utf-8", errors="replace").strip()
            if model_path is not None:
                progress(0.5, f"loading {model_path}")
                model = Model.load(model_path)
            else:
                model = load_or_train(corpus, progress=progress)
            if model.marker_names != corpus.info.marker_names:
                raise FacetrajError(f"{model_path or corpus.root}: the model's marker set differs from "
                                    "the corpus")
            return model, texts

        self.status_label.setText(f"opening {corpus.root} …")
        self.run_in_background(work, lambda r: self._on_model_ready(corpus, *r),
                               "preparing the model (first run trains it)")

    def _on_model_ready(self, corpus: Corpus, model: Model, texts: dict[str, str]) -> None:
        self.stop()
        self.corpus, self.model, self.texts = corpus, model, texts
        self.external.clear()
        self.view = None
        self._request = None
        self.face.set_model(model)
        self.settings.set_limits(model.config.context, model.config.nu, model.tuned)
        info = corpus.info
        self.browser.populate({"test": list(info.test), "train": list(info.train)}, texts)
        self.status_label.setText(f"{corpus.root}: {len(info.train)} training and {len(info.test)} test "
                                  f"utterances, {model.n_markers} markers, {model.pca.n_components} PCs")
        self.modelReady.emit()
        first = self._pending_utterance or self.default_utterance()
        self._pending_utterance = None
        if first:
            self.set_utterance(first)
        self._start_correlations()

    def default_utterance(self) -> str | None:
        """The test sentence "Tornadoes often destroy acres of farm land" (paper Figure 4), else
        the first test utterance."""
        if self.corpus is None:
            return None
        info = self.corpus.info
        want = normalise_text(DEFAULT_SENTENCE)
        for utt_id in [*info.test, *info.train]:
            if normalise_text(self.texts.get(utt_id, "")) == want:
                return utt_id
        return (info.test or info.train or [None])[0]

    # ================================================================== synthesis
    def set_synth_config(self, cfg: SynthConfig) -> None:
        """Use new synthesis settings: re-synthesize the current utterance and the correlations."""
        if cfg == self.synth_config:
            return
        self.synth_config = cfg
        self.settings.set_config(cfg)
        if self._request is not None:
            # the utterance asked for last (it may still be on its way)
            get_utterance, split, new_utterance = self._request
            self._synthesize(get_utterance, split, new_utterance)
        self._start_correlations()

    def _synthesize(self, get_utterance: Callable[[], Utterance], split: str, new_utterance: bool) -> None:
        model = self.model
        cfg = self.synth_config
        self._request = (get_utterance, split, new_utterance)
        self._synth_generation += 1
        gen = self._synth_generation

        def work(progress: Progress) -> UtteranceView:
            utt = get_utterance()
            progress(0.3, f"synthesizing {utt.name}")
            c = cfg if (utt.phones or cfg.mode == "acoustic") else cfg.with_(mode="acoustic")
            return build_view(model, utt, split, c)

        def done(view: UtteranceView) -> None:
            if gen == self._synth_generation and model is self.model:
                self._apply_view(view, new_utterance)

        self.run_in_background(work, done, "synthesizing")

    def _apply_view(self, view: UtteranceView, new_utterance: bool) -> None:
        utt_now = view.utterance
        self._request = (lambda: utt_now, view.split, False)
        t = 0.0 if new_utterance else self.clock.time()
        was_playing = self.clock.playing and not new_utterance
        if new_utterance:
            self.clock.pause()
            self.clock.load(view.utterance.audio, view.utterance.sample_rate)
            self.loop_box.setChecked(False)
            self.timeline.loop = None
            if self._pending_time is not None:
                t, self._pending_time = float(self._pending_time), None
        self.view = view
        self.face.set_view(view)
        self.timeline.set_view(view, keep_zoom=not new_utterance)
        self.slider.blockSignals(True)
        self.slider.setRange(0, view.n_frames - 1)
        self.slider.blockSignals(False)
        utt = view.utterance
        text = f" — “{utt.text}”" if utt.text else ""
        cfg = view.synthesis.config
        shown = {"triangular": "triangular", "spline": "spline", "none": "unsmoothed"}[cfg.smoothing]
        self.title.setText(f"{utt.name} ({view.split}){text}    ·    3-D: {shown} synthesis, "
                           f"{cfg.mode}, N={cfg.n_context_phones}")
        self.browser.set_current(utt.name)
        self._score_current()
        self.status_label.setText(f"{utt.name}: {view.n_frames} frames at {view.rate:g} Hz, "
                                  f"{int(view.speech.sum())} speech frames")
        self.clock.seek(t)
        self._show_time(t, force=True)
        if was_playing and not self.clock.playing:
            self.clock.play()
        if new_utterance:
            self.utteranceChanged.emit(utt.name)
        self.synthesisChanged.emit()

    def _score_current(self) -> None:
        v = self.view
        if v is None or v.original is None or self.model is None:
            return
        try:
            c = trajectory_correlations(v.original, v.shown, v.speech, self.model)
            self.browser.set_scores(v.utterance.name, c["lower_lip"], c["upper_lip"])
        except Exception:
            log.debug("scoring the current utterance failed", exc_info=True)

    def _start_correlations(self) -> None:
        """Lip correlations of every corpus utterance under the current settings, in the background."""
        if self._corr_task is not None:
            self._corr_task.cancel()
        if self.corpus is None or self.model is None:
            return
        self.browser.clear_scores()
        corpus, model, cfg = self.corpus, self.model, self.synth_config
        ids = [(s, u) for s in ("test", "train") for u in getattr(corpus.info, s)]
        smoothing = cfg.smoothing

        clock = self.clock

        def work(progress: Progress) -> None:
            for k, (split, utt_id) in enumerate(ids):
                while clock.playing and not progress.cancelled:
                    time.sleep(0.05)    # playback first: resume when the sound stops
                progress(k / max(len(ids), 1), f"lip correlations: {utt_id}")
                try:
                    utt = corpus.utterance(utt_id)
                    score = evaluate_utterance(model, utt, split, cfg, (smoothing,))[0]
                    progress.partial((utt_id, score.lower_lip, score.upper_lip))
                except FacetrajError as exc:
                    log.warning("%s", exc)
                    progress.partial((utt_id, math.nan, math.nan))
                time.sleep(0.002)   # let the GUI thread have the interpreter

        def partial(obj: tuple[str, float, float]) -> None:
            self.browser.set_scores(*obj)

        self._corr_task = self.run_in_background(work, lambda _r: self.correlationsDone.emit(),
                                                 "lip correlations", on_partial=partial)
        if self._corr_task.isRunning():
            self._corr_task.setPriority(Task.Priority.LowPriority)

    # ================================================================== playback
    def toggle_play(self) -> None:
        if self.view is None:
            return
        self.clock.toggle()

    def play(self) -> None:
        if self.view is not None:
            self.clock.play()

    def pause(self) -> None:
        self.clock.pause()

    def stop(self) -> None:
        self.clock.stop()
        if self.view is not None:
            self._show_time(self.clock.time(), force=True)

    def step_frames(self, n: int) -> None:
        if self.view is None:
            return
        self.clock.pause()
        rate = self.view.rate
        k = int(np.clip(round(self.clock.time() * rate) + n, 0, self.view.n_frames - 1))
        self.seek(k / rate)

    def step_phone(self, direction: int) -> None:
        """Jump to the start of the next (or previous) phone."""
        if self.view is None:
            return
        self.clock.pause()
        t = self.clock.time()
        starts = [s.start for s in self.view.utterance.phones] or [0.0]
        if direction > 0:
            later = [s for s in starts if s > t + 1e-6]
            target = later[0] if later else self.clock.duration
        else:
            earlier = [s for s in starts if s < t - 1e-3]
            target = earlier[-1] if earlier else 0.0
        self.seek(target)

    def clear_loop(self) -> None:
        self.loop_box.setChecked(False)
        self.clock.set_loop(None)
        self.timeline.set_loop(None)

    def _on_loop_selected(self, a: float, b: float) -> None:
        self.clock.set_loop(a, b)
        self.loop_box.setChecked(True)
        self.seek(a)

    def _on_loop_toggled(self, on: bool) -> None:
        self.clock.looping = bool(on)
        if not on:
            self.timeline.set_loop(None)
        elif self.clock.loop is not None:
            self.timeline.set_loop(self.clock.loop)

    def _on_timeline_seek(self, t: float) -> None:
        self.seek(t)

    def _on_slider(self, value: int) -> None:
        if self.view is not None:
            self.seek(value / self.view.rate)

    def _on_playing_changed(self, playing: bool) -> None:
        icon = QStyle.StandardPixmap.SP_MediaPause if playing else QStyle.StandardPixmap.SP_MediaPlay
        self.play_button.setIcon(self.style().standardIcon(icon))
        if playing:
            self._timer.start()
        else:
            self._timer.stop()
            if self.view is not None:
                self._show_time(self.clock.time(), force=True)

    def _tick(self) -> None:
        """One timer tick: show the frame at the audio clock (skip frames, never drift)."""
        if self.view is None:
            return
        t = self.clock.poll()
        if not self.clock.playing:
            self._show_time(t, force=True)
            return
        # aim at the clock time when this update reaches the screen
        end = self.clock.loop[1] if (self.clock.looping and self.clock.loop) else self.clock.duration
        target = min(t + self._latency * self.clock.speed, end)
        k = int(np.clip(round(target * self.view.rate), 0, self.view.n_frames - 1))
        if self._frame_pending is not None:
            if time.perf_counter() - self._frame_pending[0] < 0.25:
                return
            self._frame_pending = None    # no flush came (window hidden?): do not stall
        if k == self.displayed_frame:
            return
        self._frame_pending = (time.perf_counter(), k)
        self._show_time(target, force=True)

    def event(self, e: QEvent) -> bool:
        """The window's flush (UpdateRequest) is when a frame reaches the screen: time it."""
        if e.type() != QEvent.Type.UpdateRequest or self._frame_pending is None:
            return super().event(e)
        result = super().event(e)
        start, k = self._frame_pending
        self._frame_pending = None
        spent = time.perf_counter() - start
        self._latency = min(0.8 * self._latency + 0.2 * spent, 0.08) if self._latency else spent
        if self.stats is not None:
            self.stats.append((start, k, spent, self.clock.time()))
        return result

    def _show_time(self, t: float, force: bool = False) -> None:
        """Put frame round(t * rate) in the 3-D view and the cursor at ``t`` (blitted)."""
        view = self.view
        if view is None:
            return
        rate = view.rate
        k = int(np.clip(round(t * rate), 0, view.n_frames - 1))
        if not force and k == self.displayed_frame:
            return
        phone = _phone_at(view, t)
        # everything is only marked dirty here: the window's next flush puts the 3-D frame, the
        # cursor and the widgets on screen together (one composition per frame)
        self.face.show_frame(k)
        self.displayed_frame = k
        self.slider.blockSignals(True)
        self.slider.setValue(k)
        self.slider.blockSignals(False)
        self.time_label.setText(f"{t:6.3f} / {view.duration:.3f} s  frame {k:4d}  "
                                f"{('/' + phone + '/') if phone else ''}")
        self.timeline.set_cursor(t, follow=self.clock.playing)
        self.cursorMoved.emit(float(t))

    # ================================================================== files
    def _menu_open_corpus(self) -> None:
        path = QFileDialog.getExistingDirectory(self, "Open a corpus folder")
        if path:
            self.open_corpus(Path(path))

    def _menu_open_audio(self) -> None:
        audio, _ = QFileDialog.getOpenFileName(self, "Open audio for synthesis", "",
                                               "Audio (*.wav *.flac);;All files (*)")
        if not audio:
            return
        labels, _ = QFileDialog.getOpenFileName(
            self, "Phone labels (Cancel: acoustic-only synthesis)", str(Path(audio).parent),
            "Labels (*.TextGrid *.lab *.phn);;All files (*)")
        self.open_audio(Path(audio), Path(labels) if labels else None)

    def open_audio(self, audio_path: Path, labels_path: Path | None = None) -> None:
        """Synthesize from an audio file (and phone labels) that has no original markers."""
        if self.model is None:
            self._report_error(FacetrajError("no model yet: open a corpus first"))
            return
        try:
            audio, rate = read_audio(audio_path)
            phones = read_labels(labels_path, rate) if labels_path else []
        except FacetrajError as exc:
            self._report_error(exc)
            return
        name = audio_path.stem
        while name in (self.corpus.info.ids if self.corpus else []):
            name += "'"
        utt = Utterance(name=name, audio=audio, sample_rate=rate, phones=list(phones),
                        markers=None, marker_rate=self.model.marker_rate,
                        marker_names=list(self.model.marker_names), text=str(audio_path))
        self.external[name] = utt
        self.browser.add_external(name)
        self.set_utterance(name)

    def _menu_screenshot(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save a screenshot", "facetraj.png", "PNG (*.png)")
        if path:
            self.save_screenshot(Path(path))

    def save_screenshot(self, path: Path) -> Path:
        """Render the whole window (with the 3-D view) to a PNG."""
        self.face.rerender()
        self.timeline.canvas.draw()
        pix = self.grab()
        img = self.plotter.screenshot(return_img=True)
        if img is not None and img.size:
            h, w = img.shape[:2]
            rgb = np.ascontiguousarray(img[:, :, :3])
            qimg = QImage(rgb.data, w, h, 3 * w, QImage.Format.Format_RGB888)
            painter = QPainter(pix)
            target = self.face.plotter.interactor.mapTo(self, QPoint(0, 0))
            dpr = pix.devicePixelRatio()
            size = self.face.plotter.interactor.size()
            painter.drawImage(target.x(), target.y(), qimg.scaled(int(size.width() * dpr),
                                                                  int(size.height() * dpr)))
            painter.end()
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        if not pix.save(str(path), "PNG"):
            raise FacetrajError(f"{path}: cannot write the screenshot")
        return path

    # ================================================================== tasks and errors
    def _safe(self, fn: Callable[[Any], None] | None, arg: Any) -> None:
        """Call a completion handler; an exception becomes an error dialog (never a crash)."""
        if fn is None:
            return
        try:
            fn(arg)
        except Exception as exc:
            log.exception("handler failed")
            self._report_error(exc)

    def _report_error(self, exc: BaseException) -> None:
        if isinstance(exc, FacetrajError):
            msg = str(exc)
        else:
            log.error("unexpected error", exc_info=exc)
            msg = f"internal error: {type(exc).__name__}: {exc}"
        self.status_label.setText(msg)
        self.show_error(msg)

    def show_error(self, message: str) -> None:
        log.error("%s", message)
        QMessageBox.critical(self, "facetraj", message)

    def _on_task_progress(self, task: Task, fraction: float, message: str) -> None:
        if task is self._corr_task and len(self._tasks) > 1:
            return   # foreground work owns the bar
        self.progress.setValue(int(1000 * fraction))
        self.progress.setFormat(f"{task.label}: %p%")
        if message and task is not self._corr_task:
            self.status_label.setText(message)

    def _on_task_finished(self, task: Task) -> None:
        if task in self._tasks:
            self._tasks.remove(task)
        if task is self._corr_task:
            self._corr_task = None
        task.deleteLater()
        self._update_busy()

    def _update_busy(self, label: str = "") -> None:
        busy = bool(self._tasks)
        self.progress.setVisible(busy)
        if busy and label:
            self.progress.setValue(0)
            self.progress.setFormat(f"{label}: %p%")
        self.busyChanged.emit(busy)

    @property
    def busy(self) -> bool:
        """Whether foreground work (model, synthesis) is running (background correlations aside)."""
        return any(t is not self._corr_task for t in self._tasks)

    def closeEvent(self, event) -> None:
        self._closing = True
        self._timer.stop()
        self.clock.close()
        for task in list(self._tasks):
            task.cancel()
        for task in list(self._tasks):
            task.wait(5000)
        self.face.close_view()
        super().closeEvent(event)


KEYS_HELP = """space\tplay / pause
left / right\tone frame back / forward
shift + left / right\tprevious / next phone
home / end\tstart / end of the utterance
esc\tclear the loop range

On the panels: click to seek, drag to select a loop range,
wheel to zoom the time axis, right-drag to pan, double-click to show all.
In 3-D: drag to rotate, wheel to zoom, hover a marker for its name."""
