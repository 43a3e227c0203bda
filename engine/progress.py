"""The progress callback that every long engine function accepts.

``progress(fraction, message)`` is called with the fraction done (0 to 1) and a short message;
the command line draws a bar from it, the app a progress indicator.

>>> seen = []
>>> report: Progress = lambda f, m: seen.append((f, m))
>>> report(0.5, "half"); seen
[(0.5, 'half')]
"""

from __future__ import annotations

from collections.abc import Callable

Progress = Callable[[float, str], None]


def no_progress(fraction: float, message: str) -> None:
    """A progress callback that reports nothing."""
