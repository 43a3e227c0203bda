"""Errors raised for bad input: each names the file and the problem.

The command line prints ``str(err)`` and exits with status 2; the app shows it in a dialog.
"""

from __future__ import annotations

from os import PathLike


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


class OutputError(InputError, OSError):
    """An output path that cannot be written (also an :class:`OSError`, for callers that catch
    those around a save)."""


class OutputExistsError(OutputError, FileExistsError):
    """The output file exists and replacing it was not asked for (``--overwrite``)."""


class ModelFileError(InputError):
    """A model file that is not ours, truncated, or of a newer format."""
