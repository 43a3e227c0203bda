"""A one-line progress bar on stderr for the engine's ``progress(fraction, message)`` callbacks."""

from __future__ import annotations

import sys
import time


class TerminalProgress:
    """A one-line progress bar on stderr when it is a terminal (silent otherwise)."""

    def __init__(self, label: str, stream=None):
        self.label = label
        self.stream = stream or sys.stderr
        self.live = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last = -1
        self._start = time.monotonic()

    def __call__(self, fraction: float, message: str) -> None:
        pct = int(100 * fraction)
        if not self.live or pct == self._last:
            return
        self._last = pct
        bar = "#" * (pct // 4)
        self.stream.write(f"\r{self.label} [{bar:<25}] {pct:3d}% {message[:40]:<40}"
                          f"{remaining(time.monotonic() - self._start, fraction):>12}")
        if fraction >= 1.0:
            self.stream.write("\n")
        self.stream.flush()


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
