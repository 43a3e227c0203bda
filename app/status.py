"""The main window's status bar: a message, a note for midsagittal data and articulograph sensors,
and the progress of the task runner's work (foreground work owns the bar; background work shows
when nothing else runs). The message and the note are elided to their room (the whole text in
the tooltip): a long message never sets the window's least width (a summary 901 px long kept the
window from being narrower, and its end was cut off on a laptop)."""

from __future__ import annotations

from PyQt6.QtWidgets import QProgressBar, QStatusBar

from .elided import ElidedLabel
from .workers import Task, TaskRunner


class StatusArea:
    """The widgets of one status bar, following one :class:`TaskRunner`."""

    def __init__(self, bar: QStatusBar, tasks: TaskRunner):
        self.bar = bar
        self.tasks = tasks
        self.label = ElidedLabel("")
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setFixedWidth(300)
        self.progress.setVisible(False)
        self.dimensions_label = ElidedLabel("midsagittal (2-D) data: profile view, y up, z forward")
        self.dimensions_label.setStyleSheet("font-weight: 600; padding: 0 8px;")
        self.dimensions_label.hide()
        bar.addWidget(self.label, 1)
        bar.addPermanentWidget(self.dimensions_label)
        bar.addPermanentWidget(self.progress)
        tasks.started.connect(self._on_started)
        tasks.progressed.connect(self._on_progress)
        tasks.busyChanged.connect(self.progress.setVisible)

    def set_note(self, note: str) -> None:
        """The note on how the markers are shown (midsagittal data, articulograph sensors:
        ``app/articulators.py: dimensions_note``); hidden when empty."""
        self.dimensions_label.setText(note)
        self.dimensions_label.setVisible(bool(note))

    def show(self, text: str, timeout_ms: int = 0) -> None:
        """A message (a temporary one with ``timeout_ms``)."""
        if timeout_ms:
            self.bar.showMessage(text, timeout_ms)
        else:
            self.label.setText(text)

    def _on_started(self, task: Task) -> None:
        self.progress.setVisible(True)
        self.progress.setValue(0)
        self.progress.setFormat(f"{task.label}: %p%")

    def _on_progress(self, task: Task, fraction: float, message: str) -> None:
        if task.background and self.tasks.busy:
            return   # foreground work owns the bar
        self.progress.setValue(int(1000 * fraction))
        self.progress.setFormat(f"{task.label}: %p%")
        if message and not task.background:
            self.label.setText(message)
