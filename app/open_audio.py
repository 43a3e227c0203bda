"""Opening a recording for synthesis, with phone labels from wherever they can come from.

"Open audio…" uses a label file or a ``.txt`` transcript beside the audio (the one rule,
``facetraj_engine.io.labelling.labels_for_audio``), otherwise asks for the sentence (:class:`SentenceDialog`:
empty = recognize the phones; or no labels, acoustic-only). Alignment runs in a worker with the
window's busy indicator; words missing from the dictionary are asked for
(:class:`MissingWordsDialog`) and the alignment retried. The :class:`LabelSourceBox` in the settings
panel switches the same audio between its label file, aligned, recognized and no labels, so the
lips of each can be compared.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
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

from facetraj_engine.data import Provenance, Utterance
from facetraj_engine.errors import FacetrajError, InputError
from facetraj_engine.io.audio import read_audio
from facetraj_engine.labels.phoneset import ARPABET

from .provenance import LabelOrigin

if TYPE_CHECKING:   # the labelling engine is imported when audio is opened (issue #15: cold start)
    import numpy as np

    from facetraj_engine.io.corpus import Corpus
    from facetraj_engine.labels.provenance import Labels
    from facetraj_engine.method.model import Model

    from .viewer_model import UtteranceView

log = logging.getLogger(__name__)

#: Label sources the user can switch between, as (combo text, source).
SOURCE_CHOICES = (("from the label file", "file"), ("aligned from the sentence", "aligned"),
                  ("recognized (no text)", "recognized"), ("none: acoustic only", "none"))


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


# --------------------------------------------------------------------------- the opened recording
@dataclass
class OpenedAudio:
    """A recording opened for synthesis and the labels computed for it so far (by source)."""

    name: str
    path: Path
    audio: object
    rate: int
    text: str = ""
    text_from: str = ""                 # where the sentence came from: "s001.txt", "the sentence typed"
    label_file: Path | None = None
    extra_dict: dict[str, list[str]] = field(default_factory=dict)
    labels: dict[str, Labels | None] = field(default_factory=dict)

    def labels_for(self, source: str) -> Labels | None:
        """Labels of ``source`` (computed on the first call: run in a worker)."""
        from facetraj_engine.io.labelfiles import read_label_file
        from facetraj_engine.io.labelling import label_audio

        if source not in self.labels:
            if source == "none":
                self.labels[source] = None
            elif source == "file":
                if self.label_file is None:
                    raise InputError(self.path, "no label file beside the audio")
                self.labels[source] = read_label_file(self.label_file, self.rate,
                                                  len(self.audio) / self.rate)
            elif source == "aligned":
                if not self.text:
                    raise InputError(self.path, "no sentence to align: give one with Open audio…")
                self.labels[source] = label_audio(self.audio, self.rate, "aligned", self.text,
                                                  self.extra_dict, self.path)
            else:
                self.labels[source] = label_audio(self.audio, self.rate, "recognized",
                                                  source=self.path)
        return self.labels[source]

    def origin(self, source: str) -> LabelOrigin:
        """Where the labels of ``source`` (a :data:`SOURCE_CHOICES` key) came from."""
        labels = self.labels.get(source)
        found = labels.source if labels is not None else "none"
        if source == "file" and self.label_file is not None:
            return LabelOrigin(found, file=self.label_file.name)
        if source == "aligned":
            return LabelOrigin(found, transcript=self.text_from or "the sentence typed")
        return LabelOrigin(found)

    def utterance(self, source: str, marker_rate: float, marker_names: list[str]) -> Utterance:
        labels = self.labels_for(source)
        return Utterance(name=self.name, audio=self.audio, sample_rate=self.rate,
                         phones=list(labels.phones) if labels else [],
                         words=list(labels.words) if labels else [], markers=None,
                         marker_rate=marker_rate, marker_names=list(marker_names),
                         text=self.text or "",
                         label_source=labels.source if labels else "none",
                         provenance=labels.provenance if labels else Provenance(),
                         confidence=labels.trust() if labels else None)


class LabelSourceBox(QWidget):
    """The label source of an opened recording (settings panel): file, aligned, recognized,
    none. Disabled for corpus utterances."""

    sourceChosen = pyqtSignal(str)

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.combo = QComboBox()
        for text, source in SOURCE_CHOICES:
            self.combo.addItem(text, source)
        self.combo.setToolTip("Phone labels of the opened audio: switch to compare the lips "
                              "synthesized from each (phonetic search needs labels).")
        lay = QFormLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addRow("labels", self.combo)
        self.combo.activated.connect(lambda i: self.sourceChosen.emit(self.combo.itemData(i)))
        self.show_for(None, "file")

    def show_for(self, opened: OpenedAudio | None, source: str) -> None:
        """Show the choices of ``opened`` (``None``: a corpus utterance) with ``source`` current."""
        model = self.combo.model()
        for i, (_, src) in enumerate(SOURCE_CHOICES):
            ok = opened is not None and (src != "file" or opened.label_file is not None) \
                and (src != "aligned" or bool(opened.text))
            model.item(i).setEnabled(ok)
        self.combo.setEnabled(opened is not None)
        self.combo.setCurrentIndex(max(0, self.combo.findData(source)))


# --------------------------------------------------------------------------- the controller
class AudioHost(Protocol):
    """What :class:`AudioOpener` needs of the window it serves (the main window)."""

    utteranceChanged: pyqtBoundSignal
    model: Model | None
    corpus: Corpus | None
    view: UtteranceView | None

    def show_error(self, message: str) -> None: ...
    def run_task(self, fn: Callable, on_done: Callable | None, label: str, **options) -> object: ...
    def show_external(self, utt: Utterance, origin: LabelOrigin | None = None) -> None: ...


class AudioOpener(QObject):
    """"Open audio…" for the main window (an :class:`AudioHost`): finds or asks for the labels,
    aligns in a worker, shows the result, and switches label sources."""

    def __init__(self, window: AudioHost):
        super().__init__(window)  # the main window, a QObject
        self.window = window
        self.opened: dict[str, OpenedAudio] = {}
        self.box = LabelSourceBox()
        self.box.sourceChosen.connect(self.switch)
        window.utteranceChanged.connect(self._on_utterance)

    # -- asking
    def ask(self) -> None:
        """The File menu's "Open audio…": the file, then (if nothing is beside it) the sentence."""
        path, _ = QFileDialog.getOpenFileName(self.window, "Open audio for synthesis", "",
                                              "Audio (*.wav *.flac);;All files (*)")
        if not path:
            return
        from facetraj_engine.io.labelling import beside

        path = Path(path)
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
             extra_dict: dict[str, list[str]] | None = None) -> bool:
        """Open ``audio_path`` for synthesis; labels by ``facetraj_engine.io.labelling.labels_for_audio``
        (alignment or recognition in a worker), none with ``acoustic_only``. False when the
        audio cannot be read (the error is shown)."""
        read = self._read(audio_path)
        if read is not None:
            self._open(audio_path, read, labels_path, text, recognize, acoustic_only, extra_dict)
        return read is not None

    def _open(self, audio_path: Path, read: tuple[np.ndarray, int],
              labels_path: Path | None = None, text: str | None = None, recognize: bool = False,
              acoustic_only: bool = False,
              extra_dict: dict[str, list[str]] | None = None) -> None:
        from facetraj_engine.io.labelling import beside, labels_for_audio, read_transcript
        from facetraj_engine.labels.alignment import MissingWordsError

        win = self.window
        audio, rate = read
        name = audio_path.stem
        while name in (win.corpus.info.ids if win.corpus else []):
            name += "'"
        label_file, txt = beside(audio_path)
        opened = OpenedAudio(name, audio_path, audio, rate, label_file=labels_path or label_file,
                             extra_dict=dict(extra_dict or {}))
        # the sentence to align: the one typed, else the .txt beside the audio (also when a label
        # file is used first: "aligned" is then one choice of the labels box)
        if text:
            opened.text, opened.text_from = text, "the sentence typed"
        elif txt is not None:
            try:
                opened.text, opened.text_from = read_transcript(txt), txt.name
            except FacetrajError as exc:
                win.show_error(str(exc))
                return

        def work(progress) -> tuple[OpenedAudio, str]:
            if acoustic_only:
                return opened, "none"
            progress(0.1, f"labelling {audio_path.name}")
            labels = labels_for_audio(audio_path, audio, rate, labels=labels_path, text=text,
                                      recognize=recognize, extra_dict=opened.extra_dict,
                                      fallback=True)
            source = labels.source if labels else "none"
            opened.labels[source] = labels
            return opened, source

        def failed(exc: BaseException) -> None:
            if isinstance(exc, MissingWordsError):
                dialog = MissingWordsDialog(exc.words, win)
                if dialog.exec() == QDialog.DialogCode.Accepted:
                    self.open(audio_path, labels_path, text, recognize, acoustic_only,
                              {**opened.extra_dict, **dialog.pronunciations()})
                return
            win.show_error(str(exc) if isinstance(exc, FacetrajError)
                           else f"internal error: {type(exc).__name__}: {exc}")

        win.run_task(work, lambda r: self._show(*r), "aligning the phones",
                              on_error=failed)

    def _show(self, opened: OpenedAudio, source: str) -> None:
        win = self.window
        self.opened[opened.name] = opened
        utt = opened.utterance(source, win.model.marker_rate, win.model.marker_names)
        win.show_external(utt, opened.origin(source))

    # -- switching
    def switch(self, source: str) -> None:
        """Re-synthesize the current opened recording with labels from ``source``."""
        view = self.window.view
        opened = self.opened.get(view.utterance.name) if view is not None else None
        if opened is None:
            return
        win = self.window

        def work(progress) -> tuple[Utterance, LabelOrigin]:
            progress(0.1, f"labels: {source}")
            return (opened.utterance(source, win.model.marker_rate, win.model.marker_names),
                    opened.origin(source))

        def failed(exc: BaseException) -> None:
            self.box.show_for(opened, view.utterance.label_source)
            win.show_error(str(exc))

        win.run_task(work, lambda r: win.show_external(*r), f"labels: {source}", on_error=failed)

    def _on_utterance(self, name: str) -> None:
        view = self.window.view
        opened = self.opened.get(name)
        self.box.show_for(opened, view.utterance.label_source if view is not None else "file")

    def current(self) -> OpenedAudio | None:
        view = self.window.view
        return self.opened.get(view.utterance.name) if view is not None else None

