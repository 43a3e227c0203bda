"""A matplotlib canvas whose full draws run off the GUI thread.

A full draw of a figure of a few panels takes 100-400 ms on a software-rendered machine; on the
GUI thread that freezes the window (a dock opening resized the timeline and drew it anew, then the
dock's own plots: stalls of 0.4-2 s, issue #29). :class:`BackgroundCanvas` draws in one shared
worker thread into a renderer of its own and copies the finished pixels to the widget on the GUI
thread; until then the widget shows the last picture. Matplotlib supports this: a figure draw
holds ``Figure._render_lock`` (the shared font cache), so one figure draws at a time, in any thread.

The rule that keeps it safe: the GUI thread does not change a figure while it is being drawn.
Code that changes a figure asks :meth:`BackgroundCanvas.when_idle` to run the change (at once when
no draw is running, else right after it), holds the draws with :meth:`hold` while it builds, or
hands a slow build (many ticks and labels: 50-170 ms) to :meth:`rebuild`, which runs it in the
drawing thread just before the draw (it may use the figure and plain data, never a widget).
``draw()`` stays synchronous (exports, screenshots, tests); ``finish()`` brings it all up to date.
"""

from __future__ import annotations

import functools
import logging
import threading
import weakref
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor

from matplotlib.backends.backend_agg import RendererAgg
from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.figure import Figure
from PyQt6 import sip
from PyQt6.QtCore import QObject, QRectF, QSize, QTimer, pyqtSignal
from PyQt6.QtGui import QColor, QImage, QPainter

from .workers import STEP_MS

log = logging.getLogger(__name__)

#: one thread draws every figure (figures draw one at a time anyway: ``Figure._render_lock``)
_DRAWER = ThreadPoolExecutor(max_workers=1, thread_name_prefix="figure-draw")


def _run_builds(builds: list[Callable], figure: Figure) -> None:
    for build in builds:
        try:
            build(figure)
        except Exception:
            log.exception("building a figure failed")


class _Relay(QObject):
    """Carries finished draws from the drawing thread to their canvases on the GUI thread (a
    queued signal). One for the process, made on the GUI thread and never deleted: a relay that
    was a child of its canvas could be deleted with a closed window while the drawing thread
    emitted on it, a segmentation fault (seen once in CI, as a test opened its window)."""

    finished = pyqtSignal(object)      # (weak reference to the canvas, the future of its draw)

    def __init__(self):
        super().__init__()
        self.finished.connect(self._deliver)

    def _deliver(self, item: tuple) -> None:
        ref, future = item
        canvas = ref()
        if canvas is not None and not sip.isdeleted(canvas):
            canvas.take_draw(future)


@functools.cache
def _relay() -> _Relay:
    """The process's relay, made on first use (by a canvas starting a draw, on the GUI
    thread)."""
    return _Relay()


class BackgroundCanvas(FigureCanvasQTAgg):
    """A ``FigureCanvasQTAgg`` whose ``draw_idle`` draws in a worker thread.

    ``drawn`` is emitted on the GUI thread after every full draw (in the background or by
    ``draw()``) once its pixels are in the canvas (``copy_from_bbox`` gives them): use it instead
    of matplotlib's ``draw_event``, which a background draw emits in the drawing thread.
    """

    drawn = pyqtSignal()

    def __init__(self, figure):
        self._drawing: Future | None = None    # the draw running in the worker
        self._again = False              # another draw is due after it
        self._timer_due = False          # a draw is scheduled for the next event-loop pass
        self._held = 0
        self._after: list[Callable[[], None]] = []
        self._builds: list[Callable] = []       # rebuild() functions due before the next draw
        self._drawn_key: tuple | None = None   # figure size and dpi of the pixels in the renderer
        self._last: QImage | None = None       # the last full draw, shown while a resize draws
        self.draws = 0                           # full draws finished (tests, benchmarks)
        super().__init__(figure)
        w, h = self.get_width_height()
        self._hint = QSize(w, h)                 # the figure's size when made: see sizeHint

    def sizeHint(self) -> QSize:
        """The figure's first size. (Matplotlib's canvas hints its present size: in a layout whose
        size depends on its hints, such as a scroll area around word-wrapped text, each resize
        then asks for another, without end: a stack overflow.)"""
        return QSize(self._hint)

    # ------------------------------------------------------------------ state
    @property
    def busy(self) -> bool:
        """Whether a draw is running or due (the pixels are not those of the figure yet)."""
        return (self._drawing is not None or self._timer_due or self._again or self._held > 0
                or bool(self._builds))

    def _size_key(self) -> tuple:
        w, h = self.figure.bbox.size
        return int(w), int(h), float(self.figure.dpi)

    @property
    def current(self) -> bool:
        """Whether the pixels shown are a full draw of the figure at its present size."""
        return not self.busy and self._drawn_key == self._size_key()

    # ------------------------------------------------------------------ requests
    def draw_idle(self) -> None:
        """A full draw in the background, at the next pass of the event loop (requests coalesce)."""
        if self._drawing is not None or self._held:
            self._again = True
            return
        if not self._timer_due:
            self._timer_due = True
            QTimer.singleShot(0, self._start)

    def when_idle(self, fn: Callable[[], None]) -> None:
        """Run ``fn`` (which may change the figure) now, or right after the running draw (once,
        however often it was asked for meanwhile)."""
        if self._drawing is None and not self._builds:
            fn()
        elif fn not in self._after:
            self._after.append(fn)

    def rebuild(self, build: Callable[[Figure], None]) -> None:
        """Run ``build(figure)`` in the drawing thread, then draw: a build too slow for the GUI
        thread. Until it is done the GUI thread leaves the figure alone (``when_idle``)."""
        self._builds.append(build)
        self.draw_idle()

    def hold(self) -> None:
        """No draw starts until :meth:`release` (a figure being built over several passes)."""
        self._held += 1

    def release(self, draw: bool = True) -> None:
        self._held = max(0, self._held - 1)
        if not self._held and (draw or self._again):
            self._again = False
            self.draw_idle()

    def wait(self) -> None:
        """Wait for the running background draw and take its pixels (the figure may then be
        changed on this thread)."""
        future = self._drawing
        if future is not None:
            self.take_draw(future)

    def finish(self) -> None:
        """Bring the pixels up to date now, on this thread (a screenshot, an export): the running
        draw is waited for, a due one is made here."""
        self.wait()
        if self._builds:                # the builds due, then the changes waiting for them
            builds, self._builds = self._builds, []
            _run_builds(builds, self.figure)
            self._run_after()
        if self._timer_due or self._again or self._drawn_key != self._size_key():
            self._timer_due = self._again = False       # the scheduled start finds nothing due
            self.draw()

    # ------------------------------------------------------------------ drawing
    def _start(self) -> None:
        if not self._timer_due:
            return                      # drawn meanwhile (finish)
        self._timer_due = False
        if self._drawing is not None or self._held:
            self._again = True
            return
        w, h = self.get_width_height(physical=True)
        if w <= 1 or h <= 1:
            return                      # not laid out yet: its resize asks again
        key = self._size_key()
        figure = self.figure
        builds, self._builds = self._builds, []

        def work() -> tuple:
            renderer, error = None, None
            _run_builds(builds, figure)
            try:
                renderer = RendererAgg(key[0], key[1], key[2])
                figure.draw(renderer)
            except Exception as exc:    # the figure changed under the draw: drawn again
                error = exc
            return key, renderer, error

        self._drawing = future = _DRAWER.submit(work)

        relay, canvas = _relay(), weakref.ref(self)

        def done(_future) -> None:      # in the worker: to the GUI thread (the relay lives on)
            relay.finished.emit((canvas, future))

        future.add_done_callback(done)

    def take_draw(self, future: Future) -> None:
        """Take the pixels of a finished background draw (on the GUI thread: the relay calls
        it, as does :meth:`wait`)."""
        if future is not self._drawing:
            return                      # taken already (wait)
        key, renderer, error = future.result()
        self._drawing = None
        if error is not None:
            log.debug("background draw failed (%s): drawing on the GUI thread", error)
            builds, self._builds = self._builds, []
            _run_builds(builds, self.figure)
            self._run_after()
            self._again = False
            try:
                self.draw()
            except Exception:
                log.exception("drawing a figure failed")
            return
        if key == self._size_key():
            target = self.get_renderer()
            target.restore_region(renderer.copy_from_bbox(self.figure.bbox))
            self._finished_draw(key)
        if not self._builds:            # changes wait for the builds asked for before them
            self._run_after()
        if (self._again or self._builds) and not self._held:
            self._again = False
            self.draw_idle()

    def _run_after(self) -> None:
        after, self._after = self._after, []
        for fn in after:
            try:
                fn()
            except Exception:
                log.exception("a figure change after a draw failed")

    def draw(self) -> None:
        """A full draw now, on this thread (waits for a background draw to finish)."""
        if threading.current_thread() is not threading.main_thread():
            raise RuntimeError("BackgroundCanvas.draw() is for the GUI thread")
        self.wait()                     # its older picture must not land over this one
        super().draw()
        self._finished_draw(self._size_key())

    def _finished_draw(self, key: tuple) -> None:
        self._drawn_key = key
        self.draws += 1
        self.drawn.emit()
        self.update()

    def resizeEvent(self, event) -> None:
        """Keep the picture of the old size to show (stretched) until the new size is drawn."""
        if self._drawn_key is not None and self._drawn_key == self._size_key():
            buf = self.buffer_rgba()
            self._last = QImage(bytes(buf), buf.shape[1], buf.shape[0],
                                QImage.Format.Format_RGBA8888).copy()
        super().resizeEvent(event)

    def paintEvent(self, event) -> None:
        """The renderer's pixels when they are of the present size; else the last draw, stretched
        (a resize is being drawn anew), or white before the first draw."""
        if self._drawn_key == self._size_key():
            super().paintEvent(event)
            return
        painter = QPainter(self)
        try:
            if self._last is None:
                painter.fillRect(self.rect(), QColor("white"))
            else:
                painter.drawImage(QRectF(self.rect()), self._last)
        finally:
            painter.end()


class SteppedBuild:
    """A figure's build run a step per pass of the event loop (a generator whose steps change the
    figure), after the background draw running (:meth:`BackgroundCanvas.when_idle`): a newer
    build replaces it (closed), :meth:`finish` runs the rest now, and none ever runs inside
    another (``executing``: its step is on the call stack; the owner defers what a step causes,
    e.g. a resize, until after it)."""

    def __init__(self, canvas: BackgroundCanvas):
        self.canvas = canvas
        self.steps = None               # the build under way (None: none)
        self.executing = False

    @property
    def running(self) -> bool:
        return self.steps is not None

    def start(self, steps, soon: bool) -> None:
        """Replace the build under way with ``steps``: run now to the end, or with ``soon`` a
        step per pass of the event loop."""
        self.stop()
        if not soon:
            self.canvas.wait()
            self.advance(steps, to_end=True)
            return
        self.steps = steps

        def step() -> None:
            if self.steps is not steps:
                return                  # replaced by a newer build
            if not self.advance(steps):
                self.steps = None
                return
            QTimer.singleShot(STEP_MS, step)

        self.canvas.when_idle(step)

    def advance(self, steps, to_end: bool = False) -> bool:
        """Run a build's next step (``to_end``: all of them); whether steps are left."""
        self.executing = True
        try:
            for _ in steps:
                if not to_end:
                    return True
            return False
        finally:
            self.executing = False

    def stop(self) -> None:
        steps, self.steps = self.steps, None
        if steps is not None:
            steps.close()

    def finish(self) -> None:
        """The build under way run to its end now (none inside a step: it ends by itself)."""
        if self.executing:
            return
        steps, self.steps = self.steps, None
        if steps is not None:
            self.advance(steps, to_end=True)
