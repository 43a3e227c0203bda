"""Errors raised for bad input: each names the file and the problem; and warnings about input
files, each logged once.

The command line prints ``str(err)`` and exits with status 2; the app shows it in a dialog. Every
error here survives pickling (a worker process's error is rebuilt in the parent as it was raised,
:mod:`facetraj_engine.fanout`).

A warning about a file (markers shorter than the audio, channels mixed down, ...) goes through
:func:`warn_file`: logged the first time only, however often the file is read (a corpus command
reads each utterance several times), and counted, so that a corpus-wide command ends with one line
per kind of problem and the number of files that had it (:func:`file_warning_summary`).
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass
from os import PathLike
from typing import Any


class FacetrajError(Exception):
    """Base class of every error that facetraj reports to a user."""


class InputError(FacetrajError):
    """A file the user gave cannot be used.

    Examples
    --------
    >>> str(InputError("a.wav", "the file is empty"))
    'a.wav: the file is empty'
    >>> import pickle; str(pickle.loads(pickle.dumps(InputError("a.wav", "the file is empty"))))
    'a.wav: the file is empty'
    """

    def __init__(self, path: str | PathLike[str] | None, problem: str):
        self.path = None if path is None else str(path)
        self.problem = " ".join(str(problem).split())  # always one line (library texts may wrap)
        super().__init__(f"{self.path}: {self.problem}" if self.path else self.problem)

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its class, path, problem and attributes (a worker process's error comes
        back as the same error; subclasses with other ``__init__`` arguments included).

        >>> import pickle
        >>> str(pickle.loads(pickle.dumps(OutputExistsError("o.tsv", "exists"))))
        'o.tsv: exists'
        """
        return _rebuild, (type(self), self.path, self.problem, dict(self.__dict__))


def _rebuild(cls: type[InputError], path: str | None, problem: str,
             state: dict[str, Any]) -> InputError:
    """An :class:`InputError` of class ``cls`` unpickled, without calling its ``__init__``."""
    err = cls.__new__(cls)
    InputError.__init__(err, path, problem)
    err.__dict__.update(state)
    return err


class OutputError(InputError, OSError):
    """An output path that cannot be written (also an :class:`OSError`, for callers that catch
    those around a save)."""


class OutputExistsError(OutputError, FileExistsError):
    """The output file exists and replacing it was not asked for (``--overwrite``)."""


class ModelFileError(InputError):
    """A model file that is not ours, truncated, or of a newer format."""


# --------------------------------------------------------------------------- file warnings
@dataclass(frozen=True)
class FileWarning:
    """One warning about one file: the logger and level it goes to, the file, the kind of problem
    (``what``: the same text for every file that has it) and the message."""

    logger: str
    level: int
    path: str
    what: str
    message: str


class FileWarnings:
    """The warnings about files logged in this process: each logged once, counted by kind.

    In a worker process (``quiet``) they are recorded, not logged: the worker sends them to the
    parent (:meth:`since`), which logs those it has not logged yet (:meth:`merge`).
    """

    def __init__(self) -> None:
        self._seen: dict[tuple[str, str, str], FileWarning] = {}
        self.quiet = False

    def warn(self, w: FileWarning) -> None:
        key = (w.what, w.path, w.message)
        if key in self._seen:
            return
        self._seen[key] = w
        if not self.quiet:
            logging.getLogger(w.logger).log(w.level, "%s: %s", w.path, w.message)

    def mark(self) -> int:
        return len(self._seen)

    def since(self, mark: int) -> list[FileWarning]:
        """The warnings recorded after :meth:`mark` returned ``mark``."""
        return list(self._seen.values())[mark:]

    def merge(self, warnings: list[FileWarning]) -> None:
        for w in warnings:
            self.warn(w)

    def counts(self, level: int = logging.WARNING) -> Counter:
        """Files per kind of problem, for warnings of at least ``level``."""
        return Counter(w.what for w in {(w.what, w.path): w for w in self._seen.values()}.values()
                       if w.level >= level)

    def clear(self) -> None:
        self._seen.clear()


#: the file warnings of this process
FILE_WARNINGS = FileWarnings()


def warn_file(logger: logging.Logger, path: str | PathLike[str] | None, what: str, message: str,
              level: int = logging.WARNING) -> None:
    """Log ``path: message`` once per file (and message); ``what`` names the kind of problem for
    the corpus-wide count (:func:`file_warning_summary`).

    >>> FILE_WARNINGS.clear()
    >>> for _ in range(3):
    ...     warn_file(logging.getLogger("x"), "a.c3d", "short markers", "markers end at 1.00 s")
    >>> warn_file(logging.getLogger("x"), "b.c3d", "short markers", "markers end at 2.00 s")
    >>> file_warning_summary()
    ['short markers: 2 files']
    """
    FILE_WARNINGS.warn(FileWarning(logger.name, level, str(path or "input"), what, message))


def file_warning_summary() -> list[str]:
    """One line per kind of warning logged in this process, with the number of files."""
    return [f"{what}: {n} file{'s' if n != 1 else ''}"
            for what, n in sorted(FILE_WARNINGS.counts().items())]
