"""Phone labels with their provenance: the :class:`Labels` of a recording, where they came from,
how sure their maker was, and the record of it that travels with them in a TextGrid.

Labels are made three ways: checked by a person (``hand-checked``: the paper's labels, and any
label file facetraj did not write, unless the user says otherwise), aligned from a transcript
(``aligned``, PocketSphinx) or recognized from speech alone (``recognized``). Automatic labels
carry a confidence per phone in (0, 1] (:attr:`facetraj_engine.labels.provenance.Labels.confidence`).

In a TextGrid the record is two extra interval tiers that Praat opens, shows and saves like any
other (tested through Praat itself):

- ``provenance``: one interval over the whole file, e.g.
  ``source=aligned; tool=PocketSphinx 5.1.1; from=s001.txt``;
- ``confidence``: one interval per phone, as the phone was written, labelled ``"<phone>
  <confidence>"`` (``"b 0.41"``).

A phone corrected by hand in Praat afterwards (label or boundaries changed, or a new phone) no
longer matches its ``confidence`` interval: it counts as hand-checked (confidence 1, exact), while
the phones left alone keep the confidence their maker gave them. A file whose ``provenance`` tier
is deleted counts as hand-checked as a whole.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field

import numpy as np

from ..data import LABEL_KINDS, PhoneSegment, Provenance

#: The TextGrid tiers of the record.
PROVENANCE_TIER = "provenance"
CONFIDENCE_TIER = "confidence"
#: Boundaries closer than this (seconds) are the same boundary (Praat rewrites times in full
#: precision; our files hold them to the microsecond).
SAME_TIME_S = 5e-4


#: Scale of :attr:`Labels.confidence`: a phone whose score is ``-SCORE_SCALE`` per frame has
#: confidence ``1/e``. Measured: correctly aligned phones of real speech score about -3 to -10 per
#: frame, phones of a wrong sentence about -25 and below.
SCORE_SCALE = 10.0
#: Where a recording's labels came from now: a label file, aligned or recognized here.
SOURCES = ("file", "aligned", "recognized")


@dataclass
class Labels:
    """Phone and word tiers of one recording, with where they came from.

    Attributes
    ----------
    phones : phone segments in time order covering the audio (ARPAbet lower case, ``sil``).
    words : word segments (aligned words; empty for recognized or file labels without words).
    source : ``"file"``, ``"aligned"`` or ``"recognized"``.
    scores : ``(len(phones),)`` float: each phone's acoustic score per 10 ms frame from the
        PocketSphinx phone alignment -- the log-likelihood of the phone's frames relative to the
        best-scoring model state in each frame, in PocketSphinx's integer log units, averaged over
        the phone's frames. 0 is a perfect fit, more negative a worse one; comparable between
        :func:`align` and :func:`recognize` (both come from the same phone alignment). NaN where
        no score exists (file labels, or a phone the aligner did not score).
    text : the sentence aligned (normalised), else ``""``.
    provenance : how the phones were made: by default ``aligned`` or ``recognized`` for those
        sources, hand-checked for a file (a TextGrid written by facetraj records its own,
        :func:`facetraj_engine.io.labelfiles.read_label_file`).
    checked : ``(len(phones),)`` bool: the phones of automatic labels checked by hand since they
        were made (corrected in Praat or in the app: no longer as their ``confidence`` interval
        records them); ``None``: none.
    """

    phones: list[PhoneSegment]
    words: list[PhoneSegment] = field(default_factory=list)
    source: str = "file"
    scores: np.ndarray | None = None
    text: str = ""
    provenance: Provenance | None = None
    checked: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.source not in SOURCES:
            raise ValueError(f"source must be one of {SOURCES}, got {self.source!r}")
        if self.provenance is None:
            self.provenance = Provenance() if self.source == "file" else Provenance(self.source)
        if self.scores is None:
            self.scores = np.full(len(self.phones), np.nan)
        self.scores = np.asarray(self.scores, dtype=float)
        if self.scores.shape != (len(self.phones),):
            raise ValueError(f"one score per phone: {len(self.phones)} phones, "
                             f"scores {self.scores.shape}")
        if self.checked is not None:
            self.checked = np.asarray(self.checked, dtype=bool)
            if self.checked.shape != (len(self.phones),):
                raise ValueError(f"one checked flag per phone: {len(self.phones)} phones, "
                                 f"flags {self.checked.shape}")

    @property
    def hand_checked(self) -> np.ndarray:
        """Per phone, whether a person checked it: every phone of hand-checked labels, else the
        phones corrected by hand since the labels were made (:attr:`checked`)."""
        if self.provenance.hand_checked:
            return np.ones(len(self.phones), dtype=bool)
        return self.checked if self.checked is not None else np.zeros(len(self.phones), dtype=bool)

    @property
    def confidence(self) -> np.ndarray:
        """Per phone, ``exp(score / SCORE_SCALE)`` in ``(0, 1]`` (1 = perfect fit; NaN unscored).

        >>> Labels([PhoneSegment(0, .1, "sil"), PhoneSegment(.1, .2, "b")], source="aligned",
        ...        scores=[0.0, -10.0]).confidence.round(3).tolist()
        [1.0, 0.368]
        """
        return np.exp(np.minimum(self.scores, 0.0) / SCORE_SCALE)

    def trust(self) -> np.ndarray | None:
        """What synthesis weighs the labels by: ``None`` for hand-checked labels (trusted
        fully), else :attr:`confidence` per phone."""
        return None if self.provenance.hand_checked else self.confidence

    def tiers(self) -> dict[str, list[PhoneSegment]]:
        """The TextGrid tiers: ``words`` (when any), ``phones``, and for labels that are not
        hand-checked their record (``facetraj_engine.labels.provenance``): ``provenance`` and
        ``confidence``, which holds no interval for a phone checked by hand (:attr:`checked`:
        read back, it counts as checked again)."""
        tiers = {"words": list(self.words)} if self.words else {}
        tiers["phones"] = list(self.phones)
        if not self.provenance.hand_checked and self.phones:
            end = self.phones[-1].end
            tiers[PROVENANCE_TIER] = [PhoneSegment(0.0, end, provenance_text(self.provenance))]
            made = confidence_intervals(self.phones, self.confidence)
            tiers[CONFIDENCE_TIER] = [s for s, hand in zip(made, self.hand_checked, strict=True)
                                      if not hand]
        return tiers

    def to_json(self) -> dict:
        """A JSON-able dict (the label cache's file content)."""
        return {"source": self.source, "text": self.text,
                "phones": [[s.start, s.end, s.label] for s in self.phones],
                "words": [[s.start, s.end, s.label] for s in self.words],
                "scores": [None if not np.isfinite(x) else float(x) for x in self.scores],
                "provenance": asdict(self.provenance)}

    @classmethod
    def from_json(cls, obj: Mapping) -> Labels:
        return cls(phones=[PhoneSegment(float(a), float(b), str(c)) for a, b, c in obj["phones"]],
                   words=[PhoneSegment(float(a), float(b), str(c)) for a, b, c in obj["words"]],
                   source=obj["source"], text=obj.get("text", ""),
                   scores=np.array([np.nan if x is None else x for x in obj["scores"]], float),
                   provenance=Provenance(**obj["provenance"]) if "provenance" in obj else None)



def provenance_text(p: Provenance) -> str:
    """The ``provenance`` tier's text.

    >>> provenance_text(Provenance("recognized", "PocketSphinx 5.1.1"))
    'source=recognized; tool=PocketSphinx 5.1.1'
    """
    fields = {"source": p.kind, "tool": p.tool, "from": p.origin}
    return "; ".join(f"{k}={v}" for k, v in fields.items() if v)


def parse_provenance(text: str) -> Provenance | None:
    """A :class:`Provenance` from the ``provenance`` tier's text (``None`` when it names no known
    source: the file then counts as hand-checked).

    >>> parse_provenance("source=aligned; tool=PocketSphinx 5.1.1; from=a.txt")
    Provenance(kind='aligned', tool='PocketSphinx 5.1.1', origin='a.txt', corrected=0, why='')
    >>> parse_provenance("made by hand") is None
    True
    """
    fields = dict(part.split("=", 1) for part in (p.strip() for p in text.split(";")) if "=" in part)
    fields = {k.strip().lower(): v.strip() for k, v in fields.items()}
    if fields.get("source") not in LABEL_KINDS:
        return None
    return Provenance(fields["source"], fields.get("tool", ""), fields.get("from", ""))


def confidence_intervals(phones: Sequence[PhoneSegment], confidence: np.ndarray
                         ) -> list[PhoneSegment]:
    """The ``confidence`` tier: each phone's interval labelled ``"<phone> <confidence>"`` (three
    decimals; ``-`` where it has none).

    >>> [s.label for s in confidence_intervals([PhoneSegment(0, .1, "sil"),
    ...                                         PhoneSegment(.1, .2, "b")], np.array([1.0, np.nan]))]
    ['sil 1.000', 'b -']
    """
    return [PhoneSegment(s.start, s.end, f"{s.label} {c:.3f}" if np.isfinite(c) else f"{s.label} -")
            for s, c in zip(phones, confidence, strict=True)]


def phone_confidence(phones: Sequence[PhoneSegment], recorded: Sequence[PhoneSegment]
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Per phone of ``phones`` (as read now), its recorded confidence and whether it is as it was
    written: a phone whose interval and label match one of the ``confidence`` tier keeps that
    confidence; any other phone was corrected (or added) by hand and gets confidence 1.

    >>> now = [PhoneSegment(0, .1, "sil"), PhoneSegment(.1, .2, "p"), PhoneSegment(.2, .3, "a")]
    >>> was = [PhoneSegment(0, .1, "sil 0.9"), PhoneSegment(.1, .2, "b 0.3"),
    ...        PhoneSegment(.2, .3, "a -")]
    >>> conf, kept = phone_confidence(now, was)
    >>> conf.tolist(), kept.tolist()
    ([0.9, 1.0, nan], [True, False, True])
    """
    rows = []
    for seg in recorded:
        label, _, value = seg.label.strip().rpartition(" ")
        try:
            c = float(value) if value != "-" else float("nan")
        except ValueError:
            continue
        if (np.isfinite(c) and not 0.0 <= c <= 1.0) or value.lower() in ("nan", "inf", "-inf"):
            continue
        rows.append((seg.start, seg.end, label, c))
    starts = np.array([r[0] for r in rows])
    conf = np.ones(len(phones))
    kept = np.zeros(len(phones), dtype=bool)
    for i, seg in enumerate(phones):
        for j in np.flatnonzero(np.abs(starts - seg.start) < SAME_TIME_S) if rows else ():
            _, end, label, c = rows[j]
            if abs(end - seg.end) < SAME_TIME_S and label == seg.label.strip():
                conf[i], kept[i] = c, True
                break
    return conf, kept


#: ARPAbet's vowels: the phones an aligner's dictionary marks with stress digits (0, 1, 2)
ARPABET_VOWELS = frozenset("aa ae ah ao aw ay eh er ey ih iy ow oy uh uw".split())
#: the labels aligners give silence and what they could not align: empty intervals (the
#: Montreal Forced Aligner), ``sil``/``sp`` (HTK-style aligners, PocketSphinx), ``spn`` (spoken
#: noise: MFA's unknown words)
ALIGNER_SILENCES = frozenset({"", "sil", "sp", "spn"})


def aligner_conventions(labels: Sequence[str]) -> str | None:
    """Why the raw phone labels of a file that records no provenance look like an automatic
    aligner's, or ``None``: ARPAbet vowels with stress digits (``AH0``, ``IY1``: a pronouncing
    dictionary's, which a person labelling by ear does not write) on at least half the vowels,
    with the aligners' silences (empty, ``sil``, ``sp``, ``spn``). Upper-case phones with empty
    silences are the Montreal Forced Aligner's own conventions.

    >>> print(aligner_conventions(["", "DH", "AH0", "B", "OY1", "spn", ""]))  # doctest: +NORMALIZE_WHITESPACE
    the Montreal Forced Aligner's conventions: upper-case phones with stress digits (2 of 2
    vowels), empty silences, 'spn'
    >>> aligner_conventions(["sil", "dh", "ah0", "b", "oy1", "sp"])
    "an aligner's conventions: phones with stress digits (2 of 2 vowels), 'sil', 'sp'"
    >>> aligner_conventions(["sil", "dh", "ah", "b", "oy", "sil"]) is None      # by ear
    True
    """
    raw = [str(x).strip() for x in labels]
    vowels = [x for x in raw if x.lower().rstrip("012") in ARPABET_VOWELS]
    stressed = [x for x in vowels if x[-1:] in ("0", "1", "2")]
    silences = sorted({x.lower() for x in raw} & ALIGNER_SILENCES)
    if not stressed or 2 * len(stressed) < len(vowels) or not silences:
        return None
    upper = all(x == x.upper() for x in raw if x.lower() not in ALIGNER_SILENCES)
    marks = [("empty silences" if s == "" else repr(s)) for s in silences]
    mfa = upper and "" in silences
    who = "the Montreal Forced Aligner's" if mfa else "an aligner's"
    case = "upper-case phones" if upper else "phones"
    return (f"{who} conventions: {case} with stress digits ({len(stressed)} of {len(vowels)} "
            f"vowels), {', '.join(marks)}")


def labels_from_tiers(phones: Sequence[PhoneSegment], words: Sequence[PhoneSegment],
                      tiers: Mapping[str, Sequence[PhoneSegment]], declared: str | None = None,
                      raw: Sequence[str] | None = None) -> Labels:
    """The :class:`Labels` of a label file: its ``phones`` and ``words``, and the record in its
    ``tiers`` when it has one; otherwise its provenance is ``declared`` (what the user says of
    files from elsewhere), else ``aligned`` when its ``raw`` labels (as written in the file, empty
    ones too) follow an aligner's conventions (:func:`aligner_conventions`, saying why), else
    hand-checked.

    >>> phones = [PhoneSegment(0, .1, "sil"), PhoneSegment(.1, .2, "b")]
    >>> rec = {"provenance": [PhoneSegment(0, .2, "source=recognized; tool=PocketSphinx 5.1.1")],
    ...        "confidence": [PhoneSegment(0, .1, "sil 0.900"), PhoneSegment(.1, .2, "p 0.200")]}
    >>> lab = labels_from_tiers(phones, [], rec)
    >>> lab.provenance.describe(), lab.confidence.round(3).tolist()
    ('recognized (PocketSphinx 5.1.1), 1 phone corrected by hand', [0.9, 1.0])
    >>> labels_from_tiers(phones, [], {}).trust() is None
    True
    """
    recorded = tiers.get(PROVENANCE_TIER)
    found = parse_provenance(recorded[0].label) if recorded else None
    if found is None:
        why = aligner_conventions(raw) if raw is not None and not declared else None
        provenance = Provenance("aligned", why=why) if why else Provenance(declared or "hand-checked")
        return Labels(list(phones), list(words), "file", provenance=provenance)
    conf, kept = phone_confidence(phones, tiers.get(CONFIDENCE_TIER, []))
    provenance = Provenance(found.kind, found.tool, found.origin, int((~kept).sum()))
    with np.errstate(divide="ignore"):
        scores = SCORE_SCALE * np.log(np.clip(conf, 1e-9, 1.0))
    return Labels(list(phones), list(words), "file", scores, provenance=provenance, checked=~kept)
