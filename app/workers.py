"""Background work off the GUI thread.

A :class:`Task` runs ``fn(progress)`` in a QThread and reports progress, partial results, the
result or the error back on the GUI thread. A :class:`TaskRunner` is the one place that starts,
tracks and stops tasks: the main window has one (``window.tasks``, behind ``window.run_task``); a
view used on its own, without a window, makes its own. A :class:`Gate` is what a worker waits on
(e.g. "no sound is playing") without polling: opening it, or cancelling the task, wakes it.
:func:`one_per_pass` splits GUI-thread work that cannot leave it (widgets, a 3-D scene) into
steps, one per pass of the event loop, so that the window keeps responding between them.
"""

from __future__ import annotations

import gc
import logging
import threading
import traceback
from collections.abc import Callable, Sequence
from typing import Any

from PyQt6 import sip
from PyQt6.QtCore import QObject, QThread, QTimer, pyqtSignal

log = logging.getLogger(__name__)


#: the delay between two steps of :func:`one_per_pass` (ms): a timer, not a zero-time call, so
#: that the event loop serves other timers, input and paints between the steps (a chain of
#: queued calls was served before the timers: the steps ran back to back)
STEP_MS = 1


def keep_long_lived() -> None:
    """Leave every object alive now out of the garbage collector's later full passes
    (``gc.freeze``), after collecting the young generations' garbage.

    Called once a view has opened: its widgets, figures and artists live as long as the model,
    and a full pass over all of them (170-450 ms, measured while a panel was added with every
    view open) froze the event loop. The price, as at start-up (``facetraj_app.main.long_lived_objects``):
    cyclic garbage already older than the young generations is kept, and objects alive now that
    die later in a reference cycle (the timeline's axes of this moment, at its next relayout)
    are not collected; a few megabytes per view opened.
    """
    gc.collect(1)
    gc.freeze()


def one_per_pass(owner: QObject, steps: Sequence[Callable[[], None]]) -> None:
    """Run ``steps`` on the GUI thread, each in its own pass of the event loop (the first in the
    next pass), in order; the rest are dropped once ``owner`` is deleted. A step that raises is
    logged and the rest still run."""
    remaining = list(steps)

    def step() -> None:
        if not remaining or sip.isdeleted(owner):
            return
        fn = remaining.pop(0)
        try:
            fn()
        except Exception:
            log.exception("a step of %s failed", type(owner).__name__)
        if remaining:
            QTimer.singleShot(STEP_MS, step)

    QTimer.singleShot(STEP_MS, step)


class Cancelled(Exception):
    """Raised inside a task's function by :meth:`Progress.__call__` once the task is cancelled."""


class Gate:
    """An open/closed flag worker threads can wait on (a condition variable, no polling)."""

    def __init__(self, is_open: bool = True):
        self._cond = threading.Condition()
        self._open = is_open

    @property
    def is_open(self) -> bool:
        return self._open

    def set_open(self, is_open: bool) -> None:
        with self._cond:
            self._open = bool(is_open)
            self._cond.notify_all()

    def wake(self) -> None:
        """Wake the waiters so that they look at their stop condition again."""
        with self._cond:
            self._cond.notify_all()

    def wait_open(self, stop: Callable[[], bool] = lambda: False) -> bool:
        """Block until the gate is open or ``stop()`` is true (after a :meth:`wake`); whether open."""
        with self._cond:
            self._cond.wait_for(lambda: self._open or stop())
            return self._open


class Progress:
    """Handed to a task's function: call it with ``(fraction, message)``; ``partial(obj)`` sends an
    intermediate result; ``cancelled`` tells whether to stop (calling it then raises Cancelled)."""

    def __init__(self, task: Task):
        self._task = task

    @property
    def cancelled(self) -> bool:
        return self._task.is_cancelled

    def __call__(self, fraction: float, message: str = "") -> None:
        if self._task.is_cancelled:
            raise Cancelled
        self._task.progress.emit(float(fraction), str(message))

    def partial(self, obj: Any) -> None:
        if self._task.is_cancelled:
            raise Cancelled
        self._task.partial.emit(obj)

    def wait_open(self, gate: Gate) -> None:
        """Wait until ``gate`` is open; raises Cancelled if the task is cancelled meanwhile."""
        self._task.wait_open(gate)


class Task(QThread):
    """One background job. Signals arrive on the GUI thread (queued).

    A ``background`` task runs at low priority and its progress gives way to foreground work."""

    progress = pyqtSignal(float, str)
    partial = pyqtSignal(object)
    succeeded = pyqtSignal(object)
    failed = pyqtSignal(object)        # the exception

    def __init__(self, fn: Callable[[Progress], Any], label: str = "", parent: QObject | None = None,
                 background: bool = False):
        super().__init__(parent)
        self.fn = fn
        self.label = label
        self.background = background
        self.is_cancelled = False
        self._gate: Gate | None = None      # what the task waits on, if anything

    def cancel(self) -> None:
        self.is_cancelled = True
        gate = self._gate
        if gate is not None:
            gate.wake()

    def wait_open(self, gate: Gate) -> None:
        """(In the task's thread) wait until ``gate`` opens; Cancelled when cancelled first."""
        self._gate = gate
        try:
            gate.wait_open(lambda: self.is_cancelled)
        finally:
            self._gate = None
        if self.is_cancelled:
            raise Cancelled

    def run(self) -> None:
        try:
            result = self.fn(Progress(self))
        except Cancelled:
            log.debug("task %r cancelled", self.label)
            return
        except Exception as exc:
            log.debug("task %r failed:\n%s", self.label, traceback.format_exc())
            if not self.is_cancelled:
                self.failed.emit(exc)
            return
        if not self.is_cancelled:
            self.succeeded.emit(result)


_DETACHED: list[Task] = []     # cancelled tasks that outlived their runner's close (see close)


class TaskRunner(QObject):
    """Starts tasks, keeps them until they finish, routes their results and errors, stops them.

    ``error_handler(exc)`` receives the errors of tasks started without ``on_error`` and the
    exceptions raised by completion handlers (a handler never crashes the app). The gate
    ``foreground_idle`` is open while no foreground task runs: background work waits on it, so
    that it never competes with what the user waits for (e.g. the first frame, a synthesis).
    """

    started = pyqtSignal(object)                 # the task
    progressed = pyqtSignal(object, float, str)  # (task, fraction, message)
    finished = pyqtSignal(object)                # the task (succeeded, failed or cancelled)
    busyChanged = pyqtSignal(bool)               # whether any task runs

    def __init__(self, parent: QObject | None = None,
                 error_handler: Callable[[BaseException], None] | None = None):
        super().__init__(parent)
        self.error_handler = error_handler
        self.tasks: list[Task] = []
        self.closed = False
        self.foreground_idle = Gate(is_open=True)

    def run(self, fn: Callable[[Progress], Any], on_done: Callable[[Any], None] | None, label: str, *,
            on_error: Callable[[BaseException], None] | None = None,
            on_partial: Callable[[Any], None] | None = None,
            on_progress: Callable[[float, str], None] | None = None,
            background: bool = False) -> Task:
        """Run ``fn(progress)`` in a worker thread; the callbacks arrive on the GUI thread.

        Once the runner is closed the task is returned without being started."""
        task = Task(fn, label, self, background=background)
        if self.closed:
            return task
        task.progress.connect(lambda f, m: self.progressed.emit(task, f, m))
        if on_progress is not None:
            task.progress.connect(on_progress)
        task.succeeded.connect(lambda r: self._safe(on_done, r))
        task.failed.connect(lambda e: self._safe(on_error, e) if on_error else self._error(e))
        if on_partial is not None:
            task.partial.connect(lambda obj: self._safe(on_partial, obj))
        task.finished.connect(lambda: self._finished(task))
        self.tasks.append(task)
        if not background:
            self.foreground_idle.set_open(False)
        task.start()
        if background and task.isRunning():
            task.setPriority(Task.Priority.LowPriority)
        self.started.emit(task)
        self.busyChanged.emit(True)
        return task

    @property
    def busy(self) -> bool:
        """Whether foreground work is running (background tasks aside)."""
        return any(not t.background for t in self.tasks)

    def running(self, task: Task | None) -> bool:
        return task is not None and task in self.tasks

    def close(self, timeout_ms: int = 5000) -> None:
        """Start nothing more; cancel every task and wait for it (before the owner closes).

        A task still running after ``timeout_ms`` (a long synthesis notices the cancellation only
        at its next progress call) is detached from the owner and kept alive until it ends, so
        that closing the owner never destroys a running thread (Qt aborts the process then)."""
        self.closed = True
        for task in list(self.tasks):
            task.cancel()
        for task in list(self.tasks):
            if not task.wait(timeout_ms):
                log.warning("task %r still running after %d ms: detached", task.label, timeout_ms)
                for signal in (task.finished, task.progress, task.partial):
                    try:
                        signal.disconnect()     # its receivers close with the owner
                    except TypeError:
                        pass                    # it had none
                task.setParent(None)
                _DETACHED.append(task)

    def _safe(self, fn: Callable[[Any], None] | None, arg: Any) -> None:
        """Call a completion handler; its exception goes to the error handler (never a crash)."""
        if fn is None:
            return
        try:
            fn(arg)
        except Exception as exc:
            log.exception("handler failed")
            self._error(exc)

    def _error(self, exc: BaseException) -> None:
        if self.error_handler is not None:
            self.error_handler(exc)
        else:
            log.error("background task failed", exc_info=exc)

    def _finished(self, task: Task) -> None:
        if task in self.tasks:
            self.tasks.remove(task)
        task.deleteLater()
        self.foreground_idle.set_open(not self.busy)
        self.finished.emit(task)
        self.busyChanged.emit(bool(self.tasks))
