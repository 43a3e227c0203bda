"""Start-up phases at debug level (``facetraj -v``): each step on the way to the window's first
frame, logged with the seconds since the process started. This is the profile behind the
cold-start benchmark (``benchmarks/startup.py``, docs/benchmarks.md "Cold start", issue #15).
"""

from __future__ import annotations

import logging
import os
import time

log = logging.getLogger(__name__)


def _process_start() -> float:
    """The process's start on the ``time.monotonic`` clock: from ``/proc`` on Linux (boot-time
    clock ticks, 10 ms resolution), elsewhere the import of this module."""
    try:
        with open(f"/proc/{os.getpid()}/stat", "rb") as fh:
            ticks = int(fh.read().rsplit(b")", 1)[1].split()[19])   # field 22: starttime
        since_boot = ticks / os.sysconf("SC_CLK_TCK")
        return time.monotonic() - (time.clock_gettime(time.CLOCK_BOOTTIME) - since_boot)
    except (OSError, ValueError, IndexError, AttributeError):
        return time.monotonic()


_START = _process_start()


def process_seconds() -> float:
    """Seconds since this process started."""
    return time.monotonic() - _START


def mark(phase: str) -> None:
    """Log that start-up reached ``phase`` (debug level, with the time since the process started)."""
    if log.isEnabledFor(logging.DEBUG):
        log.debug("phase %-34s %6.2f s after the process started", phase, process_seconds())
