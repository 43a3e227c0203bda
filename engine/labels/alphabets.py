"""Phone alphabets of label files, told apart and mapped onto ARPAbet (the models' phone set).

A label file may be written in ARPAbet (CMU, any case, stress digits allowed, and the extended
symbols such as ``ax`` or ``dx``), TIMIT (ARPAbet with closures, ``q``, ``epi``, ``h#``),
MOCHA-TIMIT (Edinburgh machine-readable, ``@``, ``ii``, ``i@``), SAMPA or X-SAMPA (English,
``{``, ``V``, ``i:``, ``@U``; X-SAMPA adds ``r\\``, ``@```, ``4``) or IPA (``æ``, ``ʌ``, ``iː``,
``oʊ``, stress and length marks ignored). :func:`detect` finds the one alphabet that knows every
label of a file (silence labels aside; on a tie the first of :data:`ALPHABETS`, so a file that
is valid ARPAbet is read as ARPAbet) and :func:`to_arpabet` maps the labels with it. Labels no
alphabet knows are an error naming them and the fix (a label map, ``--label-map FILE``), never
silently dropped: a phone the synthesis does not know cannot be placed.

Each table maps a symbol onto the nearest of the 39 CMU phones (General American), as the MOCHA
map does: British vowels without an American twin to their nearest, centring diphthongs to their
first element, the flap to ``dx`` and the glottal stop to ``q`` (which
:func:`facetraj_engine.labels.phoneset.map_labels` then maps onto the model's ``t`` unless it knows them).
"""

from __future__ import annotations

import logging
import re
import unicodedata
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass

from ..data import PhoneSegment
from ..errors import InputError, warn_file
from .phoneset import ARPABET, FALLBACK, SILENCE, normalise_label

log = logging.getLogger(__name__)

#: MOCHA-TIMIT labels (southern British English, Edinburgh machine-readable) onto ARPAbet.
#: Vowels go to the nearest General American vowel; centring diphthongs to their first element.
MOCHA_TO_ARPABET: dict[str, str] = {
    "i": "ih", "ii": "iy", "iy": "iy", "e": "eh", "a": "ae", "aa": "aa", "o": "aa", "oo": "ao",
    "u": "uh", "uu": "uw", "uh": "ah", "@": "ah", "@@": "er", "ei": "ey", "ai": "ay",
    "oi": "oy", "ou": "ow", "@u": "ow", "au": "aw", "i@": "ih", "e@": "eh", "u@": "uh",
    "h": "hh", "j": "y", "y": "y", "p": "p", "b": "b", "t": "t", "d": "d", "k": "k", "g": "g",
    "ch": "ch", "jh": "jh", "f": "f", "v": "v", "th": "th", "dh": "dh", "s": "s", "z": "z",
    "sh": "sh", "zh": "zh", "m": "m", "n": "n", "ng": "ng", "l": "l", "r": "r", "w": "w",
    "breath": "sil", "sil": "sil",
}

#: Extended ARPAbet symbols kept as they are (a model may know them; else map_labels falls back).
EXTENDED_ARPABET = ("ax", "axr", "ix", "ux", "el", "em", "en", "eng", "nx", "dx", "hv")

#: TIMIT's symbols beyond extended ARPAbet: closures onto their stop, pauses onto silence.
TIMIT_EXTRA = {**{k: FALLBACK[k] for k in ("bcl", "dcl", "gcl", "pcl", "tcl", "kcl", "ax-h")},
               "q": "q", "epi": SILENCE, "h#": SILENCE, "pau": SILENCE}

_SAMPA_CONSONANTS = {
    "p": "p", "b": "b", "t": "t", "d": "d", "k": "k", "g": "g", "tS": "ch", "dZ": "jh",
    "f": "f", "v": "v", "T": "th", "D": "dh", "s": "s", "z": "z", "S": "sh", "Z": "zh",
    "h": "hh", "m": "m", "n": "n", "N": "ng", "l": "l", "r": "r", "w": "w", "j": "y",
    "x": "k", "?": "q", "n=": "n", "l=": "l", "m=": "m", "W": "w",
}
_SAMPA_VOWELS = {
    "I": "ih", "e": "eh", "E": "eh", "{": "ae", "Q": "aa", "V": "ah", "U": "uh", "@": "ah",
    "i:": "iy", "i": "iy", "u:": "uw", "u": "uw", "3:": "er", "3": "er", "A:": "aa", "A": "aa",
    "O:": "ao", "O": "ao", "o:": "ao", "eI": "ey", "aI": "ay", "OI": "oy", "@U": "ow",
    "oU": "ow", "aU": "aw", "I@": "ih", "e@": "eh", "E@": "eh", "U@": "uh",
}
#: SAMPA for English (J. C. Wells), case-sensitive.
SAMPA_TO_ARPABET: dict[str, str] = {**_SAMPA_CONSONANTS, **_SAMPA_VOWELS}
#: X-SAMPA for English: SAMPA's symbols and the American and allophonic ones it adds.
X_SAMPA_TO_ARPABET: dict[str, str] = {
    **SAMPA_TO_ARPABET, "r\\": "r", "@`": "er", "3`": "er", "3`:": "er", "4": "dx", "5": "l",
    "a": "ae", "o": "ow", "r\\`": "r", "i_^": "iy", "E:": "eh", "6": "ah", "a:": "aa",
}
#: IPA (Unicode) for English, after stress, length, tie and syllabic marks are removed.
IPA_TO_ARPABET: dict[str, str] = {
    "p": "p", "b": "b", "t": "t", "d": "d", "k": "k", "g": "g", "\u0261": "g",
    "t\u0283": "ch", "d\u0292": "jh", "f": "f", "v": "v", "\u03b8": "th", "\u00f0": "dh",
    "s": "s", "z": "z", "\u0283": "sh", "\u0292": "zh", "h": "hh", "m": "m", "n": "n",
    "\u014b": "ng", "l": "l", "\u026b": "l", "\u0279": "r", "r": "r", "\u027e": "dx",
    "\u0294": "q", "w": "w", "\u028d": "w", "j": "y",
    "i": "iy", "\u026a": "ih", "e": "eh", "\u025b": "eh", "\u00e6": "ae", "a": "ae",
    "\u0251": "aa", "\u0252": "aa", "\u028c": "ah", "\u0259": "ah", "\u0250": "ah",
    "\u025c": "er", "\u025d": "er", "\u025a": "er", "\u0254": "ao", "o": "ow", "\u028a": "uh",
    "u": "uw", "\u0268": "ih", "\u0289": "uw",
    "e\u026a": "ey", "a\u026a": "ay", "\u0254\u026a": "oy", "o\u028a": "ow", "\u0259\u028a": "ow",
    "a\u028a": "aw", "\u026a\u0259": "ih", "e\u0259": "eh", "\u025b\u0259": "eh",
    "\u028a\u0259": "uh", "\u025b\u0279": "eh", "\u0251\u0279": "aa", "\u0254\u0279": "ao",
}
#: marks an IPA label may carry that do not change the phone: stress, length, ties, syllabic
_IPA_MARKS = re.compile("[\u02c8\u02cc'\u02d0\u02d1:\u0361\u035c\u0329\u030d\u032f.]")


def _arpabet_fold(label: str) -> str:
    return re.sub(r"[012]$", "", label.strip().lower())


def _sampa_fold(label: str) -> str:
    return label.strip().lstrip('"%')


def _ipa_fold(label: str) -> str:
    return _IPA_MARKS.sub("", unicodedata.normalize("NFD", label.strip()))


@dataclass(frozen=True)
class Alphabet:
    """A phone alphabet: its ``name``, the ``key`` that names it as a label map (``--label-map
    sampa``), its ``table`` (symbol -> ARPAbet) and how a label is looked up in it (``fold``:
    case, stress digits or marks)."""

    name: str
    key: str
    table: Mapping[str, str]
    fold: Callable[[str], str] = str.strip

    def lookup(self, label: str) -> str | None:
        """The ARPAbet phone of ``label``, or None when this alphabet does not know it."""
        return self.table.get(self.fold(label))


ARPABET_ALPHABET = Alphabet("ARPAbet", "arpabet", {p: p for p in (*ARPABET, *EXTENDED_ARPABET)},
                            _arpabet_fold)
#: The alphabets :func:`detect` tells apart, in the order that breaks a tie.
ALPHABETS: tuple[Alphabet, ...] = (
    ARPABET_ALPHABET,
    Alphabet("TIMIT", "timit", {**ARPABET_ALPHABET.table, **TIMIT_EXTRA}, _arpabet_fold),
    Alphabet("MOCHA-TIMIT", "mocha", MOCHA_TO_ARPABET, lambda s: s.strip().lower()),
    Alphabet("SAMPA", "sampa", SAMPA_TO_ARPABET, _sampa_fold),
    Alphabet("X-SAMPA", "x-sampa", X_SAMPA_TO_ARPABET, _sampa_fold),
    Alphabet("IPA", "ipa", IPA_TO_ARPABET, _ipa_fold),
)


def alphabet(key: str) -> Alphabet | None:
    """The alphabet named ``key`` (``mocha``, ``sampa``, ...; any case), or None."""
    return next((a for a in ALPHABETS if a.key == key.strip().lower()), None)


@dataclass
class Detection:
    """What :func:`detect` found: the ``alphabet`` that knows the most labels and the labels it
    does not know (``unknown``: none when the file is in that alphabet)."""

    alphabet: Alphabet
    unknown: list[str]
    n_labels: int


def _is_silence(label: str) -> bool:
    return normalise_label(label) == SILENCE


def detect(labels: Iterable[str]) -> Detection:
    """The alphabet of a file's labels.

    >>> detect(["sil", "dh", "i", "s", "@", "ii"]).alphabet.name
    'MOCHA-TIMIT'
    >>> d = detect(["DH", "AH0", "zz"]); d.alphabet.name, d.unknown
    ('ARPAbet', ['zz'])
    >>> detect(["D", "@", "b", "{", "i:"]).alphabet.name, detect(["ð", "ə", "ˈɔɪ"]).alphabet.name
    ('SAMPA', 'IPA')
    """
    distinct = list(dict.fromkeys(lab for lab in labels if not _is_silence(lab)))
    best: Detection | None = None
    for a in ALPHABETS:
        unknown = [lab for lab in distinct if a.lookup(lab) is None]
        if best is None or len(unknown) < len(best.unknown):
            best = Detection(a, unknown, len(distinct))
    assert best is not None
    return best


def to_arpabet(phones: Sequence[PhoneSegment], path: str | None = None) -> list[PhoneSegment]:
    """A label file's phones in ARPAbet: as they are when they are ARPAbet, else mapped with the
    alphabet :func:`detect` finds (logged once per file). Labels no alphabet knows raise an
    :class:`InputError` naming them, where each first appears, and the option that fixes it."""
    found = detect(s.label for s in phones)
    if found.unknown:
        first = {s.label: s.start for s in reversed(phones)}
        listed = ", ".join(f"{u!r} (at {first[u]:.3f} s)" for u in found.unknown[:8])
        more = f" and {len(found.unknown) - 8} more" if len(found.unknown) > 8 else ""
        known = found.n_labels - len(found.unknown)
        raise InputError(path, f"labels in no phone alphabet facetraj knows: {listed}{more}"
                               f" (the closest, {found.alphabet.name}, knows {known} of the "
                               f"{found.n_labels} labels; alphabets: "
                               f"{', '.join(a.name for a in ALPHABETS)}); map them onto ARPAbet "
                               f"with a label map, --label-map FILE of 'label<TAB>arpabet' lines")
    a = found.alphabet
    if a is ARPABET_ALPHABET:
        return list(phones)
    warn_file(log, path, "labels mapped onto ARPAbet", f"{a.name} labels, mapped onto ARPAbet",
              logging.INFO)
    return [PhoneSegment(s.start, s.end, SILENCE if _is_silence(s.label) else a.lookup(s.label)
                         or SILENCE) for s in phones]
