"""Mapping a file's channels onto articulators: ``--channel-names``, ``channel_names`` in
corpus.json, or a ``channel-names.txt`` beside the data.

Two forms, never mixed: ``OLD=NEW`` renames the channel ``OLD`` (``NEW`` = ``-`` leaves it out),
and a plain list names every channel in the file's order (logged, channel by channel: no channel
is renamed by its position without a message).
"""

from __future__ import annotations

import logging
import re
from collections.abc import Sequence
from pathlib import Path

from ...errors import InputError
from ..files import read_text
from .recording import MarkerRecording

log = logging.getLogger(__name__)

#: The names file looked for beside a folder's recordings.
NAMES_FILE = "channel-names.txt"
#: What a marker name may be: letters, digits, ``_ - . +``.
_NAME = re.compile(r"^[A-Za-z0-9_.+-]{1,64}$")
DROP = "-"


def read_names_file(path: str | Path) -> list[str]:
    """The channel names of a names file: ``OLD NEW`` or ``OLD=NEW`` lines, or one new name a
    line (every channel in order); ``#`` starts a comment."""
    path = Path(path)
    out = []
    for lineno, line in enumerate(read_text(path, "channel names file").splitlines(), 1):
        fields = line.split("#", 1)[0].replace("=", " ").split()
        if len(fields) > 2:
            raise InputError(path, f"line {lineno}: expected 'OLD NEW' or one name, got {line!r}")
        if fields:
            out.append("=".join(fields))
    if not out:
        raise InputError(path, "the channel names file names no channel")
    check_names(out, path)
    return out


def check_names(spec: Sequence[str], source: str | Path | None = None) -> None:
    """Refuse a malformed mapping (mixed forms, names facetraj cannot use, a name twice)."""
    renames = [s for s in spec if "=" in s]
    if renames and len(renames) != len(spec):
        raise InputError(source, "channel names mix OLD=NEW and plain names: use one form")
    new = [s.split("=", 1)[1] if "=" in s else s for s in spec]
    olds = [s.split("=", 1)[0] for s in renames]
    for name in [*new, *olds]:
        if name != DROP and not _NAME.match(name):
            raise InputError(source, f"channel name {name!r} is not a name (letters, digits, "
                                     f"'_', '-', '.', '+'; at most 64)")
    kept = [n for n in new if n != DROP]
    twice = sorted({n for n in kept if kept.count(n) > 1} | {n for n in olds if olds.count(n) > 1})
    if twice:
        raise InputError(source, f"channel names name {', '.join(twice)} twice")


def apply_names(rec: MarkerRecording, spec: Sequence[str] | None, path: Path) -> MarkerRecording:
    """``rec`` with its channels renamed (and left out) by ``spec``; an error names ``path``."""
    if not spec:
        return rec
    check_names(spec, path)
    if "=" in spec[0]:
        mapping = dict(s.split("=", 1) for s in spec)
        unknown = [old for old in mapping if old not in rec.names]
        if unknown:
            raise InputError(path, f"channel names rename {', '.join(unknown)}, not channels of "
                                   f"this file (its channels: {' '.join(rec.names)})")
        new = [mapping.get(n, n) for n in rec.names]
    else:
        if len(spec) != len(rec.names):
            raise InputError(path, f"{len(spec)} channel names for its {len(rec.names)} channels "
                                   f"({' '.join(rec.names)})")
        new = list(spec)
        log.info("%s: channels named by position: %s", path.name,
                 ", ".join(f"{o} -> {n}" for o, n in zip(rec.names, new, strict=True)))
    keep = [i for i, n in enumerate(new) if n != DROP]
    names = [new[i] for i in keep]
    if len(set(names)) != len(names):
        raise InputError(path, f"channel names give two channels one name "
                               f"({', '.join(sorted({n for n in names if names.count(n) > 1}))})")
    if not keep:
        raise InputError(path, "channel names leave no channel")
    return rec.with_markers(rec.markers[:, keep], names=names)
