"""Background work off the GUI thread: a :class:`Task` runs ``fn(progress)`` in a QThread and
reports progress, partial results, the result or the error back on the GUI thread."""

from __future__ import annotations

import logging
import traceback
from collections.abc import Callable
from typing import Any

from PyQt6.QtCore import QObject, QThread, pyqtSignal

log = logging.getLogger(__name__)


class Cancelled(Exception):
    """Raised inside a task's function by :meth:`Progress.__call__` once the task is cancelled."""


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


class Task(QThread):
    """One background job. Signals arrive on the GUI thread (queued)."""

    progress = pyqtSignal(float, str)
    partial = pyqtSignal(object)
    succeeded = pyqtSignal(object)
    failed = pyqtSignal(object)        # the exception

    def __init__(self, fn: Callable[[Progress], Any], label: str = "", parent: QObject | None = None):
        super().__init__(parent)
        self.fn = fn
        self.label = label
        self.is_cancelled = False

    def cancel(self) -> None:
        self.is_cancelled = True

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
