"""A one-line progress bar on stderr for the engine's ``progress(fraction, message)`` callbacks,
and the log handler that prints log lines above it, not through it (issue 38)."""

from __future__ import annotations

import logging
import sys
import time


class TerminalProgress:
    """A one-line progress bar on stderr when it is a terminal (silent otherwise). While it is
    drawn, a log line (:class:`LogAboveBar`) clears it, prints, and draws it again."""

    #: the bar drawn now, if any (one at a time: the command's)
    active: TerminalProgress | None = None

    def __init__(self, label: str, stream=None):
        self.label = label
        self.stream = stream or sys.stderr
        self.live = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last = -1
        self._start = time.monotonic()
        self._line = ""

    def __call__(self, fraction: float, message: str) -> None:
        pct = int(100 * fraction)
        if not self.live or pct == self._last:
            return
        self._last = pct
        bar = "#" * (pct // 4)
        self._line = (f"{self.label} [{bar:<25}] {pct:3d}% {message[:40]:<40}"
                      f"{remaining(time.monotonic() - self._start, fraction):>12}")
        self.stream.write("\r" + self._line)
        if fraction >= 1.0:
            self.stream.write("\n")
            self._line = ""
        TerminalProgress.active = self if self._line else None
        self.stream.flush()

    def clear(self) -> None:
        """Take the bar off its line (a log line is about to be printed there)."""
        if self._line:
            self.stream.write("\r" + " " * len(self._line) + "\r")

    def redraw(self) -> None:
        """Draw the bar again, under what was printed."""
        if self._line:
            self.stream.write(self._line)
            self.stream.flush()


class LogAboveBar(logging.StreamHandler):
    """A stderr log handler that prints each line above the progress bar being drawn (the bar is
    cleared, the line printed, the bar drawn again under it), not into it."""

    def emit(self, record: logging.LogRecord) -> None:
        bar = TerminalProgress.active
        if bar is None or bar.stream is not self.stream:
            super().emit(record)
            return
        bar.clear()
        super().emit(record)
        bar.redraw()


def remaining(elapsed: float, fraction: float) -> str:
    """The time left, estimated from the time so far, once there is enough to go by.

    >>> remaining(30.0, 0.25), remaining(1.0, 0.01), remaining(400.0, 0.5)
    ('~1.5 min left', '', '~7 min left')
    """
    if fraction < 0.02 or fraction >= 1.0 or elapsed < 2.0:
        return ""
    left = elapsed * (1.0 - fraction) / fraction
    if left < 60:
        return f"~{left:.0f} s left"
    return f"~{left / 60:.1f} min left" if left < 300 else f"~{left / 60:.0f} min left"
