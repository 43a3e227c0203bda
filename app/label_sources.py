"""The phone labels an utterance on screen can be synthesized from, without Qt: its own (the
corpus's label file, or the label file beside an opened recording), aligned from its sentence,
recognized from its speech alone, or none (acoustic-only synthesis), by the one rule every
command follows (``facetraj_engine.io.label_rule.resolve_labels``). A phonetician switches
between them to compare the lips each gives, on a corpus utterance as on a recording opened
from a file (``app/open_audio.py`` shows the choice and runs the labelling in a worker).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from facetraj_engine.data import Utterance
from facetraj_engine.errors import InputError

from .provenance import LabelOrigin

if TYPE_CHECKING:   # the labelling engine is imported when labels are made (issue #15: cold start)
    from facetraj_engine.labels.provenance import Labels

#: The label sources a phonetician can switch between, as (the labels box's text, source).
SOURCE_CHOICES = (("from the label file", "file"), ("aligned from the sentence", "aligned"),
                  ("recognized (no text)", "recognized"), ("none: acoustic only", "none"))


@dataclass
class LabelSources:
    """The label sources of one utterance and the labels made for it so far (by source).

    ``base``: the utterance as read (its audio, its markers: the original; for a corpus
    utterance its own labels too); ``path``: its audio file (names it in messages); ``text``:
    the sentence to align and ``text_from`` where it came from (``s002.txt``, "the sentence
    typed"); ``label_file``: the label file given or beside it (none: no "file" choice);
    ``own_labels``: the base's labels are the "file" choice (a corpus utterance)."""

    base: Utterance
    path: Path
    text: str = ""
    text_from: str = ""
    label_file: Path | None = None
    own_origin: LabelOrigin | None = None
    extra_dict: dict[str, list[str]] = field(default_factory=dict)
    labels: dict[str, Labels | None] = field(default_factory=dict)
    shown: str = "file"             # the source of the labels on screen

    @property
    def name(self) -> str:
        return self.base.name

    def unavailable(self, source: str) -> str:
        """Why ``source`` cannot be chosen for this utterance ("" when it can)."""
        if source == "file" and self.label_file is None and self.own_origin is None:
            return f"no label file for {self.path.name} (none beside it, none in the corpus)"
        if source == "aligned" and not self.text:
            return (f"no sentence to align for {self.path.name}: no .txt beside it (File → Open "
                    "audio… asks for one)")
        return ""

    def labels_for(self, source: str) -> Labels | None:
        """The labels of ``source`` (made on the first call: alignment and recognition are slow,
        run in a worker), by the one rule asked for that source."""
        from facetraj_engine.analysis.phone_compare import labels_of

        if source in self.labels:
            return self.labels[source]
        why = self.unavailable(source)
        if why:
            raise InputError(self.path, why)
        if source == "file" and self.own_origin is not None:
            found = None                # the base's own: :meth:`utterance` uses them as they are
        else:
            found = labels_of(source, self.path, self.base.audio, self.base.sample_rate, self.text,
                              self.label_file, self.extra_dict)
            if source == "aligned" and found is not None and self.text_from:
                found.provenance = replace(found.provenance, origin=self.text_from)
        self.labels[source] = found
        return found

    def origin(self, source: str) -> LabelOrigin:
        """Where the labels of ``source`` (a :data:`SOURCE_CHOICES` key) came from."""
        if source == "file" and self.own_origin is not None:
            return self.own_origin
        if source == "file" and self.label_file is not None:
            return LabelOrigin("file", file=self.label_file.name)
        labels = self.labels.get(source)
        found = labels.source if labels is not None else "none"
        if source == "aligned":
            return LabelOrigin(found, transcript=self.text_from or "the sentence typed")
        return LabelOrigin(found)

    def utterance(self, source: str) -> Utterance:
        """The utterance with the labels of ``source`` (:meth:`labels_for` first)."""
        from facetraj_engine.analysis.phone_compare import relabelled

        labels = self.labels_for(source)
        if source == "file" and self.own_origin is not None:
            return self.base
        return replace(relabelled(self.base, labels), text=self.text or "")


def corpus_sources(utt: Utterance, audio: Path, origin: LabelOrigin | None, text: str,
                   text_from: str) -> LabelSources:
    """The label sources of a corpus utterance ``utt`` as the corpus reads it: its own labels
    (from where ``origin`` says; none without phones) are the "file" choice."""
    own = origin if utt.phones and origin is not None else None
    return LabelSources(utt, audio, text=text, text_from=text_from, own_origin=own)


__all__ = ["SOURCE_CHOICES", "LabelSources", "corpus_sources"]
