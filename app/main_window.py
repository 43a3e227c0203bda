"""The facetraj main window: it lays out the widgets and wires their signals.

Architecture
============
``state: ViewerModel`` (``app/viewer_model.py``, no Qt) holds the corpus, the model, the synthesis
settings, the current view and the latest synthesis request with its generation number (stale
results are dropped there); ``tasks: TaskRunner`` (``app/workers.py``) runs all background work;
``playback: PlaybackScheduler`` (``app/playback.py``) paces the frames while the sound of ``clock``
plays. Extensions (``app/own_data.py: OwnData``, ``app/analysis: AnalysisViews``) are objects that
take the window and use only the contract below; ``app/main.py: build_window`` installs them.

Window contract
===============
Attributes
    ``model``, ``corpus``, ``view`` (``UtteranceView``, ``app/state.py``), ``synth_config`` (read
    from ``state``), ``plotter`` (the pyvistaqt ``QtInteractor``), ``face`` (``FaceView``),
    ``timeline`` (``app/timeline.py``), ``analysis_menu``, ``marker_panels`` (``MarkerPanels``),
    ``action_screenshot`` (File-menu entries of extensions go before it).

Signals
    ``utteranceChanged(str)`` after a new utterance is shown (``view`` already updated);
    ``cursorMoved(float)`` the cursor time in seconds, at most once per displayed frame;
    ``synthesisChanged()`` after every (re)synthesis; ``modelReady()`` after a model is loaded;
    ``busyChanged(bool)``.

Methods
    ``menu(name) -> QMenu``: the menu "File", "View", "Analysis", "Help", or a new one (added
    before Help); ``add_dock(widget, title, area=Right) -> QDockWidget`` (listed in View);
    ``run_task(fn, on_done, label, *, on_error=None, on_partial=None, on_progress=None,
    background=False) -> Task``: ``fn(progress)`` in a worker thread, the status bar shows its
    progress, the callbacks run on the GUI thread, an error goes to ``on_error`` or
    ``report_error``; ``report_error(exc)`` (a dialog, or the handler set with
    ``set_error_handler(fn)``); ``show_status(text, timeout_ms=0)``;
    ``add_extension(name, obj)`` / ``extension(name)``; ``set_utterance(utt_id)``, ``seek(t)``,
    ``current_time()``, ``open_corpus(path)``, ``open_audio(path, labels)``.

Timeline panels
    ``timeline.add_panel(panel)`` / ``timeline.remove_panel(panel)``; a panel is any object with
    ``title: str``, ``height: float`` (relative) and ``draw(ax, view: UtteranceView) -> None``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

from PyQt6.QtCore import QEvent, Qt, QTimer, pyqtSignal
from PyQt6.QtGui import QAction, QKeySequence, QShortcut
from PyQt6.QtWidgets import (
    QDockWidget,
    QFileDialog,
    QLabel,
    QMainWindow,
    QMenu,
    QMessageBox,
    QProgressBar,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

from engine.config import SynthConfig
from engine.corpus import Corpus, load_corpus
from engine.data import Utterance
from engine.errors import FacetrajError
from engine.evaluation import trajectory_correlations
from engine.formats import read_audio, read_labels
from engine.model import Model

from .browser import UtteranceBrowser
from .cache import load_or_train
from .controls import SPEEDS, TransportBar, ViewBar
from .marker_panels import MarkerPanels
from .playback import PlaybackScheduler
from .settings_panel import SynthSettingsPanel
from .state import UtteranceView
from .timeline import LipPanel, PhoneTierPanel, SpectrogramPanel, Timeline, WaveformPanel
from .transport import PlaybackClock
from .view3d import FaceView
from .viewer_model import DEFAULT_SENTENCE, SynthRequest, ViewerModel, correlation_sweep, load_model
from .workers import Progress, Task, TaskRunner

__all__ = ["DEFAULT_SENTENCE", "SPEEDS", "MainWindow"]

log = logging.getLogger(__name__)

SMOOTHING_NAMES = {"triangular": "triangular", "spline": "spline", "none": "unsmoothed"}


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
        self.state = ViewerModel(pending_utterance=utterance, pending_time=start_time)
        self.tasks = TaskRunner(self, error_handler=self.report_error)
        self.tasks.started.connect(self._on_task_started)
        self.tasks.progressed.connect(self._on_task_progress)
        self.tasks.busyChanged.connect(self._on_busy_changed)
        self.clock = PlaybackClock(self, use_audio=use_audio)
        self.playback = PlaybackScheduler(self.clock, self)
        self.playback.frameDue.connect(lambda t: self._show_time(t, force=True))
        self.clock.playingChanged.connect(self._on_playing_changed)
        self._corr_task: Task | None = None
        self._error_handler: Callable[[str], None] | None = None
        self._extensions: dict[str, object] = {}
        self._menus: dict[str, QMenu] = {}
        self._build_widgets()
        self._build_menus()
        self._build_shortcuts()
        if corpus_path is not None:
            QTimer.singleShot(0, lambda: self.open_corpus(Path(corpus_path), model_path))

    # ================================================================== state (read-only views)
    @property
    def model(self) -> Model | None:
        return self.state.model

    @property
    def corpus(self) -> Corpus | None:
        return self.state.corpus

    @property
    def view(self) -> UtteranceView | None:
        return self.state.view

    @property
    def synth_config(self) -> SynthConfig:
        return self.state.synth_config

    @property
    def displayed_frame(self) -> int:
        return self.playback.displayed_frame

    @property
    def stats(self) -> list | None:
        """The playback benchmark's hook (see :class:`PlaybackScheduler`)."""
        return self.playback.stats

    @stats.setter
    def stats(self, value: list | None) -> None:
        self.playback.stats = value

    @property
    def busy(self) -> bool:
        """Whether foreground work (model, synthesis) is running (background correlations aside)."""
        return self.tasks.busy

    @property
    def correlations_running(self) -> bool:
        return self.tasks.running(self._corr_task)

    # ================================================================== construction
    def _build_widgets(self) -> None:
        self.face = FaceView(self)
        self.plotter = self.face.plotter
        self.plotter.interactor.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.timeline = Timeline(self)
        for panel in (WaveformPanel(), SpectrogramPanel(), PhoneTierPanel(),
                      LipPanel(self, "upper"), LipPanel(self, "lower")):
            self.timeline.panels.append(panel)
        self.timeline.seekRequested.connect(self.seek)
        self.timeline.loopSelected.connect(self._on_loop_selected)
        self.marker_panels = MarkerPanels(self.timeline)
        self.view_bar = ViewBar(self.face)
        self.camera_buttons = self.view_bar.camera_buttons
        self.transport = self._build_transport()
        self.title = QLabel("")
        self.title.setStyleSheet("font-size: 15px; font-weight: 600; padding: 2px 6px;")
        split = QSplitter(Qt.Orientation.Vertical)
        split.addWidget(_column([self.view_bar, self.face, self.transport], 2, stretch=self.face))
        split.addWidget(_column([self.title, self.timeline], 0, stretch=self.timeline))
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
        self._build_status_bar()

    def _build_transport(self) -> TransportBar:
        bar = TransportBar()
        bar.playClicked.connect(self.toggle_play)
        bar.stopClicked.connect(self.stop)
        bar.stepClicked.connect(self.step_frames)
        bar.speedChanged.connect(self.clock.set_speed)
        bar.slider.valueChanged.connect(self._on_slider)
        bar.loop_box.toggled.connect(self._on_loop_toggled)
        self.slider, self.speed, self.loop_box = bar.slider, bar.speed, bar.loop_box
        self.time_label = bar.time_label
        return bar

    def _build_status_bar(self) -> None:
        self.status_label = QLabel("")
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setFixedWidth(300)
        self.progress.setVisible(False)
        self.dimensions_label = QLabel("midsagittal (2-D) data: profile view, y up, z forward")
        self.dimensions_label.setStyleSheet("font-weight: 600; padding: 0 8px;")
        self.dimensions_label.hide()
        self.statusBar().addWidget(self.status_label, 1)
        self.statusBar().addPermanentWidget(self.dimensions_label)
        self.statusBar().addPermanentWidget(self.progress)

    def _dock(self, widget: QWidget, title: str, area: Qt.DockWidgetArea) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(title)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                         | QDockWidget.DockWidgetFeature.DockWidgetClosable)
        self.addDockWidget(area, dock)
        return dock

    def _action(self, menu: str, text: str, slot: Callable[[], Any]) -> QAction:
        action = QAction(text, self)
        action.triggered.connect(lambda _c=False: slot())
        self.menu(menu).addAction(action)
        return action

    def _build_menus(self) -> None:
        self.action_open_corpus = self._action("File", "Open &corpus folder…", self._menu_open_corpus)
        self.action_open_audio = self._action("File", "Open &audio (+ labels) for synthesis…",
                                              self._menu_open_audio)
        self.action_screenshot = self._action("File", "Save &screenshot…", self._menu_screenshot)
        self.menu("File").addSeparator()
        self._action("File", "&Quit", self.close).setShortcut(QKeySequence.StandardKey.Quit)
        self.view_menu = self.menu("View")
        self.view_menu.addAction(self.browser_dock.toggleViewAction())
        self.view_menu.addAction(self.settings_dock.toggleViewAction())
        self._action("View", "Show the whole utterance", self.timeline.reset_zoom)
        self.view_menu.addSeparator()
        self.action_add_marker_panel = self._action("View", "Add a marker trajectory panel…",
                                                    self._ask_marker_panel)
        self._action("View", "Remove the marker trajectory panels", self.marker_panels.clear)
        self.analysis_menu = self.menu("Analysis")
        self._action("Help", "Keys", lambda: QMessageBox.information(self, "Keys", KEYS_HELP))

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

    # ================================================================== public contract
    def menu(self, name: str) -> QMenu:
        """The menu ``name`` ("File", "View", "Analysis", "Help"; another name: a new menu)."""
        if name not in self._menus:
            help_menu = self._menus.get("Help")
            if help_menu is None:
                self._menus[name] = self.menuBar().addMenu(f"&{name}")
            else:
                self._menus[name] = QMenu(f"&{name}", self)
                self.menuBar().insertMenu(help_menu.menuAction(), self._menus[name])
        return self._menus[name]

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

    def run_task(self, fn: Callable[[Progress], Any], on_done: Callable[[Any], None] | None, label: str,
                 **options: Any) -> Task:
        """Run ``fn(progress)`` in a worker thread (see :meth:`TaskRunner.run` for ``options``)."""
        return self.tasks.run(fn, on_done, label, **options)

    def report_error(self, exc: BaseException) -> None:
        """Show an error: the engine's own errors as they are, anything else as an internal one."""
        if isinstance(exc, FacetrajError):
            msg = str(exc)
        else:
            log.error("unexpected error", exc_info=exc)
            msg = f"internal error: {type(exc).__name__}: {exc}"
        self.status_label.setText(msg)
        log.error("%s", msg)
        if self._error_handler is not None:
            self._error_handler(msg)
        else:
            QMessageBox.critical(self, "facetraj", msg)

    def set_error_handler(self, handler: Callable[[str], None] | None) -> None:
        """Route error messages to ``handler`` instead of a dialog (None: dialogs again)."""
        self._error_handler = handler

    def show_status(self, text: str, timeout_ms: int = 0) -> None:
        """A message in the status bar (a temporary one with ``timeout_ms``)."""
        if timeout_ms:
            self.statusBar().showMessage(text, timeout_ms)
        else:
            self.status_label.setText(text)

    def add_extension(self, name: str, extension: object) -> None:
        self._extensions[name] = extension

    def extension(self, name: str) -> Any:
        """The extension installed under ``name`` (KeyError if none)."""
        return self._extensions[name]

    def set_utterance(self, utt_id: str) -> None:
        """Show utterance ``utt_id`` (of the corpus, or opened from files): loaded and synthesized in
        the background; ``utteranceChanged`` follows."""
        try:
            request = self.state.request_utterance(utt_id)
        except FacetrajError as exc:
            self.report_error(exc)
            return
        if request is not None:
            self._synthesize(request)

    def seek(self, t: float) -> None:
        """Move the clock, the cursor and the 3-D frame to ``t`` seconds."""
        self.clock.seek(t)
        self._show_time(self.clock.time(), force=True)

    def current_time(self) -> float:
        return self.clock.time()

    def default_utterance(self) -> str | None:
        return self.state.default_utterance()

    # ================================================================== corpus and model
    def open_corpus(self, path: Path, model_path: Path | None = None) -> None:
        """Open a corpus folder; its model is loaded from ``model_path``, the cache, or trained."""
        try:
            corpus = load_corpus(path)
        except FacetrajError as exc:
            self.report_error(exc)
            return
        self.status_label.setText(f"opening {corpus.root} …")
        self.run_task(lambda p: load_model(corpus, model_path, p, load_or_train),
                      lambda r: self._on_model_ready(corpus, *r), "preparing the model (first run trains it)")

    def _on_model_ready(self, corpus: Corpus, model: Model, texts: dict[str, str]) -> None:
        self.stop()
        first = self.state.set_model(corpus, model, texts)
        self.face.set_model(model)
        self.settings.set_limits(model.config.context, model.config.nu)
        info = corpus.info
        self.browser.populate({"test": list(info.test), "train": list(info.train)}, texts)
        self.status_label.setText(f"{corpus.root}: {len(info.train)} training and {len(info.test)} test "
                                  f"utterances, {model.n_markers} markers, {model.pca.n_components} PCs")
        self._show_planar(model.is_planar)
        self.marker_panels.set_model(model)
        self.modelReady.emit()
        if first:
            self.set_utterance(first)
        self._start_correlations()

    def _show_planar(self, planar: bool) -> None:
        """Midsagittal (2-D) data is shown as such: the profile camera and a status-bar note."""
        self.dimensions_label.setVisible(planar)
        if planar:
            self.view_bar.set_camera("profile")

    def _ask_marker_panel(self) -> None:
        if self.model is None:
            self.report_error(FacetrajError("no model yet"))
            return
        self.marker_panels.ask(self.model, self)

    # ================================================================== synthesis
    def set_synth_config(self, cfg: SynthConfig) -> None:
        """Use new synthesis settings: re-synthesize the current utterance and the correlations."""
        changed, request = self.state.set_config(cfg)
        if not changed:
            return
        self.settings.set_config(cfg)
        if request is not None:
            self._synthesize(request)
        self._start_correlations()

    def _synthesize(self, request: SynthRequest) -> None:
        def done(view: UtteranceView) -> None:
            if self.state.accept(request, view):
                self._apply_view(view, request.new_utterance)

        self.run_task(request.run, done, "synthesizing")

    def _apply_view(self, view: UtteranceView, new_utterance: bool) -> None:
        t = 0.0 if new_utterance else self.clock.time()
        was_playing = self.clock.playing and not new_utterance
        if new_utterance:
            self.clock.pause()
            self.clock.load(view.utterance.audio, view.utterance.sample_rate)
            self.loop_box.setChecked(False)
            self.timeline.loop = None
            t = self.state.take_pending_time(t)
        self.playback.set_frames(view.n_frames, view.rate)
        self.face.set_view(view)
        self.timeline.set_view(view, keep_zoom=not new_utterance)
        self.transport.set_frames(view.n_frames)
        self._show_titles(view)
        self.clock.seek(t)
        self._show_time(t, force=True)
        if was_playing and not self.clock.playing:
            self.clock.play()
        if new_utterance:
            self.utteranceChanged.emit(view.utterance.name)
        self.synthesisChanged.emit()

    def _show_titles(self, view: UtteranceView) -> None:
        utt, cfg = view.utterance, view.synthesis.config
        text = f" — “{utt.text}”" if utt.text else ""
        self.title.setText(f"{utt.name} ({view.split}){text}    ·    3-D: {SMOOTHING_NAMES[cfg.smoothing]} "
                           f"synthesis, {cfg.mode}, N={cfg.n_context_phones}")
        self.browser.set_current(utt.name)
        self._score_current()
        self.status_label.setText(f"{utt.name}: {view.n_frames} frames at {view.rate:g} Hz, "
                                  f"{int(view.speech.sum())} speech frames")

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
        """Lip correlations of every corpus utterance under the current settings, in the background;
        the sweep waits while sound plays (playback first)."""
        if self._corr_task is not None:
            self._corr_task.cancel()
        st = self.state
        if st.corpus is None or st.model is None:
            return
        self.browser.clear_scores()
        corpus, model, cfg, ids = st.corpus, st.model, st.synth_config, st.correlation_ids()
        idle = self.playback.idle

        def work(progress: Progress) -> None:
            def before(k: int, utt_id: str) -> None:
                progress.wait_open(idle)
                progress(k / max(len(ids), 1), f"lip correlations: {utt_id}")

            for _k, utt_id, lower, upper in correlation_sweep(model, corpus, ids, cfg, before):
                progress.partial((utt_id, lower, upper))

        self._corr_task = self.run_task(work, lambda _r: self.correlationsDone.emit(), "lip correlations",
                                        on_partial=lambda obj: self.browser.set_scores(*obj),
                                        background=True)

    # ================================================================== playback
    def toggle_play(self) -> None:
        if self.view is not None:
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
        if self.view is not None:
            self.clock.pause()
            self.seek(self.state.step_frames_target(self.clock.time(), n))

    def step_phone(self, direction: int) -> None:
        """Jump to the start of the next (or previous) phone."""
        if self.view is not None:
            self.clock.pause()
            self.seek(self.state.step_phone_target(self.clock.time(), direction))

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

    def _on_slider(self, value: int) -> None:
        if self.view is not None:
            self.seek(value / self.view.rate)

    def _on_playing_changed(self, playing: bool) -> None:
        self.transport.set_playing(playing)
        if not playing and self.view is not None:
            self._show_time(self.clock.time(), force=True)

    def event(self, e: QEvent) -> bool:
        """The window's flush (UpdateRequest) is when a frame reaches the screen: the scheduler
        times it."""
        if e.type() != QEvent.Type.UpdateRequest or not self.playback.pending:
            return super().event(e)
        result = super().event(e)
        self.playback.flushed()
        return result

    def _show_time(self, t: float, force: bool = False) -> None:
        """Put frame round(t * rate) in the 3-D view and the cursor at ``t`` (blitted)."""
        view = self.view
        if view is None:
            return
        k = view.frame_at(t)
        if not force and k == self.displayed_frame:
            return
        phone = self.state.phone_at(t)
        # everything is only marked dirty here: the window's next flush puts the 3-D frame, the
        # cursor and the widgets on screen together (one composition per frame)
        self.face.show_frame(k)
        self.playback.shown(k)
        self.transport.show_frame(k, f"{t:6.3f} / {view.duration:.3f} s  frame {k:4d}  "
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
        model = self.model
        if model is None:
            self.report_error(FacetrajError("no model yet: open a corpus first"))
            return
        try:
            audio, rate = read_audio(audio_path)
            phones = read_labels(labels_path, rate) if labels_path else []
        except FacetrajError as exc:
            self.report_error(exc)
            return
        utt = Utterance(name=audio_path.stem, audio=audio, sample_rate=rate, phones=list(phones),
                        markers=None, marker_rate=model.marker_rate,
                        marker_names=list(model.marker_names), text=str(audio_path))
        name = self.state.add_external(utt)
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
        self.face.paint_into(pix, self)
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        if not pix.save(str(path), "PNG"):
            raise FacetrajError(f"{path}: cannot write the screenshot")
        return path

    # ================================================================== tasks
    def _on_task_started(self, task: Task) -> None:
        self.progress.setVisible(True)
        self.progress.setValue(0)
        self.progress.setFormat(f"{task.label}: %p%")

    def _on_task_progress(self, task: Task, fraction: float, message: str) -> None:
        if task.background and self.tasks.busy:
            return   # foreground work owns the bar
        self.progress.setValue(int(1000 * fraction))
        self.progress.setFormat(f"{task.label}: %p%")
        if message and not task.background:
            self.status_label.setText(message)

    def _on_busy_changed(self, busy: bool) -> None:
        self.progress.setVisible(busy)
        self.busyChanged.emit(busy)

    def closeEvent(self, event) -> None:
        self.playback.stop()
        self.clock.close()
        self.tasks.close()
        self.face.close_view()
        super().closeEvent(event)


def _column(widgets: list[QWidget], spacing: int, stretch: QWidget) -> QWidget:
    """Widgets stacked vertically without margins; ``stretch`` takes the spare height."""
    box = QWidget()
    lay = QVBoxLayout(box)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.setSpacing(spacing)
    for w in widgets:
        lay.addWidget(w, 1 if w is stretch else 0)
    return box


KEYS_HELP = """space\tplay / pause
left / right\tone frame back / forward
shift + left / right\tprevious / next phone
home / end\tstart / end of the utterance
esc\tclear the loop range

On the panels: click to seek, drag to select a loop range,
wheel to zoom the time axis, right-drag to pan, double-click to show all.
In 3-D: drag to rotate, wheel to zoom, hover a marker for its name."""
