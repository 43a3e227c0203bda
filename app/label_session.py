"""The labels of the utterance on screen as a phonetician corrects them, without Qt: the label
document (``facetraj_engine.labels.editing``), the utterance it belongs to, where its labels came
from, and where Save writes them.

:func:`labels_of_view` recovers the labels the view was synthesized from with everything their
maker recorded (source, provenance, confidence, the phones already checked by hand);
:meth:`LabelSession.utterance` is the utterance with the labels on screen, which the window
synthesizes after every edit; :func:`save_path` is where they are saved: beside the audio for a
recording opened from a file (where every command finds them by the one label rule), the
corpus's own label file for a corpus utterance (where ``train`` and ``eval`` read it).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from facetraj_engine.data import Utterance
from facetraj_engine.errors import FacetrajError
from facetraj_engine.labels.editing import LabelDocument
from facetraj_engine.labels.provenance import SCORE_SCALE, SOURCES, Labels

from .provenance import LabelOrigin
from .state import UtteranceView

log = logging.getLogger(__name__)


def labels_from_utterance(utt: Utterance) -> Labels:
    """The labels an utterance carries, as :class:`Labels` (its confidence as scores; the
    phones checked by hand since they were made are not told apart from others of confidence 1:
    :func:`labels_of_view` reads them from the label file when there is one)."""
    conf = utt.confidence
    scores = None
    if conf is not None and not utt.provenance.hand_checked:
        with np.errstate(divide="ignore"):
            scores = SCORE_SCALE * np.log(np.clip(np.asarray(conf, float), 1e-9, 1.0))
    source = utt.label_source if utt.label_source in SOURCES else "file"
    return Labels(list(utt.phones), list(utt.words), source, scores, utt.text,
                  provenance=utt.provenance,
                  checked=utt.checked if utt.checked is not None and
                  len(utt.checked) == len(utt.phones) else None)


def labels_of_view(view: UtteranceView, made: Labels | None = None,
                   label_file: Path | None = None, declared: str | None = None) -> Labels:
    """The labels ``view`` was synthesized from: ``made`` (the label source's own, when the
    window kept them), else those of ``label_file`` (the corpus's, read again: which phones were
    checked by hand), else the utterance's; each used only when its phones are the view's."""
    utt = view.utterance
    phones = list(utt.phones)
    if made is not None and list(made.phones) == phones:
        return made
    if label_file is not None and label_file.suffix.lower() in (".textgrid", ".lab", ".phn"):
        from facetraj_engine.io.labelfiles import read_label_file

        try:
            read = read_label_file(label_file, utt.sample_rate, utt.duration, declared)
        except FacetrajError as exc:            # shown from the utterance's own (logged)
            log.warning("%s", exc)
        else:
            if list(read.phones) == phones:
                return read
    return labels_from_utterance(utt)


def save_path(view: UtteranceView, audio_path: Path | None, data_root: Path | None) -> Path | None:
    """Where the labels of ``view`` are saved: a corpus utterance's label file in the corpus
    (``<id>.TextGrid``: read before any ``.lab`` or marker file's phones), a recording's TextGrid
    beside its audio; ``None`` without either."""
    name = view.utterance.name
    if view.split != "external" and data_root is not None:
        for suffix in (".TextGrid", ".TEXTGRID", ".textgrid"):
            if (data_root / f"{name}{suffix}").is_file():
                return data_root / f"{name}{suffix}"
        return data_root / f"{name}.TextGrid"
    if audio_path is not None:
        return audio_path.with_suffix(".TextGrid")
    return None


@dataclass
class LabelSession:
    """The labels of one utterance being corrected: the document, the utterance as it was shown
    when the corrections began (``base``: its audio and markers), where its labels came from
    (``origin``), its split, and where Save writes (``path``; ``None``: ask); ``replace_ok``:
    the existing files the user agreed to replace (asked once each); ``on_disk``: the stamp
    (modification time, size) of the file as last read or written here, so that a change on
    disk is told from this session's own save."""

    doc: LabelDocument
    base: Utterance
    origin: LabelOrigin
    split: str
    path: Path | None = None
    replace_ok: set[Path] = field(default_factory=set)
    on_disk: tuple[int, int] | None = None

    @classmethod
    def of_view(cls, view: UtteranceView, labels: Labels, frame_rate: float,
                phone_set: list[str], path: Path | None) -> LabelSession:
        doc = LabelDocument(labels, view.duration, frame_rate, phone_set, view.utterance.name)
        return cls(doc, view.utterance, view.label_origin, view.split, path)

    @property
    def name(self) -> str:
        return self.base.name

    def same_place(self, view: UtteranceView | None) -> bool:
        """Whether ``view`` shows this session's recording (whatever its labels)."""
        return view is not None and view.utterance.name == self.name and \
            view.utterance.audio is self.base.audio

    def matches(self, view: UtteranceView | None) -> bool:
        """Whether ``view`` shows this session's recording with its labels on screen (a new
        result of an edit or of other settings; not another utterance or label source)."""
        return self.same_place(view) and tuple(view.utterance.phones) == self.doc.phones

    def utterance(self) -> Utterance:
        """The recording with the labels on screen (what the window synthesizes)."""
        labels = self.doc.labels_now()
        return replace(self.base, phones=list(labels.phones), words=list(labels.words),
                       provenance=labels.provenance, confidence=labels.trust(),
                       checked=None if labels.provenance.hand_checked else labels.hand_checked)

    def origin_now(self) -> LabelOrigin:
        """Where the labels on screen came from (the file once saved)."""
        file = self.path.name if self.path is not None and self.saved_once else self.origin.file
        return LabelOrigin(self.origin.source, file, self.origin.transcript)

    @property
    def saved_once(self) -> bool:
        return self.on_disk is not None

    def summary(self) -> str:
        """The labels' state in words: how many phones are checked by hand, saved or not.

        (For the status bar and the log; ``facetraj synth`` says the same of the saved file.)
        """
        labels = self.doc.labels_now()
        hand = int(labels.hand_checked.sum())
        kind = labels.provenance.kind
        what = ("hand-checked" if kind == "hand-checked" else
                f"{kind}, {hand} of {len(labels.phones)} phones checked by hand")
        state = "unsaved edits" if self.doc.dirty else (f"saved in {self.path.name}" if
                                                          self.saved_once and self.path else "")
        return f"{self.name}: labels {what}" + (f" ({state})" if state else "")


def stamp(path: Path) -> tuple[int, int] | None:
    """A file's modification time (ns) and size, ``None`` when it is not there."""
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_mtime_ns, st.st_size


__all__ = ["LabelSession", "labels_from_utterance", "labels_of_view", "save_path", "stamp"]
