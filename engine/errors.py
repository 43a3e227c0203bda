"""Errors raised for bad input: each names the file and the problem.

The command line prints ``str(err)`` and exits with status 2; the app shows it in a dialog.
"""

from __future__ import annotations

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
