"""A one-line progress bar on stderr for the engine's ``progress(fraction, message)`` callbacks."""

from __future__ import annotations

import sys


class TerminalProgress:
    """A one-line progress bar on stderr when it is a terminal (silent otherwise)."""

    def __init__(self, label: str, stream=None):
        self.label = label
        self.stream = stream or sys.stderr
        self.live = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last = -1

    def __call__(self, fraction: float, message: str) -> None:
        pct = int(100 * fraction)
        if not self.live or pct == self._last:
            return
        self._last = pct
        bar = "#" * (pct // 4)
        self.stream.write(f"\r{self.label} [{bar:<25}] {pct:3d}% {message[:40]:<40}")
        if fraction >= 1.0:
            self.stream.write("\n")
        self.stream.flush()
