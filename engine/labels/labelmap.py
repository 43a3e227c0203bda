"""Label maps: other phone alphabets onto ARPAbet (the model's phone set).

A label map file is UTF-8 text, one ``label<TAB>arpabet`` pair per line (``#`` comments). The
MOCHA-TIMIT (Edinburgh machine-readable) map ships with facetraj as :data:`MOCHA_TO_ARPABET`.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError

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


class LabelMap(dict):
    """A label map (label -> ARPAbet) that remembers where it was read from, so that a label it
    maps to an unknown phone is blamed on it, not on the label file."""

    def __init__(self, table: dict[str, str], source: str):
        super().__init__(table)
        self.source = source


def read_label_map(path: str | os.PathLike[str]) -> LabelMap:
    """Read a ``label<TAB>arpabet`` file (whitespace also separates); ``mocha`` names the built-in
    MOCHA map."""
    if str(path).lower() == "mocha":
        return LabelMap(MOCHA_TO_ARPABET, "the built-in MOCHA label map")
    path = Path(path)
    if not path.exists():
        raise InputError(path, "no such label map")
    if path.is_dir():
        raise InputError(path, "is a folder, not a label map file")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(path, "the label map is not UTF-8 text") from exc
    table = {}
    for lineno, line in enumerate(text.splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        if len(parts) != 2:
            raise InputError(path, f"line {lineno}: expected 'label arpabet', got {line!r}")
        table[parts[0]] = parts[1]
    return LabelMap(table, str(path))
