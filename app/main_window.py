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
    from ``state``), ``plotter`` (a plotter widget, ``app/plotter_widget.py``), ``face`` (``FaceView``),
    ``timeline`` (``app/timeline.py``), ``analysis_menu``, ``marker_panels`` (``MarkerPanels``),
    ``closed_lips`` (``facetraj_engine.analysis.lips.ClosedLips`` of the model: the lips at closure),
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
    ``report_error``; ``report_error(exc)`` and ``show_error(message)`` (a dialog, or the handler
    set with ``set_error_handler(fn)``); ``set_correlation_sweep(on)`` (the browser's background
    lip correlations); ``show_status(text, timeout_ms=0)``;
    ``add_extension(name, obj)`` / ``extension(name)``; ``set_utterance(utt_id)``, ``seek(t)``,
    ``current_time()``, ``open_corpus(path)``, ``open_audio(path, labels)``;
    ``leave_checks`` (a list) / ``may_leave(what)``: each ``check(what)`` is asked before the
    labels on screen are left (another utterance or corpus, quitting); one False stays.

Adding a feature
    Write an object that takes the window (like ``OwnData``): its menu entries go into
    ``menu(...)`` (File entries before ``action_screenshot``), a toggle can live in a
    ``QToolBar`` added with ``addToolBar``, its work goes through ``run_task`` and its errors through
    ``report_error``; it follows the window through the signals above. Install it in
    ``app/main.py: build_window`` with ``add_extension``.

Timeline panels
    ``timeline.add_panel(panel)`` / ``timeline.remove_panel(panel)``; a panel is any object with
    ``title: str``, ``height: float`` (relative) and ``draw(ax, view: UtteranceView) -> None``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

from PyQt6.QtCore import QEvent, Qt, pyqtSignal
from PyQt6.QtGui import QKeySequence
from PyQt6.QtWidgets import (
    QDockWidget,
    QMainWindow,
    QMenu,
    QMessageBox,
    QSplitter,
    QWidget,
)

from facetraj_engine.analysis.lips import ClosedLips, closed_lips
from facetraj_engine.config import SynthConfig
from facetraj_engine.data import Utterance
from facetraj_engine.errors import FacetrajError
from facetraj_engine.io.corpus import Corpus
from facetraj_engine.method.model import Model

from .articulators import dimensions_note
from .browser import UtteranceBrowser
from .controls import (
    SPEEDS,
    LoopRange,
    NoticeBar,
    TitleBar,
    TransportBar,
    ViewBar,
    ask_corpus_folder,
    ask_recordings_folder,
    ask_screenshot_path,
    playback_shortcuts,
)
from .correlations import BrowserScores
from .data_opener import DataOpener
from .marker_panels import MarkerPanels
from .open_audio import AudioOpener
from .phases import mark
from .playback import PlaybackScheduler
from .plotter_widget import grab_with_3d
from .provenance import LabelOrigin
from .settings_panel import SynthSettingsPanel
from .state import UtteranceView
from .status import StatusArea
from .timeline import LipPanel, PhoneTierPanel, SpectrogramPanel, Timeline, WaveformPanel
from .transport import PlaybackClock
from .view3d import FaceView
from .viewer_model import (
    DEFAULT_SENTENCE,
    SynthRequest,
    ViewerModel,
    view_summary,
    view_title,
    voice_match_tip,
)
from .window_frame import (
    Column,
    LeftDocks,
    PanelSplit,
    WindowDocks,
    WindowMenus,
    fit_to_screen,
    text_scroll,
)
from .workers import Progress, Task, TaskRunner

__all__ = ["DEFAULT_SENTENCE", "SPEEDS", "MainWindow"]

log = logging.getLogger(__name__)

#: Qt's PNG "quality" sets the zlib level ((100 - quality) * 9 // 91): 80 is level 1, which
#: writes a window screenshot in half the time of the default level and about as small (PNG is
#: lossless either way: the same pixels)
PNG_QUALITY = 80
#: the largest share of the height the panels take from the 3-D view to show every panel
PANELS_SHARE = 0.72
#: the 3-D view's least height (a small window with the view's bars on several rows kept none)
FACE_LEAST_PX = 80

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
        self.tasks.busyChanged.connect(self.busyChanged)
        self.clock = PlaybackClock(self, use_audio=use_audio)
        self.playback = PlaybackScheduler(self.clock, self)
        self.playback.frameDue.connect(lambda t: self._show_time(t, force=True))
        self.playback.prepareDue.connect(self._prepare_time)
        self.clock.playingChanged.connect(self._on_playing_changed)
        self._error_handler: Callable[[str], None] | None = None
        self.closed_lips: ClosedLips | None = None      # the talker's lips at closure (per model)
        self._extensions: dict[str, object] = {}
        self.leave_checks: list[Callable[[str], bool]] = []     # see may_leave
        self.menus = WindowMenus(self, self.report_error)
        self.docks = WindowDocks(self)
        self._build_widgets()
        self.audio_opener = AudioOpener(self)       # "Open audio…" and its label sources
        self.settings.add_widget(self.audio_opener.box)
        _build_menus(self)
        self._shortcuts = playback_shortcuts(self)
        self.opener = DataOpener(self)               # corpora, recordings, the model on its way
        if corpus_path is not None:
            self.opener.open_first_corpus(Path(corpus_path), model_path)

    # ================================================================== state (read-only views)
    model = property(lambda self: self.state.model, doc="The model (None until one is loaded).")
    corpus = property(lambda self: self.state.corpus, doc="The corpus (None until one is opened).")
    view = property(lambda self: self.state.view, doc="The utterance shown (``UtteranceView``).")
    synth_config = property(lambda self: self.state.synth_config, doc="The synthesis settings.")
    pins = property(lambda self: self.state.pins, doc="Results kept to compare (``app/pins.py``).")
    displayed_frame = property(lambda self: self.playback.displayed_frame, doc="The frame on screen.")
    busy = property(lambda self: self.tasks.busy, doc="Whether foreground work (model, synthesis) runs.")
    settled = property(lambda self: self.view is not None and not self.busy and not self.timeline.building,
                       doc="An utterance shown, no foreground work, the panels laid out and drawn.")
    correlations_running = property(lambda self: self.scores.running,
                                    doc="Whether the background lip-correlation sweep runs.")
    stats = property(lambda self: self.playback.stats, lambda self, v: setattr(self.playback, "stats", v),
                     doc="The playback benchmark's hook (see :class:`PlaybackScheduler`).")

    # ================================================================== construction
    def _build_widgets(self) -> None:
        self.face = FaceView(self)
        self.face.setMinimumHeight(FACE_LEAST_PX)
        self.plotter = self.face.plotter
        # a click on the 3-D view or the panels takes the keyboard focus from a spin box or a
        # filter box (which keep the arrows, space, Home and End to themselves): the playback
        # keys work again (the interactor passes it up to the view, VTK gets no key)
        self.plotter.interactor.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.face.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        self.timeline = Timeline(self)
        self.timeline.canvas.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        for panel in (WaveformPanel(), SpectrogramPanel(), PhoneTierPanel(self),
                      LipPanel(self, "upper"), LipPanel(self, "lower")):
            self.timeline.panels.append(panel)
        self.timeline.seekRequested.connect(self.seek)
        self.marker_panels = MarkerPanels(self.timeline)
        self.view_bar = ViewBar(self.face)
        self.camera_buttons = self.view_bar.camera_buttons
        self.transport = _build_transport(self)
        self.title = TitleBar()
        self.notice = NoticeBar()
        self.splitter = _split(Column([self.view_bar, self.face, self.transport], 2, stretch=self.face),
                               Column([self.notice, self.title, self.timeline], 0, stretch=self.timeline))
        self.setCentralWidget(self.splitter)
        # panels left out for lack of room: more of the height for them; kept through resizes
        self.panel_split = PanelSplit(self.splitter, self.timeline, most=PANELS_SHARE)
        self.transport.enlarge.toggled.connect(self.panel_split.enlarge)
        self.utteranceChanged.connect(self.notice.utterance_shown)
        self.modelReady.connect(lambda: self.notice.utterance_shown(""))    # another corpus
        self.browser = UtteranceBrowser(self)
        self.browser.utteranceSelected.connect(self.set_utterance)
        self.browser_dock = self.docks.dock(self.browser, "Utterances", Qt.DockWidgetArea.LeftDockWidgetArea)
        self.settings = SynthSettingsPanel(self.synth_config, self)
        self.settings.configChanged.connect(self.set_synth_config)
        self.settings.searchChosen.connect(lambda cfg: self.set_synth_config(cfg, explicit=True))
        self.settings_dock = self.docks.dock(text_scroll(self.settings), "Synthesis settings",
                                        Qt.DockWidgetArea.LeftDockWidgetArea)
        self.dock_width = self.docks.width_of(Qt.DockWidgetArea.LeftDockWidgetArea)
        self.dock_width.place(400)
        self.left_docks = LeftDocks(self, self.browser_dock, self.settings_dock, self.settings)
        self.status = StatusArea(self.statusBar(), self.tasks)
        self.status_label, self.progress = self.status.label, self.status.progress
        self.dimensions_label = self.status.dimensions_label
        self.scores = BrowserScores(self.browser, self.tasks, self.playback.idle)

    def place_on_screen(self, wanted: tuple[int, int]) -> None:
        """``wanted`` size where the screen has room, else its free area, centred (``fit_to_screen``);
        the browser dock a quarter of the width (at most 400 px): a laptop keeps room for the face."""
        width = fit_to_screen(self, wanted)[2]
        self.dock_width.place(min(400, width // 4))
        self.left_docks.apply()

    # ================================================================== public contract
    def menu(self, name: str) -> QMenu:
        """The menu ``name`` ("File", "View", "Analysis", "Help"; another name: a new menu)."""
        return self.menus.menu(name)

    def add_dock(self, widget: QWidget, title: str,
                 area: Qt.DockWidgetArea = Qt.DockWidgetArea.RightDockWidgetArea) -> QDockWidget:
        """Add ``widget`` as a dock; docks added to the same area are tabbed together."""
        dock = self.docks.add(widget, title, area)
        self.view_menu.addAction(dock.toggleViewAction())
        return dock

    def run_task(self, fn: Callable[[Progress], Any], on_done: Callable[[Any], None] | None, label: str,
                 **options: Any) -> Task:
        """Run ``fn(progress)`` in a worker thread (see :meth:`TaskRunner.run` for ``options``)."""
        return self.tasks.run(fn, on_done, label, **options)

    def report_error(self, exc: BaseException) -> None:
        """Show an error (:func:`error_message`) with :meth:`show_error`."""
        self.show_error(error_message(exc))

    def show_error(self, message: str) -> None:
        """An error message: in the status bar, and a dialog with the message logged (or only the
        ``set_error_handler`` one, which reports it itself: ``facetraj --screenshot`` prints it
        once, as every command does)."""
        self.status_label.setText(message)
        if self._error_handler is not None:
            self._error_handler(message)
        else:
            log.error("%s", message)
            QMessageBox.critical(self, "facetraj", message)

    def set_error_handler(self, handler: Callable[[str], None] | None) -> None:
        """Route error messages to ``handler`` instead of a dialog (None: dialogs again)."""
        self._error_handler = handler

    def show_status(self, text: str, timeout_ms: int = 0) -> None:
        """A message in the status bar (a temporary one with ``timeout_ms``)."""
        self.status.show(text, timeout_ms)

    def show_notice(self, text: str, action_text: str = "", action: Callable[[], Any] | None = None,
                    owner: str = "") -> None:
        """A hint over the panels until closed (or, given an ``owner`` utterance, until another
        is shown), with a button doing ``action``."""
        self.notice.show_notice(text, action_text, action, owner)

    def add_extension(self, name: str, extension: object) -> None:
        self._extensions[name] = extension

    def extension(self, name: str) -> Any:
        """The extension installed under ``name`` (KeyError if none)."""
        return self._extensions[name]

    def may_leave(self, what: str) -> bool:
        """Whether every one of ``leave_checks`` lets the labels on screen go for ``what``."""
        return all(check(what) for check in self.leave_checks)

    def set_utterance(self, utt_id: str) -> None:
        """Show utterance ``utt_id`` (of the corpus, or opened from files): loaded and synthesized in
        the background; ``utteranceChanged`` follows."""
        shown = self.view.utterance.name if self.view is not None else utt_id
        if utt_id != shown and not self.may_leave(f"showing {utt_id}"):
            return self.browser.restore_current(shown)
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

    # ================================================================== corpus and model
    def open_corpus(self, path: Path, model_path: Path | None = None) -> None:
        """Open a corpus folder (a folder of recordings: :meth:`open_recordings`); its model is
        loaded from ``model_path``, the cache, or trained (``app/data_opener.py``)."""
        self.opener.open_corpus(Path(path), model_path)

    def open_recordings(self, path: Path) -> None:
        """Synthesize the recordings of a folder (or one audio file) with the model in use."""
        self.opener.open_recordings(Path(path))

    def when_model_ready(self, fn: Callable[[], Any]) -> None:
        """``fn()`` now if a model is in use and none is on its way, else once it is ready."""
        self.opener.when_model_ready(fn)

    def use_model(self, corpus: Corpus, model: Model, texts: dict[str, str]) -> None:
        """The model of ``corpus`` is ready (``app/data_opener.py``): forget the old model's
        view, show the new corpus and its first utterance."""
        mark("model ready")
        self.stop()         # the old utterance is of the old marker set: the panels, the transport and
        self.playback.set_frames(0, 60.0)   # the title drop it (the 3-D scene: set_model)
        self.transport.set_frames(0)
        self.timeline.set_view(None)
        self.title.setText("")
        first = self.state.set_model(corpus, model, texts)
        self.closed_lips = closed_lips(model)     # the 3-D mouth shuts there; the lip panels' line
        self.face.set_model(model, self.closed_lips)
        self.settings.set_limits(model.config.context, model.config.nu, model.tuned)
        info = corpus.info
        self.browser.populate({"test": list(info.test), "train": list(info.train)}, texts)
        self.status_label.setText(f"{corpus.root}: {len(info.train)} training and {len(info.test)} test "
                                  f"utterances, {model.n_markers} markers, {model.pca.n_components} PCs")
        self.status.set_note(dimensions_note(model))        # midsagittal data, articulators: a
        self.view_bar.set_planar(model.is_planar or self.face.articulators)  # note, the profile
        self.marker_panels.set_model(model)
        self.modelReady.emit()
        if first:
            self.set_utterance(first)
        self._start_sweep()
        self.opener.run_after_model()

    def set_correlation_sweep(self, on: bool) -> None:
        """Whether every corpus utterance's lip correlations are computed in the background (the
        browser's columns; on by default, off for a one-frame screenshot). The utterance shown
        is scored either way."""
        self.scores.enabled = bool(on)
        self._start_sweep()

    def _start_sweep(self) -> None:
        self.scores.start(self.state, lambda _r: self.correlationsDone.emit())

    # ================================================================== synthesis
    def set_synth_config(self, cfg: SynthConfig, explicit: bool = False) -> None:
        """Use new synthesis settings: re-synthesize the current utterance and (when they changed)
        the correlations. ``explicit``: the user chose the search in ``cfg`` (see
        ``ViewerModel.set_config``)."""
        changed, request = self.state.set_config(cfg, explicit)
        if changed:
            self.settings.set_config(cfg)
        if request is not None:
            self._synthesize(request)
        if changed:
            self._start_sweep()

    def _synthesize(self, request: SynthRequest) -> None:
        def done(view: UtteranceView) -> None:
            if self.state.accept(request, view):
                self._apply_view(view, request.new_utterance)

        self.run_task(request.run, done, "synthesizing")

    def _apply_view(self, view: UtteranceView, new_utterance: bool) -> None:
        mark("synthesis done")
        t = 0.0 if new_utterance else self.clock.time()
        was_playing = self.clock.playing and not new_utterance
        if new_utterance:
            self.clock.pause()
            self.clock.load(view.utterance.audio, view.utterance.sample_rate)
            self.loop_box.setChecked(False)
            self.timeline.loop = None
            t = self.state.take_pending_time(t)
        self.playback.set_frames(view.n_frames, view.rate)
        self.view_bar.set_has_original(view.original is not None)
        self.face.set_view(view)
        self.transport.set_frames(view.n_frames)
        self._show_titles(view)
        self.clock.seek(t)
        self._show_time(t, force=True)          # the new faces on screen, then the panels
        self.timeline.set_view(view, keep_zoom=not new_utterance)
        mark("timeline drawn")
        if was_playing and not self.clock.playing:
            self.clock.play()
        if new_utterance:
            self.utteranceChanged.emit(view.utterance.name)
        self.synthesisChanged.emit()

    def _show_titles(self, view: UtteranceView) -> None:
        self.title.setText(view_title(view))
        self.settings.show_used(view.synthesis.config, self.synth_config, view.mode_reason)
        self.browser.set_current(view.utterance.name)
        if not self.state.relabelled:           # the browser's scores: the corpus's labels
            self.scores.score(view, self.model)
        self.status_label.setText(view_summary(view))
        self.status_label.setToolTip(voice_match_tip(view))     # the voice match in words

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
        self._show_time(self.clock.time(), force=True)      # nothing without a view

    def step_frames(self, n: int) -> None:
        if self.view is not None:
            self.clock.pause()
            self.seek(self.state.step_frames_target(self.clock.time(), n))

    def step_phone(self, direction: int) -> None:
        """Jump to the start of the next (or previous) phone."""
        if self.view is not None:
            self.clock.pause()
            self.seek(self.state.step_phone_target(self.clock.time(), direction))

    def _on_slider(self, value: int) -> None:
        if self.view is not None:
            self.seek(value / self.view.rate)

    def _on_playing_changed(self, playing: bool) -> None:
        self.transport.set_playing(playing)
        if not playing:
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

    def _prepare_time(self, t: float) -> None:
        """Render the 3-D frame at ``t`` ahead, off screen (the scheduler shows it at its time)."""
        if self.view is not None:
            self.face.prepare_frame(self.view.frame_at(t))

    # ================================================================== files
    def open_audio(self, audio_path: Path, labels_path: Path | None = None, **kw) -> bool:
        """Synthesize from an audio file (its labels: ``labels_path``, ``text=``, ``recognize=True``,
        ``acoustic_only=True`` or beside it; markers beside it: ``AudioOpener.open``)."""
        if self.state.loading:      # with the model the user will see
            self.when_model_ready(lambda: self.audio_opener.open(Path(audio_path), labels_path, **kw))
            return True
        return self.audio_opener.open(Path(audio_path), labels_path, **kw)

    def show_external(self, utt: Utterance, origin: LabelOrigin | None = None, show: bool = True) -> None:
        """Show an utterance opened from files (listed under "opened" in the browser; only
        listed without ``show``); ``origin``: where its labels came from (the file, the
        transcript aligned)."""
        name = self.state.add_external(utt, origin)
        self.browser.add_external(name)
        if show:
            self.set_utterance(name)

    def show_labels(self, utt: Utterance, origin: LabelOrigin, own: bool = False) -> None:
        """Synthesize the utterance on screen again with the labels of ``utt`` (another label
        source, ``app/label_sources.py``; ``own``: its own again), the time and zoom kept."""
        request = self.state.request_labels(utt, origin, own)
        if request is not None:
            self._synthesize(request)

    def save_screenshot(self, path: Path) -> Path:
        """Render the whole window (with every 3-D view shown, the PC modes' too, as on screen:
        ``grab_with_3d``) to a PNG."""
        self.face.rerender()
        self.timeline.ensure_drawn()
        return _write_png(grab_with_3d(self), Path(path))

    def closeEvent(self, event) -> None:
        self.playback.stop()
        self.clock.close()
        self.tasks.close()
        self.face.close_view()
        super().closeEvent(event)


def _build_transport(w: MainWindow) -> TransportBar:
    """The transport bar, wired to the window's clock and playback."""
    bar = TransportBar()
    bar.playClicked.connect(w.toggle_play)
    bar.stopClicked.connect(w.stop)
    bar.stepClicked.connect(w.step_frames)
    bar.speedChanged.connect(w.clock.set_speed)
    bar.slider.valueChanged.connect(w._on_slider)
    w.slider, w.speed, w.loop_box = bar.slider, bar.speed, bar.loop_box
    w.loop = LoopRange(w.clock, w.timeline, bar.loop_box, w.seek)
    return bar


def _build_menus(w: MainWindow) -> None:
    """The window's own menu entries (File, View, Help)."""
    w.action_open_corpus = w.menus.action("File", "Open &corpus folder…",
                                          lambda: _given(ask_corpus_folder(w), w.open_corpus))
    w.action_open_audio = w.menus.action("File", "Open &audio for synthesis…", lambda: w.audio_opener.ask())
    w.action_open_recordings = w.menus.action("File", "Open a &folder of recordings…",
                                              lambda: _given(ask_recordings_folder(w), w.open_recordings))
    w.action_screenshot = w.menus.action(
        "File", "Save &screenshot…",
        lambda: _given(ask_screenshot_path(w), lambda p: w.show_status(f"wrote {w.save_screenshot(p)}")))
    w.menu("File").addSeparator()
    w.menus.action("File", "&Quit", w.close).setShortcut(QKeySequence.StandardKey.Quit)
    w.view_menu = w.menu("View")
    w.view_menu.addAction(w.browser_dock.toggleViewAction())
    w.view_menu.addAction(w.settings_dock.toggleViewAction())
    w.menus.action("View", "Show the whole utterance", w.timeline.reset_zoom)
    w.view_menu.addSeparator()
    w.action_add_marker_panel = w.menus.action("View", "Add a marker trajectory panel…",
                                               lambda: w.marker_panels.ask(w.model, w))
    w.menus.action("View", "Remove the marker trajectory panels", w.marker_panels.clear)
    w.analysis_menu = w.menu("Analysis")
    w.menus.action("Help", "Keys", lambda: QMessageBox.information(w, "Keys", KEYS_HELP))


def _write_png(image, path: Path) -> Path:
    """Save a grabbed window (a ``QPixmap``) as ``path``, its folder made if need be."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not image.save(str(path), "PNG", PNG_QUALITY):
        raise FacetrajError(f"{path}: cannot write the screenshot")
    return path


def error_message(exc: BaseException) -> str:
    """The engine's own errors as they are (they name the file), anything else as an internal one
    (logged with its traceback)."""
    if isinstance(exc, FacetrajError):
        return str(exc)
    log.error("unexpected error", exc_info=exc)
    return f"internal error: {type(exc).__name__}: {exc}"


def _given(args: tuple | None, fn: Callable[..., Any]) -> None:
    """``fn(*args)`` unless a dialog was cancelled (``args`` None)."""
    if args is not None:
        fn(*args)


def _split(top: QWidget, bottom: QWidget) -> QSplitter:
    """Two widgets one above the other, sharing the height, neither collapsible."""
    split = QSplitter(Qt.Orientation.Vertical)
    split.addWidget(top)
    split.addWidget(bottom)
    split.setStretchFactor(0, 1)
    split.setStretchFactor(1, 1)
    split.setSizes([480, 520])
    split.setChildrenCollapsible(False)
    return split


KEYS_HELP = """space\tplay / pause
left / right\tone frame back / forward
shift + left / right\tprevious / next phone
home / end\tstart / end of the utterance
esc\tclear the loop range
ctrl+p\tpin the result on screen (Compare)

On the panels: click to seek, drag to select a loop range,
wheel to zoom the time axis, right-drag to pan, double-click to show all.
In 3-D: drag to rotate, wheel to zoom, hover a marker for its name."""
