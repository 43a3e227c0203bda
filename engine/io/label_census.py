"""How the labels of a corpus were made, phone by phone (issue 56): how many phones a person
checked (hand-checked label files, and the phones of automatic ones corrected by hand since: in
the app's label editor or in Praat), how many are aligned, how many recognized; which utterances
have corrections. Read from the label files alone, by the rule that reads them for training and
evaluation (:func:`facetraj_engine.labels.provenance.labels_from_tiers`). ``facetraj train``,
``eval``, ``corpus init`` and ``report`` say it."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import InputError
from ..labels.phoneset import normalise_label
from ..labels.provenance import labels_from_tiers
from .corpus import Corpus, label_source
from .labelfiles import LABEL_SUFFIXES, read_labels, read_textgrid_tiers

#: the kinds counted, in the order they are said
KINDS = ("hand-checked", "aligned", "recognized")


@dataclass
class LabelCensus:
    """Phones (silence left out) per kind, utterances per kind of their label file, and the
    utterances of automatic labels with phones corrected by hand (how many each)."""

    phones: dict[str, int] = field(default_factory=lambda: dict.fromkeys(KINDS, 0))
    utterances: dict[str, int] = field(default_factory=lambda: dict.fromkeys(KINDS, 0))
    corrected: dict[str, int] = field(default_factory=dict)

    @property
    def total(self) -> int:
        return sum(self.phones.values())

    def describe(self) -> str:
        """In words, for the commands' logs.

        >>> LabelCensus({"hand-checked": 12, "aligned": 0, "recognized": 30},
        ...             {"hand-checked": 0, "aligned": 0, "recognized": 2}, {"a": 5, "b": 7}).describe()
        '42 phones: 12 hand-checked (12 corrected by hand in 2 utterances), 30 recognized'
        """
        parts = []
        for kind in KINDS:
            n = self.phones[kind]
            if not n and kind != "hand-checked":
                continue
            text = f"{n} {kind}"
            if kind == "hand-checked" and self.corrected:
                k = len(self.corrected)
                text += (f" ({sum(self.corrected.values())} corrected by hand in {k} "
                         f"utterance{'s' * (k != 1)})")
            parts.append(text)
        return f"{self.total} phones: " + ", ".join(parts)

    def to_json(self) -> dict:
        return {"phones": dict(self.phones), "utterances": dict(self.utterances),
                "corrected": dict(self.corrected)}


def label_census(corpus: Corpus) -> LabelCensus:
    """The :class:`LabelCensus` of ``corpus`` (labels held in marker files count as aligned; a
    label file that cannot be read is left out: reading it for training says why)."""
    out = LabelCensus()
    declared = corpus.info.label_provenance or None
    for utt_id in corpus.info.ids:
        try:
            path = label_source(corpus.data_root, utt_id)
            if path.suffix.lower() == ".textgrid":
                tiers = read_textgrid_tiers(path)
                phones = [p for p in tiers.get("phones", [])]
            elif path.suffix.lower() in LABEL_SUFFIXES:
                tiers, phones = {}, read_labels(path)
            else:
                tiers, phones = None, _held_phones(path)
        except InputError:
            continue
        raw = [p.label for p in phones]
        labels = labels_from_tiers(phones, [], tiers or {}, "aligned" if tiers is None else declared,
                                   raw)
        kind = labels.provenance.kind
        out.utterances[kind] += 1
        hand = labels.hand_checked
        for p, checked in zip(phones, hand, strict=True):
            if normalise_label(p.label or "sil") == "sil":
                continue
            out.phones["hand-checked" if checked else kind] += 1
        if kind != "hand-checked" and hand.any():
            out.corrected[utt_id] = int(sum(1 for p, c in zip(phones, hand, strict=True)
                                            if c and normalise_label(p.label or "sil") != "sil"))
    return out


def _held_phones(path):
    """The phones a marker file holds (MVIEW's PHONES)."""
    from .markerformats import held_recording

    rec = held_recording(path, "carries_labels")
    return list(rec.phones) if rec is not None else []


__all__ = ["KINDS", "LabelCensus", "label_census"]
