"""What the main window opens: corpus folders (their model loaded, from the cache or trained, in
the background), folders of recordings, and the work asked for while a model is on its way.

The last corpus opened wins: a model that arrives for a corpus opened before it is dropped
(``ViewerModel.begin_model_load``), and a recording opened while a corpus loads is synthesized
with that corpus's model, the one the user will see (:meth:`DataOpener.when_model_ready`), not
the one about to be replaced. Plain Python over the window's contract (``app/main_window.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from PyQt6.QtCore import QTimer

from facetraj_engine.errors import FacetrajError
from facetraj_engine.io.corpus import Corpus, load_corpus
from facetraj_engine.method.model import Model
from facetraj_engine.workflow.model_cache import load_or_train

from .phases import mark
from .recordings import RecordingQueue, recordings_in
from .viewer_model import load_model


class DataOpener:
    """Opens corpora and recordings in ``window`` (a ``MainWindow``)."""

    def __init__(self, window):
        self.window = window
        self.waiting: list[Callable[[], Any]] = []     # asked for while a model loads

    def open_corpus(self, path: Path, model_path: Path | None = None) -> None:
        """Open a corpus folder; a folder of recordings (audio, no ``corpus.json``) is opened as
        such (:meth:`open_recordings`)."""
        w = self.window
        try:
            if recordings_in(path):
                self.open_recordings(path)
                return
            if not w.may_leave("opening another corpus"):     # unsaved label edits
                return
            corpus = load_corpus(path)
        except FacetrajError as exc:
            w.report_error(exc)
            return
        self.load_model(corpus, model_path)

    def open_first_corpus(self, path: Path, model_path: Path | None) -> None:
        """The corpus given to the window's constructor: its model starts loading at once, beside
        the window's first paint; an error is reported once the event loop runs (after the
        caller has set its error handler)."""
        try:
            corpus = load_corpus(path)
        except FacetrajError as exc:
            QTimer.singleShot(0, lambda e=exc: self.window.report_error(e))
            return
        self.load_model(corpus, model_path)

    def open_recordings(self, path: Path) -> None:
        """Synthesize the recordings of a folder (or one audio file) with the model in use (the
        one on its way, if a corpus loads), each with its labels by the one label rule (as
        ``facetraj gui folder/`` does): the first shown, the others listed in the browser."""
        w = self.window
        try:
            paths = recordings_in(path)
        except FacetrajError as exc:
            w.report_error(exc)
            return
        if not paths:
            w.report_error(FacetrajError(f"{path}: a corpus folder, not a folder of recordings "
                                         "(File > Open corpus folder opens it)"))
            return
        if w.model is None and not w.state.loading:
            w.report_error(FacetrajError("no model yet: open a corpus first"))
            return
        if not w.may_leave(f"opening the recordings of {path.name}"):      # unsaved label edits
            return
        w.show_status(f"opening {len(paths)} recordings of {path} …")
        w.add_extension("recordings", RecordingQueue(w, paths))     # kept while it works

    def load_model(self, corpus: Corpus, model_path: Path | None) -> None:
        """Load or train ``corpus``'s model in the background; a model of a corpus opened
        before the last one is dropped when it arrives (the last one opened is shown)."""
        w = self.window
        mark("corpus index read")
        w.show_status(f"opening {corpus.root} …")
        number = w.state.begin_model_load()

        def failed(exc: BaseException) -> None:
            w.state.end_model_load(number)
            w.report_error(exc)
            self.run_after_model()            # with the model in use, if any

        def done(result: tuple[Model, dict[str, str]]) -> None:
            if w.state.is_latest_load(number):
                w.use_model(corpus, *result)

        w.run_task(lambda p: load_model(corpus, model_path, p, load_or_train), done,
                   "preparing the model (first run trains it)", on_error=failed)

    def when_model_ready(self, fn: Callable[[], Any]) -> None:
        """``fn()`` now if a model is in use and none is on its way, else once the model on its
        way is ready (or has failed to load)."""
        if self.window.state.ready:
            fn()
        else:
            self.waiting.append(fn)

    def run_after_model(self) -> None:
        """What was asked for while the model was on its way (the window calls it once the
        model is in use)."""
        waiting, self.waiting = self.waiting, []
        for fn in waiting:
            fn()
