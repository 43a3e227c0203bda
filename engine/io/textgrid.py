"""Praat TextGrid text files read as Praat reads them: a stream of numbers, quoted strings and
``<exists>``/``<absent>`` flags, with labels between them (``xmin =``, ``intervals [3]:``) that
are skipped, so the long and the short text forms are one grammar. Anything else (``4.3O57``, a
stray character, text after the last tier), and what the grammar does not allow (a missing
number, a time that is not finite, too few intervals) is refused with the place it was found;
nothing is guessed, sorted or repaired. (praatio writes them; it reads them more leniently, and
more slowly.)
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

#: one token, told by the group that matches: a quoted string ("" inside it is one quote, line
#: breaks allowed), a number, a flag, a label skipped between the values (a key word such as
#: ``xmin``, ``tiers?`` or ``intervals:``, ``=``, an index such as ``[3]:``), else ``text``: any
#: other run of non-blanks, which the grammar refuses
_TOKEN = re.compile(r'\s*(?:"(?P<string>[^"]*(?:""[^"]*)*)"'
                    r'|(?P<number>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)(?=\s|\Z)'
                    r'|(?P<flag><exists>|<absent>)(?=\s|\Z)'
                    r'|(?P<label>[A-Za-z]+[?:]?|=|\[\d*\]:?)(?=\s|\Z)'
                    r'|(?P<text>\S+))')


class TextGridSyntaxError(ValueError):
    """The text is not a TextGrid; the message says where."""


@dataclass(frozen=True)
class Tier:
    """One tier: ``IntervalTier`` entries ``(start, end, label)``, ``TextTier`` ``(time, label)``."""

    kind: str
    name: str
    entries: list[tuple]


class _Tokens:
    """The file's tokens in order, read by what the grammar expects next."""

    def __init__(self, text: str):
        self.items: list[tuple[str, str]] = []
        for m in _TOKEN.finditer(text):
            kind = m.lastgroup
            if kind == "string":
                self.items.append((m["string"].replace('""', '"'), kind))
            elif kind is not None and kind != "label":
                self.items.append((m[kind], kind))
        self.at = 0

    def _next(self, kind: str, what: str):
        if self.at >= len(self.items):
            raise TextGridSyntaxError(f"the text ends where {what} was expected")
        value, got = self.items[self.at]
        if got != kind:
            raise TextGridSyntaxError(f"expected {what}, found {_shown(value)}")
        self.at += 1
        return value

    def string(self, what: str) -> str:
        return self._next("string", what)

    def number(self, what: str) -> float:
        value = float(self._next("number", what))
        if not math.isfinite(value):
            raise TextGridSyntaxError(f"{what} is not a finite number ({value})")
        return value

    def count(self, what: str) -> int:
        value = self.number(what)
        if value != int(value) or value < 0:
            raise TextGridSyntaxError(f"{what} is not a count ({value:g})")
        return int(value)

    def end(self) -> None:
        """Nothing but labels may follow the last tier."""
        if self.at < len(self.items):
            raise TextGridSyntaxError(f"unexpected {_shown(self.items[self.at][0])} after the "
                                      f"last tier")

    def flag(self) -> str | None:
        if self.at < len(self.items) and self.items[self.at][1] == "flag":
            self.at += 1
            return self.items[self.at - 1][0]
        return None


def _shown(value: str) -> str:
    """A token as an error shows it: quoted, cut after 40 characters (a stray quote's string
    runs to the next quote)."""
    return repr(value if len(value) <= 40 else value[:40] + "...")


def parse_textgrid(text: str) -> list[Tier]:
    """The tiers of a TextGrid's text (long or short form), in the file's order.

    >>> short = ['File type = "ooTextFile"', 'Object class = "TextGrid"', "0", "1", "<exists>",
    ...          "1", '"IntervalTier"', '"phones"', "0", "1", "2", "0", "0.4", '"sil"', "0.4", "1",
    ...          '"a ""b"" c"']
    >>> parse_textgrid(chr(10).join(short))
    [Tier(kind='IntervalTier', name='phones', entries=[(0.0, 0.4, 'sil'), (0.4, 1.0, 'a "b" c')])]
    """
    t = _Tokens(text)
    if t.string("the file type") != "ooTextFile" or t.string("the object class") != "TextGrid":
        raise TextGridSyntaxError('not a TextGrid text file (it must start with File type = '
                                  '"ooTextFile", Object class = "TextGrid")')
    t.number("the start time")
    t.number("the end time")
    if t.flag() == "<absent>":
        t.end()
        return []
    tiers = []
    for k in range(t.count("the number of tiers")):
        kind = t.string(f"tier {k + 1}'s class")
        name = t.string(f"tier {k + 1}'s name")
        t.number(f"tier {name!r}'s start time")
        t.number(f"tier {name!r}'s end time")
        n = t.count(f"tier {name!r}'s number of entries")
        if kind == "IntervalTier":
            entries = [(t.number(f"tier {name!r}: interval {i + 1}'s start"),
                        t.number(f"tier {name!r}: interval {i + 1}'s end"),
                        t.string(f"tier {name!r}: interval {i + 1}'s label")) for i in range(n)]
        elif kind == "TextTier":
            entries = [(t.number(f"tier {name!r}: point {i + 1}'s time"),
                        t.string(f"tier {name!r}: point {i + 1}'s label")) for i in range(n)]
        else:
            raise TextGridSyntaxError(f"tier {k + 1} has class {kind!r}, not IntervalTier or "
                                      f"TextTier")
        tiers.append(Tier(kind, name, entries))
    t.end()
    return tiers
