"""Opening a recording for synthesis, with phone labels from wherever they can come from.

"Open audio…" uses a label file or a ``.txt`` transcript beside the audio (the one rule,
``facetraj_engine.io.label_rule.resolve_labels``), otherwise asks for the sentence (:class:`SentenceDialog`:
empty = recognize the phones; or no labels, acoustic-only). Alignment runs in a worker with the
window's busy indicator; words missing from the dictionary are asked for
(:class:`MissingWordsDialog`) and the alignment retried. The :class:`LabelSourceBox` in the settings
panel switches the utterance on screen, a recording opened so or a corpus utterance, between its
label file, aligned, recognized and no labels (``app/label_sources.py``), so that the lips of
each can be compared.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from PyQt6.QtCore import QObject, pyqtBoundSignal, pyqtSignal
from PyQt6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.data import Utterance
from facetraj_engine.errors import FacetrajError
from facetraj_engine.io.audio import read_audio
from facetraj_engine.io.markers_beside import MarkersBeside, read_markers_beside
from facetraj_engine.labels.phoneset import ARPABET

from .label_sources import SOURCE_CHOICES, LabelSources, corpus_sources
from .provenance import LabelOrigin

if TYPE_CHECKING:   # the labelling engine is imported when audio is opened (issue #15: cold start)
    import numpy as np

    from facetraj_engine.io.corpus import Corpus
    from facetraj_engine.method.model import Model

    from .viewer_model import UtteranceView, ViewerModel

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- dialogs
class SentenceDialog(QDialog):
    """Asks for the sentence spoken in a recording. ``choice()`` after ``exec()``: ``("aligned",
    text)``, ``("recognized", "")`` for empty text, ``("none", "")`` for acoustic-only."""

    def __init__(self, audio_name: str, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("The sentence spoken")
        self.text = QLineEdit()
        self.text.setPlaceholderText("e.g. The boy enjoyed the noisy toy.  (empty: recognize)")
        self.text.setMinimumWidth(460)
        self._none = False
        info = QLabel(f"No labels or transcript beside <b>{audio_name}</b>.<br>Type the English "
                      "sentence spoken to align its phones, or leave it empty to recognize them.")
        info.setWordWrap(True)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                   | QDialogButtonBox.StandardButton.Cancel)
        self.acoustic = QPushButton("No labels (acoustic only)")
        buttons.addButton(self.acoustic, QDialogButtonBox.ButtonRole.AcceptRole)
        self.acoustic.clicked.connect(self._acoustic_only)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        lay = QVBoxLayout(self)
        lay.addWidget(info)
        lay.addWidget(self.text)
        lay.addWidget(buttons)

    def _acoustic_only(self) -> None:
        self._none = True
        self.accept()

    def choice(self) -> tuple[str, str]:
        if self._none:
            return "none", ""
        text = self.text.text().strip()
        return ("aligned", text) if text else ("recognized", "")


class MissingWordsDialog(QDialog):
    """Asks the pronunciation (ARPAbet phones) of each word the dictionary lacks.
    ``pronunciations()`` -> word -> phones, after ``exec()``."""

    def __init__(self, words: Sequence[str], parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("Words not in the pronouncing dictionary")
        self.edits: dict[str, QLineEdit] = {}
        form = QFormLayout()
        for w in words:
            e = QLineEdit()
            e.setPlaceholderText("ARPAbet phones, e.g. N OY Z IY")
            e.textChanged.connect(self._check)
            self.edits[w] = e
            form.addRow(w, e)
        explain = QLabel("The pronouncing dictionary (CMUdict) does not know "
                         f"{'this word' if len(words) == 1 else 'these words'}. Give each word's "
                         "phones in ARPAbet, separated by spaces (stress digits are ignored); the "
                         "sentence is then aligned again.")
        explain.setWordWrap(True)
        explain.setMinimumWidth(420)
        self.message = QLabel("")
        self.message.setStyleSheet("color: #c92a2a")
        self.buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                        | QDialogButtonBox.StandardButton.Cancel)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        lay = QVBoxLayout(self)
        lay.addWidget(explain)
        lay.addLayout(form)
        lay.addWidget(self.message)
        lay.addWidget(self.buttons)
        self._check()

    def pronunciations(self) -> dict[str, list[str]]:
        return {w: [p.lower().rstrip("012") for p in e.text().split()] for w, e in self.edits.items()}

    def _check(self, *_args) -> None:
        bad = sorted({p for phones in self.pronunciations().values() for p in phones
                      if p not in ARPABET})
        empty = [w for w, phones in self.pronunciations().items() if not phones]
        self.buttons.button(QDialogButtonBox.StandardButton.Ok).setEnabled(not bad and not empty)
        self.message.setText(f"not ARPAbet: {' '.join(bad)}" if bad else
                             "every word needs its phones" if empty else "")


# --------------------------------------------------------------------------- the labels box
class LabelSourceBox(QWidget):
    """The label source of the utterance on screen (settings panel): file, aligned, recognized,
    none; a choice that is not available says why in its tooltip."""

    sourceChosen = pyqtSignal(str)

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.combo = QComboBox()
        for text, source in SOURCE_CHOICES:
            self.combo.addItem(text, source)
        # as narrow as the settings' other boxes (the left dock's width is the 3-D view's loss)
        self.combo.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.combo.setMinimumContentsLength(16)
        lay = QFormLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addRow("labels", self.combo)
        self.combo.activated.connect(lambda i: self.sourceChosen.emit(self.combo.itemData(i)))
        self.show_for(None, "file")

    def show_for(self, sources: LabelSources | None, source: str, why_not: str = "") -> None:
        """Show the choices of ``sources`` (the utterance on screen) with ``source`` current;
        without them the box is off and ``why_not`` says why."""
        model = self.combo.model()
        for i, (_, src) in enumerate(SOURCE_CHOICES):
            why = sources.unavailable(src) if sources is not None else why_not
            model.item(i).setEnabled(not why)
            model.item(i).setToolTip(why)
        self.combo.setEnabled(sources is not None)
        self.combo.setCurrentIndex(max(0, self.combo.findData(source)))
        if sources is None:
            self.combo.setToolTip(why_not)
            return
        off = [f"{text}: {sources.unavailable(src)}" for text, src in SOURCE_CHOICES
               if sources.unavailable(src)]
        self.combo.setToolTip("The phone labels the face is synthesized from: switch to compare "
                              f"the lips each gives (pin one first, Ctrl+P) for {sources.name}."
                              + "".join(f"\nnot available, {line}" for line in off))


# --------------------------------------------------------------------------- the controller
class AudioHost(Protocol):
    """What :class:`AudioOpener` needs of the window it serves (the main window)."""

    utteranceChanged: pyqtBoundSignal
    synthesisChanged: pyqtBoundSignal
    model: Model | None
    corpus: Corpus | None
    view: UtteranceView | None
    state: ViewerModel

    def show_error(self, message: str) -> None: ...
    def show_status(self, text: str, timeout_ms: int = 0) -> None: ...
    def show_notice(self, text: str, action_text: str = "", action: Callable | None = None,
                    owner: str = "") -> None: ...
    def extension(self, name: str) -> object: ...
    def run_task(self, fn: Callable, on_done: Callable | None, label: str, **options) -> object: ...
    def show_external(self, utt: Utterance, origin: LabelOrigin | None = None,
                      show: bool = True) -> None: ...
    def show_labels(self, utt: Utterance, origin: LabelOrigin, own: bool = False) -> None: ...
    def when_model_ready(self, fn: Callable[[], object]) -> None: ...
    def may_leave(self, what: str) -> bool: ...


class AudioOpener(QObject):
    """"Open audio…" for the main window (an :class:`AudioHost`): finds or asks for the labels,
    aligns in a worker, shows the result; and the labels box, which switches the label source
    of the utterance on screen (a recording opened so, or a corpus utterance).

    ``finished(path, ok)`` after a recording opened (shown, or only listed) or failed."""

    finished = pyqtSignal(str, bool)

    def __init__(self, window: AudioHost):
        super().__init__(window)  # the main window, a QObject
        self.window = window
        self.opened: dict[str, LabelSources] = {}     # recordings opened from files, by name
        self.corpus_sources: LabelSources | None = None    # the corpus utterance shown
        self.box = LabelSourceBox()
        self.box.sourceChosen.connect(self.switch)
        window.synthesisChanged.connect(self._refresh_box)

    # -- asking
    def ask(self) -> None:
        """The File menu's "Open audio…": the file, then (if nothing is beside it) the sentence."""
        path, _ = QFileDialog.getOpenFileName(self.window, "Open audio for synthesis", "",
                                              "Audio (*.wav *.flac);;All files (*)")
        if path:         # with the model the user will see, if a corpus is on its way
            self.window.when_model_ready(lambda: self._ask_labels(Path(path)))

    def _ask_labels(self, path: Path) -> None:
        """Open ``path``: with the labels or sentence beside it, else those the user chooses."""
        from facetraj_engine.io.label_rule import beside

        read = self._read(path)  # a corrupt file is reported before the sentence is asked for
        if read is None:
            return
        label_file, txt = beside(path)
        if label_file is not None or txt is not None:
            self._open(path, read)
            return
        dialog = SentenceDialog(path.name, self.window)
        if dialog.exec() != QDialog.DialogCode.Accepted:
            return
        source, text = dialog.choice()
        self._open(path, read, text=text or None, recognize=source == "recognized",
                   acoustic_only=source == "none")

    def _read(self, audio_path: Path) -> tuple[np.ndarray, int] | None:
        """The audio of ``audio_path`` and its rate; ``None`` (after the error dialog) if it
        cannot be read or there is no model to synthesize with."""
        if self.window.model is None:
            self.window.show_error("no model yet: open a corpus first")
            return None
        from facetraj_engine.method.pipeline import check_length

        try:
            audio, rate = read_audio(audio_path)
            check_length(self.window.model, len(audio), rate, str(audio_path))
        except FacetrajError as exc:
            self.window.show_error(str(exc))
            return None
        return audio, rate

    # -- opening
    def open(self, audio_path: Path, labels_path: Path | None = None, text: str | None = None,
             recognize: bool = False, acoustic_only: bool = False,
             extra_dict: dict[str, list[str]] | None = None, show: bool = True) -> bool:
        """Open ``audio_path`` for synthesis; labels by ``facetraj_engine.io.label_rule.resolve_labels``
        (alignment or recognition in a worker), none with ``acoustic_only``; shown, or with
        ``show=False`` only listed in the browser. False when the audio cannot be read (the
        error is shown)."""
        read = self._read(audio_path)
        if read is not None:
            self._open(audio_path, read, labels_path, text, recognize, acoustic_only, extra_dict,
                       show)
        else:
            self.finished.emit(str(audio_path), False)
        return read is not None

    def _recording(self, audio_path: Path, read: tuple[np.ndarray, int], labels_path: Path | None,
                   text: str | None, extra_dict: dict[str, list[str]] | None) -> LabelSources:
        """The label sources of a recording (no labels made yet, no markers read yet): the
        label file given or beside it, the sentence typed or the ``.txt`` beside it (also when
        a label file is used first: "aligned" is then one choice of the labels box). Raises
        the transcript's error."""
        from facetraj_engine.io.label_rule import beside, read_transcript

        win, (audio, rate) = self.window, read
        label_file, txt = beside(audio_path)
        base = Utterance(name=win.state.external_name(audio_path.stem, audio_path.suffix),
                         audio=audio, sample_rate=rate, phones=[], markers=None,
                         marker_rate=win.model.marker_rate, marker_names=list(win.model.marker_names))
        sources = LabelSources(base, audio_path, label_file=labels_path or label_file,
                               extra_dict=dict(extra_dict or {}))
        if text:
            sources.text, sources.text_from = text, "the sentence typed"
        elif txt is not None:
            sources.text, sources.text_from = read_transcript(txt), txt.name
        return sources

    def _open(self, audio_path: Path, read: tuple[np.ndarray, int],
              labels_path: Path | None = None, text: str | None = None, recognize: bool = False,
              acoustic_only: bool = False,
              extra_dict: dict[str, list[str]] | None = None, show: bool = True) -> None:
        from facetraj_engine.io.label_rule import LabelRequest, resolve_labels
        from facetraj_engine.labels.alignment import MissingWordsError

        win = self.window
        try:
            sources = self._recording(audio_path, read, labels_path, text, extra_dict)
        except FacetrajError as exc:
            win.show_error(str(exc))
            self.finished.emit(str(audio_path), False)
            return
        model = win.model

        def work(progress) -> tuple[LabelSources, str, MarkersBeside | None, str]:
            found, why = None, ""
            try:
                found = read_markers_beside(audio_path, model.marker_names, model.marker_rate,
                                            sources.base.duration)
            except FacetrajError as exc:     # the recording opens without them, saying why
                why = str(exc)
            if found is not None and found.usable:
                sources.base = replace(sources.base, markers=found.markers)
            if acoustic_only:
                return sources, "none", found, why
            progress(0.1, f"labelling {audio_path.name}")
            found_labels = resolve_labels(audio_path, *read, LabelRequest(
                labels=labels_path, text=text, recognize=recognize, extra_dict=sources.extra_dict),
                progress=lambda f, m: progress(0.1 + 0.8 * f, m))     # each decoding pass
            log.info("%s: labels %s", audio_path.name, found_labels.describe())
            labels = found_labels.labels
            source = labels.source if labels else "none"
            sources.labels[source] = labels
            sources.shown = source
            return sources, source, found, why

        def failed(exc: BaseException) -> None:
            if isinstance(exc, MissingWordsError):
                dialog = MissingWordsDialog(exc.words, win)
                if dialog.exec() == QDialog.DialogCode.Accepted:
                    self.open(audio_path, labels_path, text, recognize, acoustic_only,
                              {**sources.extra_dict, **dialog.pronunciations()}, show)
                    return
            else:
                win.show_error(str(exc) if isinstance(exc, FacetrajError)
                               else f"internal error: {type(exc).__name__}: {exc}")
            self.finished.emit(str(audio_path), False)

        def done(result) -> None:
            if win.model is not model:     # another corpus opened meanwhile: its model's markers
                self.open(audio_path, labels_path, text, recognize, acoustic_only,   # and rate
                          sources.extra_dict, show)
                return
            self._show(*result, show=show)

        win.run_task(work, done, "aligning the phones", on_error=failed)

    def _show(self, sources: LabelSources, source: str, beside: MarkersBeside | None,
              beside_error: str, show: bool = True) -> None:
        win = self.window
        self.opened[sources.name] = sources
        win.show_external(sources.utterance(source), sources.origin(source), show=show)
        name, path = sources.name, sources.path
        if not show:
            pass
        elif beside_error:
            win.show_notice(f"{beside_error}: {path.name} opens without original markers",
                            owner=name)
        elif beside is not None and not beside.usable:     # MOCHA's .ema beside its .wav
            win.show_notice(beside.hint(path.name, len(win.model.marker_names)), "Import its folder…",
                            lambda: win.extension("own_data").do_import(path.parent), owner=name)
        elif beside is not None:
            win.show_status(f"original markers from {beside.path.name}", 8000)
        self.finished.emit(str(path), True)

    # -- switching
    def current(self) -> LabelSources | None:
        """The label sources of the utterance on screen (None: nothing shown)."""
        view = self.window.view
        if view is None:
            return None
        name = view.utterance.name
        if view.split == "external":
            return self.opened.get(name)
        if self.corpus_sources is None or self.corpus_sources.name != name \
                or self.corpus_sources.base.audio is not view.utterance.audio:
            self.corpus_sources = self._corpus_sources(view)
        return self.corpus_sources

    def _corpus_sources(self, view: UtteranceView) -> LabelSources:
        """A corpus utterance as shown first (its own labels), and its sentence."""
        from facetraj_engine.io.corpus import audio_path

        corpus, name = self.window.corpus, view.utterance.name
        text = self.window.state.texts.get(name, "")
        held = (corpus.data_root / f"{name}.txt").is_file()
        try:
            path = audio_path(corpus.data_root, name)
        except FacetrajError:       # the audio held in its marker file (MVIEW): a name for messages
            path = corpus.data_root / f"{name}.wav"
        return corpus_sources(view.utterance, path, view.origin, text,
                              f"{name}.txt" if held else "the sentence of its marker file")

    def switch(self, source: str) -> None:
        """Synthesize the utterance on screen again with labels from ``source`` (its time and
        zoom kept); pins of it stay shown beside it."""
        sources = self.current()
        if sources is None:
            return
        win = self.window
        if not win.may_leave("switching to other labels"):
            self._refresh_box()
            return
        from facetraj_engine.labels.alignment import MissingWordsError

        def work(progress) -> tuple[Utterance, LabelOrigin]:
            progress(0.1, f"labels of {sources.name}: {source}")
            return sources.utterance(source), sources.origin(source)

        def failed(exc: BaseException) -> None:
            self._refresh_box()
            if isinstance(exc, MissingWordsError):
                dialog = MissingWordsDialog(exc.words, win)
                if dialog.exec() == QDialog.DialogCode.Accepted:
                    sources.extra_dict.update(dialog.pronunciations())
                    self.switch(source)
                return
            win.show_error(str(exc) if isinstance(exc, FacetrajError)
                           else f"internal error: {type(exc).__name__}: {exc}")

        def done(result: tuple[Utterance, LabelOrigin]) -> None:
            sources.shown = source
            win.show_labels(*result, own=source == "file" and sources.own_origin is not None)

        win.run_task(work, done, f"labels: {source}", on_error=failed)

    def _refresh_box(self) -> None:
        sources = self.current()
        why = ("open a corpus or a recording first" if self.window.view is None
               else "no audio file to label for this utterance")
        self.box.show_for(sources, sources.shown if sources is not None else "file", why)
