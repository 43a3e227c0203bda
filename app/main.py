"""``run_app``: the entry point of ``facetraj`` (no arguments), ``facetraj gui`` and
``facetraj --screenshot OUT.png``."""

from __future__ import annotations

import gc
import logging
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .display import ensure_display, require_display, route_qt_messages
from .phases import mark

log = logging.getLogger(__name__)

WINDOW_SIZE = (1600, 1000)


@contextmanager
def long_lived_objects() -> Iterator[None]:
    """A block that makes objects living as long as the process (the window's imports: some
    250,000 objects): the cyclic garbage collector pauses during it and leaves its objects out of
    later passes (``gc.freeze``): full passes over them held up the first frame (issue #15)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if was_enabled:
            gc.enable()


@contextmanager
def matplotlib_without_property_docs() -> Iterator[None]:
    """A block that imports matplotlib (if nothing did before) without its property tables.

    While it is first imported, matplotlib writes the docstring of each artist class's ``set``
    and of the plotting methods that pass properties on: tables of every settable property
    (``matplotlib.artist.kwdoc``), about 0.2 s of the window's imports (issue #15), for
    ``help()`` text the app never shows. Within this block ``kwdoc`` gives an empty text; the
    ``set`` signatures, the properties and everything drawn are unchanged. Once matplotlib is
    imported the block does nothing.
    """
    if "matplotlib.figure" in sys.modules:
        yield
        return
    import matplotlib.artist

    kwdoc = matplotlib.artist.kwdoc
    matplotlib.artist.kwdoc = lambda _artist: ""
    try:
        yield
    finally:
        matplotlib.artist.kwdoc = kwdoc


def build_window(corpus: Path | str | None, model: Path | None = None, utterance: str | None = None,
                 time: float | None = None, use_audio: bool | None = None):
    """The main window as users get it: with the analysis views and the import/export entries.

    A view set that fails to install is logged and left out; the window still opens.
    """
    with matplotlib_without_property_docs():
        from . import analysis, compare, label_editing, label_files, live, measure, own_data, review_dock
        from .main_window import MainWindow

    mark("window modules imported")
    window = MainWindow(None if corpus is None else Path(corpus), model_path=model, utterance=utterance,
                        start_time=time, use_audio=use_audio)
    mark("main window built")
    for extension in (own_data, analysis, live, compare, measure, label_editing, label_files,
                      review_dock):
        try:
            extension.install(window)
        except Exception:
            log.exception("%s could not be installed", extension.__name__)
    return window


def run_app(corpus: Path | str, screenshot: str | None = None, utterance: str | None = None,
            time: float | None = None, model: Path | None = None,
            recordings: list[Path] | None = None) -> int:
    """Open the main window on ``corpus`` (and ``recordings`` without face data, synthesized with
    its model: :class:`facetraj_app.recordings.RecordingQueue`); with ``screenshot``, render it to that
    PNG and exit.

    Returns the process exit status (2 when the corpus, model or utterance cannot be used in
    screenshot mode).
    """
    mark("run_app")
    xvfb = ensure_display() if screenshot else None
    require_display("the facetraj window")
    route_qt_messages()
    from PyQt6.QtCore import QTimer
    from PyQt6.QtWidgets import QApplication

    from facetraj_engine.threads import one_blas_thread

    one_blas_thread()       # synthesis runs beside the rendering (facetraj_engine.threads)
    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("facetraj")
    mark("QApplication")
    with long_lived_objects():
        window = build_window(corpus, model=model, utterance=utterance, time=time)
    from .exception_hook import install_exception_hook

    hook = install_exception_hook(window)   # an exception in a slot: a dialog, never an abort
    if recordings:
        from .recordings import RecordingQueue

        window.add_extension("recordings", RecordingQueue(window, recordings))
    window.place_on_screen(WINDOW_SIZE)
    status = {"code": 0}
    if screenshot:
        out = Path(screenshot)

        def fail(message: str) -> None:
            print(f"facetraj: error: {message}", file=sys.stderr)
            status["code"] = 2
            app.quit()

        window.set_error_handler(fail)     # no dialogs in screenshot mode
        window.set_correlation_sweep(False)  # one frame: nothing to compute in the background

        def shoot() -> None:
            if window.view is None:
                return
            try:
                window.seek(time or 0.0)
                app.processEvents()
                mark("screenshot due")
                window.save_screenshot(out)
                mark("screenshot written")
                log.info("screenshot written to %s", out)
                print(out)
            except Exception as exc:
                fail(str(exc))
                return
            app.quit()

        # at once: the view is laid out and drawn when synthesisChanged arrives, and shoot() lets
        # the pending events (paints, resizes) through before rendering and grabbing
        window.synthesisChanged.connect(lambda: QTimer.singleShot(0, shoot))
    window.show()
    QTimer.singleShot(0, lambda: window.place_on_screen(WINDOW_SIZE))   # its frame is known now
    try:
        rc = app.exec()
    finally:
        window.close()
        hook.restore()
    del xvfb   # it ends when this process disconnects
    return status["code"] or rc
