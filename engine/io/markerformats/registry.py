"""The one registry of marker-file formats: which reader reads a file, and what is accepted.

Every format is a :class:`MarkerFormat` in a module of this package (its ``FORMATS`` tuple); the
registry finds them there, so adding a format is adding one module (and its tests). A file is
read by the first format whose content test (``sniff``, on the file's first bytes) says it is
one of its files; when none does, by its suffix (a suffix two formats share goes to the one
without a content test: a ``.pos`` without the AG50x header is an AG500 file). Every error about
an unknown format lists what :func:`accepted` says, made from the same list.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from ...errors import InputError
from .common import check_rate
from .recording import MarkerRecording

#: Bytes of a file's start that the content tests see.
SNIFF_BYTES = 1024
#: Modules of this package that hold no format.
_NOT_FORMATS = {"registry", "recording", "common", "channels"}


@dataclass(frozen=True)
class MarkerFormat:
    """One marker-file format.

    Attributes
    ----------
    name : what the format is called in messages and docs.
    suffixes : the file suffixes (lower case) read as this format when no content test matches.
    read : the reader: a path to a :class:`MarkerRecording` (mm, facetraj's axes, NaN missing),
        or an :class:`~facetraj_engine.errors.InputError` naming the file and the problem.
    sniff : a test on the file's first :data:`SNIFF_BYTES` bytes: whether the content says it is
        this format (``None``: known by suffix alone).
    signature : what the content test looks for, for messages.
    carries_audio, carries_labels : the files can hold the speech, and its labels, themselves.
    takes_rate : ``read`` takes the rate as a second argument, for files that may not give it.
    order : precedence among the formats (content tests run in this order).
    """

    name: str
    suffixes: tuple[str, ...]
    read: Callable[[Path], MarkerRecording]
    sniff: Callable[[bytes], bool] | None = None
    signature: str = ""
    carries_audio: bool = False
    carries_labels: bool = False
    takes_rate: bool = False
    order: int = 50

    def describe(self) -> str:
        """The format, its suffixes and content signature, for messages.

        >>> MarkerFormat("XRMB", (".txy",), lambda p: None).describe()
        'XRMB (.txy)'
        """
        return f"{self.name} ({', '.join(self.suffixes)}{'; ' + self.signature if self.signature else ''})"


@cache
def formats() -> tuple[MarkerFormat, ...]:
    """Every format of this package's modules, in precedence order."""
    found: list[MarkerFormat] = []
    for info in pkgutil.iter_modules([str(Path(__file__).parent)]):
        if info.name not in _NOT_FORMATS:
            module = importlib.import_module(f".{info.name}", __package__)
            found.extend(getattr(module, "FORMATS", ()))
    return tuple(sorted(found, key=lambda f: (f.order, f.name)))


def marker_suffixes() -> tuple[str, ...]:
    """Every suffix a marker file may have, in precedence order (for finding an utterance's file)."""
    return tuple(dict.fromkeys(s for f in formats() for s in f.suffixes))


def accepted() -> str:
    """What facetraj reads as marker files, in words (every format error ends with it)."""
    return "facetraj reads " + ", ".join(f.describe() for f in formats())


def format_of(path: Path) -> MarkerFormat | None:
    """The format of the file at ``path`` by its content, else its suffix; ``None`` if neither."""
    if path.is_file():
        with open(path, "rb") as fh:
            head = fh.read(SNIFF_BYTES)
        for fmt in formats():
            if fmt.sniff is not None and fmt.sniff(head):
                return fmt
    by_suffix = [f for f in formats() if path.suffix.lower() in f.suffixes]
    # a suffix two formats share goes to the one its content cannot announce (.pos: AG500)
    return next((f for f in by_suffix if f.sniff is None), by_suffix[0] if by_suffix else None)


def format_for(path: str | Path) -> MarkerFormat:
    """The format that reads ``path``, or an :class:`InputError` listing what is accepted."""
    path = Path(path)
    if path.is_dir():
        raise InputError(path, "is a folder, not a marker file")
    fmt = format_of(path)
    if fmt is not None and not path.exists():
        raise InputError(path, "no such marker file")
    if fmt is None:
        raise InputError(path, f"unknown marker format {path.suffix.lower() or '(no suffix)'!r} "
                               f"({accepted()})")
    return fmt


def read_recording(path: str | Path, rate: float | None = None) -> MarkerRecording:
    """Read any marker file into a :class:`MarkerRecording`, checked: a sane rate, frames and
    markers, no marker without a single sample. ``rate`` is used only by a file that gives none."""
    path = Path(path)
    fmt = format_for(path)
    rec = fmt.read(path, rate) if fmt.takes_rate else fmt.read(path)
    rec.format = fmt.name
    check_rate(path, rec.rate, " (from the file)")
    if rec.markers.ndim != 3 or rec.markers.shape[0] == 0 or rec.markers.shape[1] == 0:
        raise InputError(path, "the marker file holds no frames or no markers")
    if len(rec.names) != rec.markers.shape[1]:
        raise InputError(path, f"{len(rec.names)} names for {rec.markers.shape[1]} markers")
    empty = [n for n, seen in zip(rec.names, np.isfinite(rec.markers).all(axis=2).any(axis=0),
                                  strict=True) if not seen]
    if empty:
        raise InputError(path, f"no valid sample of {', '.join(empty[:5])}"
                               f"{' ...' if len(empty) > 5 else ''} ({rec.missing} samples marked "
                               f"missing); leave such channels out with --channel-names NAME=-")
    return rec


def held_recording(path: str | Path, carries: str) -> MarkerRecording | None:
    """The recording of ``path`` when it is a marker file whose format can hold the speech itself
    (``carries="carries_audio"``) or its labels (``"carries_labels"``): an MVIEW file; ``None``
    for any other file, of no format or of one that holds neither."""
    try:
        fmt = format_for(path)
    except InputError:
        return None
    return read_recording(path) if getattr(fmt, carries) else None
