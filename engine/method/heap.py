"""Memory that many small arrays held and let go, given back to the system.

Training gathers the corpus an utterance at a time: thousands of arrays of a few tens of kB
(each utterance's codewords), joined into the model's arrays at the end. The C library keeps
the memory of freed small blocks in the process's heap for later use, counted in its resident
size; with glibc, ``malloc_trim`` returns the free pages to the system. Elsewhere: nothing.
"""

from __future__ import annotations

import functools


@functools.cache
def _trim():
    """glibc's ``malloc_trim``, or ``None`` where there is none."""
    import ctypes.util  # training's (it starts subprocess's import): not for a synthesis's start

    try:
        return ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").malloc_trim
    except (OSError, AttributeError):
        return None


def give_back() -> None:
    """Return the heap's free pages to the system (when the C library can)."""
    trim = _trim()
    if trim is not None:
        trim(0)
