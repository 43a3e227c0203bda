"""The app's side of the bad-input fuzz run: the main window opens a mutated file as a user
would (File -> Open audio with its labels, File -> Open corpus folder with a model, an utterance
of that corpus), and the probe tells what happened: an error dialog (its text recorded, then
closed as a user would), the file opened, an internal error, or nothing within the time limit;
and whether the window keeps running afterwards (visible, its event loop turning, seeking).

No exception hook is installed: as in the app users run, an exception escaping into Qt aborts the
process, which the fuzz runner (``tests/fuzzing.py``) sees as a crash of that case.
``tests/test_app_bad_input.py`` drives the same probe under pytest-qt.
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

#: seconds an action may take (a model trained on a small corpus included)
ACTION_TIMEOUT_S = 40.0
#: seconds without foreground work after which an action counts as done
SETTLE_S = 0.4


class AppProbe:
    """Opens files in a main window (``facetraj_app.main_window.MainWindow``) and reports the outcome."""

    def __init__(self, window):
        from PyQt6.QtCore import QTimer

        self.win = window
        self.dialogs: list[str] = []
        self._timer = QTimer(window)
        self._timer.setInterval(25)
        self._timer.timeout.connect(self._close_dialogs)   # runs inside a dialog's own loop too
        self._timer.start()

    def _close_dialogs(self) -> None:
        """An error dialog: its text recorded, closed with its button; a question (the words the
        dictionary lacks, say): its title recorded as ``[question] ...``, cancelled."""
        from PyQt6.QtWidgets import QApplication, QDialog, QMessageBox

        box = QApplication.activeModalWidget()
        if isinstance(box, QMessageBox):
            self.dialogs.append(box.text())
            box.done(0)
        elif isinstance(box, QDialog):
            self.dialogs.append(f"[question] {box.windowTitle()}")
            box.reject()

    def _spin(self, seconds: float) -> None:
        from PyQt6.QtCore import QEventLoop
        from PyQt6.QtWidgets import QApplication

        end = time.monotonic() + seconds
        while time.monotonic() < end:
            QApplication.processEvents(QEventLoop.ProcessEventsFlag.AllEvents, 20)
            time.sleep(0.005)

    def _settle(self, timeout: float) -> bool:
        """Turn the event loop until no foreground work has run for :data:`SETTLE_S` (True), or
        ``timeout`` passes (False)."""
        end = time.monotonic() + timeout
        quiet_since = time.monotonic()
        while time.monotonic() < end:
            self._spin(0.05)
            if self.win.busy:
                quiet_since = time.monotonic()
            elif time.monotonic() - quiet_since >= SETTLE_S:
                return True
        return False

    def act(self, action: Sequence[str]) -> Callable[[], None]:
        """The window's entry point for ``action``: ``("audio", wav, labels or "")``,
        ``("corpus", folder, model or "")`` or ``("utterance", folder, model, id)``."""
        kind, *args = action
        paths = [Path(a) if a else None for a in args[:2]]
        if kind == "audio":
            return lambda: self.win.open_audio(paths[0], paths[1])
        if kind == "corpus":
            return lambda: self.win.open_corpus(paths[0], paths[1])
        if kind == "utterance":
            def open_and_show() -> None:
                self.win.open_corpus(paths[0], paths[1])
                if self._settle(ACTION_TIMEOUT_S) and not self.dialogs:
                    self.win.set_utterance(args[2])
            return open_and_show
        raise ValueError(f"unknown app action {kind!r}")

    def run(self, action: Sequence[str], timeout: float = ACTION_TIMEOUT_S) -> dict:
        """Do ``action`` and report: ``status`` ("dialog": an error dialog; "asked": a question
        dialog only; "opened", "internal error", "hang", "exception", "window gone"), the
        dialogs' texts, seconds."""
        self.dialogs = []
        t0 = time.monotonic()
        try:
            self.act(action)()
        except Exception as exc:       # escaped from the window's own code: a crash in the app
            return {"status": "exception", "message": f"{type(exc).__name__}: {exc}",
                    "seconds": time.monotonic() - t0}
        done = self._settle(timeout)
        status = "dialog" if self.dialogs else "opened" if done else "hang"
        if self.dialogs and all(d.startswith("[question] ") for d in self.dialogs):
            status = "asked"
        if any(d.startswith("internal error") for d in self.dialogs):
            status = "internal error"
        if status != "hang" and not self.alive():
            status = "window gone"
        return {"status": status, "message": " | ".join(self.dialogs)[:400],
                "seconds": time.monotonic() - t0}

    def alive(self) -> bool:
        """The window is shown, its event loop turns and it seeks."""
        from PyQt6.QtCore import QTimer

        fired: list[bool] = []
        QTimer.singleShot(0, lambda: fired.append(True))
        self._spin(0.05)
        if not (fired and self.win.isVisible()):
            return False
        if self.win.view is not None:
            self.win.seek(min(0.2, self.win.clock.duration))
        return True


def run_batch(corpus: str, model: str, actions: list[tuple[int, list[str]]], results: str) -> int:
    """In a process of its own (forked by the fuzz runner, with a display): the window on
    ``corpus`` and ``model``, each action run by :class:`AppProbe`, one JSON line per action
    appended to ``results`` (so that a crash leaves the lines before it)."""
    os.environ.setdefault("QT_LOGGING_RULES", "qt.multimedia.*=false;qt.multimedia.ffmpeg=false")
    from PyQt6.QtWidgets import QApplication

    from facetraj_app.main import build_window
    from facetraj_engine.threads import one_blas_thread

    one_blas_thread()
    app = QApplication.instance() or QApplication(sys.argv[:1])
    win = build_window(Path(corpus), model=Path(model), use_audio=False)
    win.set_correlation_sweep(False)    # no background evaluation whose dialog lands later
    win.resize(1280, 800)
    win.show()
    probe = AppProbe(win)
    if not probe._settle(ACTION_TIMEOUT_S) or probe.dialogs:
        print(f"the window did not open cleanly: {probe.dialogs}", file=sys.stderr)
        return 3
    with open(results, "a", encoding="utf-8") as out:
        for index, action in actions:
            report = probe.run(action)
            out.write(json.dumps({"index": index, **report}) + "\n")
            out.flush()
    win.close()
    app.processEvents()
    return 0
