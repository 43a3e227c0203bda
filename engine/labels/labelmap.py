"""Label maps: other phone alphabets onto ARPAbet (the model's phone set).

A label map file is UTF-8 text, one ``label<TAB>arpabet`` pair per line (``#`` comments). The
alphabets facetraj knows (MOCHA-TIMIT, TIMIT, SAMPA, X-SAMPA, IPA: :mod:`.alphabets`) are label maps
too, named by their key (``mocha``, ``sampa``, ...); :data:`MOCHA_TO_ARPABET` is MOCHA's table.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from .alphabets import MOCHA_TO_ARPABET, Alphabet, alphabet

__all__ = ["MOCHA_TO_ARPABET", "AlphabetMap", "LabelMap", "read_label_map"]

class LabelMap(dict):
    """A label map (label -> ARPAbet) that remembers where it was read from, so that a label it
    maps to an unknown phone is blamed on it, not on the label file."""

    def __init__(self, table: dict[str, str], source: str):
        super().__init__(table)
        self.source = source


class AlphabetMap(LabelMap):
    """A built-in alphabet as a label map: labels looked up as the alphabet writes them (its
    case, stress and length marks)."""

    def __init__(self, alpha: Alphabet):
        super().__init__(dict(alpha.table), f"the built-in {alpha.name} label map")
        self.alphabet = alpha

    def get(self, label, default=None):
        found = self.alphabet.lookup(label)
        return default if found is None else found

    def __contains__(self, label) -> bool:
        return self.alphabet.lookup(label) is not None


def read_label_map(path: str | os.PathLike[str]) -> LabelMap:
    """Read a ``label<TAB>arpabet`` file (whitespace also separates); ``mocha``, ``timit``,
    ``sampa``, ``x-sampa`` and ``ipa`` name the built-in alphabets."""
    if str(path).lower() == "mocha":
        return LabelMap(MOCHA_TO_ARPABET, "the built-in MOCHA label map")
    named = alphabet(str(path)) if not Path(path).exists() else None
    if named is not None:
        return AlphabetMap(named)
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
