"""How many threads numpy's BLAS may use, and how many threads synthesis splits its frames
between.

OpenBLAS keeps a thread per core and lets idle ones spin while they wait for work. Our matrix
products are small (frames x codewords), so a second BLAS thread buys little, and when the cores
are busy (the evaluation's worker processes, the app's synthesis beside its rendering, other
programs) the spinning threads take the cores from the work (docs/benchmarks.md measures it).
Work that runs beside other work therefore uses one BLAS thread, and so does synthesis itself
(:func:`above_blas`): its own frame threads are the other work.

Synthesis parallelises above BLAS instead: its per-frame stages (the LSF analysis, the LSF index
search, eqs 5-8) are independent from frame to frame, and numpy releases the interpreter lock
inside its array operations, so contiguous spans of frames run in threads, one per usable core
(:func:`frame_threads`), each frame computed as it would be alone. The rule for how many lives
here, once.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import os
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import AbstractContextManager
from contextvars import ContextVar
from itertools import pairwise
from typing import ParamSpec, TypeVar

from threadpoolctl import ThreadpoolController, threadpool_limits

T = TypeVar("T")
P = ParamSpec("P")

#: environment variable that sets the frame threads (a positive integer) in place of the cores
THREADS_ENV = "FACETRAJ_THREADS"
#: the fewest frames a thread is given. Numpy releases the interpreter lock only inside each
#: array operation, and a thread waits for it between operations: with 10 s of 60 Hz frames in
#: all, two threads took longer than one; with 60 s, up to 1.5x (phonetic) and 1.8x
#: (acoustic-only) less time (docs/benchmarks.md)
MIN_FRAMES_PER_THREAD = 600
#: at most this many frame threads, whatever the machine
MAX_FRAME_THREADS = 8

_limit: ContextVar[int | None] = ContextVar("frame_thread_limit", default=None)
#: the frame threads' pool and its size, made when first needed
_pool: tuple[ThreadPoolExecutor, int] | None = None


def _forget_pool() -> None:
    """In a forked child: the parent's pool threads do not exist there, and a task given to the
    copied pool would wait for them for ever; the child makes its own when it needs one."""
    global _pool
    _pool = None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def one_blas_thread() -> AbstractContextManager:
    """Limit BLAS to one thread: until the end of the ``with`` block, or (called on its own) for
    the rest of the process.

    >>> import numpy as np
    >>> with one_blas_thread():
    ...     float((np.eye(3) @ np.ones(3)).sum())
    3.0
    """
    return threadpool_limits(limits=1, user_api="blas")


def above_blas(fn: Callable[P, T]) -> Callable[P, T]:
    """``fn`` splits its work between frame threads (:func:`map_spans`): while it runs, BLAS
    runs on one thread, else its idle threads spin beside the frame threads and take the cores
    from them (docs/benchmarks.md, "BLAS beside the frame threads")."""
    @functools.wraps(fn)
    def run(*args: P.args, **kwargs: P.kwargs) -> T:
        with _loaded_blas().limit(limits=1, user_api="blas"):
            return fn(*args, **kwargs)

    return run


@functools.cache
def _loaded_blas() -> ThreadpoolController:
    """The BLAS libraries loaded when first asked (numpy's among them), found once: finding
    them walks the process's libraries, which takes longer than synthesizing a short input."""
    return ThreadpoolController()


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS tells it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:                          # not on Linux
        return max(1, os.cpu_count() or 1)


def frame_threads() -> int:
    """How many threads synthesis splits its frames between: the limit set by
    :func:`limit_frame_threads` in this thread, else ``$FACETRAJ_THREADS``, else the usable cores
    (at most :data:`MAX_FRAME_THREADS`).

    >>> with limit_frame_threads(1):
    ...     frame_threads()
    1
    """
    limit = _limit.get()
    if limit is not None:
        return limit
    env = os.environ.get(THREADS_ENV, "").strip()
    if env.isdigit() and int(env) > 0:
        return min(int(env), MAX_FRAME_THREADS)
    return min(usable_cores(), MAX_FRAME_THREADS)


@contextlib.contextmanager
def limit_frame_threads(n: int) -> Iterator[None]:
    """Synthesis in this thread (and its context) uses at most ``n`` frame threads until the end
    of the ``with`` block: for work that already runs one process per core (the evaluation)."""
    token = _limit.set(max(1, int(n)))
    try:
        yield
    finally:
        _limit.reset(token)


def frame_spans(n_frames: int, threads: int | None = None) -> list[tuple[int, int]]:
    """``n_frames`` cut into contiguous ``(start, stop)`` spans, one per thread (``threads``,
    default :func:`frame_threads`), none shorter than :data:`MIN_FRAMES_PER_THREAD` frames.

    >>> frame_spans(3000, 2), frame_spans(1000, 2), frame_spans(0, 2)
    ([(0, 1500), (1500, 3000)], [(0, 1000)], [(0, 0)])
    """
    threads = frame_threads() if threads is None else threads
    k = max(1, min(threads, n_frames // MIN_FRAMES_PER_THREAD))
    cuts = [n_frames * i // k for i in range(k + 1)]
    return list(pairwise(cuts))


def map_spans(fn: Callable[[int, int], T], n_frames: int, threads: int | None = None) -> list[T]:
    """``fn(start, stop)`` for each of :func:`frame_spans`, in threads when there are several;
    the results in span order, each span run in a copy of the caller's context (its
    :func:`limit_frame_threads` holds there). An
    exception in a span is raised here. (The threads' matrix
    products are small: callers that run beside other work run BLAS on one thread, as the app,
    live mode and the evaluation do, :func:`one_blas_thread`.)

    >>> map_spans(lambda a, b: b - a, 3000, 2)
    [1500, 1500]
    """
    spans = frame_spans(n_frames, threads)
    if len(spans) == 1:
        return [fn(*spans[0])]
    global _pool
    if _pool is None or _pool[1] < len(spans):
        _pool = (ThreadPoolExecutor(len(spans), thread_name_prefix="facetraj-frames"), len(spans))
    # each span in a copy of the caller's context: its frame-thread limit holds there
    futures = [_pool[0].submit(contextvars.copy_context().run, fn, a, b) for a, b in spans]
    return [f.result() for f in futures]
