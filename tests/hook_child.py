"""A child process for tests/test_exception_hook_gui.py: the app as ``facetraj gui`` runs it
(``run_app``), with one slot made to fail -- the Right key's (``MainWindow.step_frames``). Once the
first utterance is shown it presses Right (the slot raises), then End (a slot that works), and
prints what the error dialog said and where the window is; ``hook``/``bare`` (argv[2]): with the
app's exception hook, or with Python's own (PyQt6 then aborts the process).

    python tests/hook_child.py CORPUS hook|bare
"""

from __future__ import annotations

import sys
from pathlib import Path

from PyQt6.QtCore import Qt, QTimer
from PyQt6.QtTest import QTest
from PyQt6.QtWidgets import QApplication, QMessageBox

from facetraj_app import exception_hook, main
from facetraj_app.main_window import MainWindow


def injected(self, n: int) -> None:
    raise RuntimeError("injected failure in a slot")


def run(corpus: Path, hooked: bool) -> int:
    QMessageBox.critical = staticmethod(lambda _parent, _title, text, *a, **k: print(f"DIALOG: {text}",
                                                                                     flush=True))
    MainWindow.step_frames = injected
    if not hooked:
        exception_hook.install_exception_hook = lambda window: exception_hook.ExceptionHook(
            window.show_error, exception_hook.ActionTrail(window))     # made, never installed
    built = main.build_window

    def build(*args, **kwargs):
        window = built(*args, **kwargs)
        window.set_correlation_sweep(False)
        def press(key) -> None:
            window.face.setFocus()          # as a click on the 3-D view leaves it: keys reach
            QTest.keyClick(QApplication.focusWidget() or window, key)      # the window's shortcuts

        steps = iter([lambda: press(Qt.Key.Key_Right), lambda: press(Qt.Key.Key_End),
                      lambda: print(f"ALIVE at {window.current_time():.3f} s of "
                                    f"{window.view.duration:.3f} s", flush=True),
                      QApplication.instance().quit])

        def poll() -> None:
            window.activateWindow()
            if window.settled and QApplication.activeWindow() is window:   # keys reach it
                next(steps)()
            QTimer.singleShot(200, poll)

        QTimer.singleShot(0, poll)
        return window

    main.build_window = build
    return main.run_app(corpus)


if __name__ == "__main__":
    sys.exit(run(Path(sys.argv[1]), sys.argv[2] == "hook"))
