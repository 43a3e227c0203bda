"""Work fanned out over processes, one item (an utterance, a recording) at a time, with the
serial run's errors.

:func:`fan_out` runs ``fn(item)`` for every item, serially or in worker processes (forked, so
that the model and the corpus are inherited, not pickled). Either way a bad file gives the same
outcome:

- by default, the first item in order whose file is bad stops the work with its own
  :class:`~engine.errors.FacetrajError` (``file: problem``; its ``item`` attribute names the
  item), as the serial run does; the items still waiting are cancelled;
- with a :class:`Skips` (the commands' ``--skip-bad``), the item is left out, its message kept,
  and the work goes on; the command ends with :meth:`Skips.summary` ("1 of 3 utterances skipped:
  ...") and exit status 3 (its result is incomplete).

A worker's error comes back as it was raised (every facetraj error pickles, and anything that
does not is replaced by a plain copy before it leaves the worker); a worker that dies (killed,
out of memory, a crash in a file reader) is an error naming the items it was working on, never a
``BrokenProcessPool`` traceback. The warnings about files a worker logs (``engine.errors
.warn_file``) are sent to the parent, which logs each once.
"""

from __future__ import annotations

import logging
import pickle
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

from .errors import FILE_WARNINGS, FacetrajError, FileWarning, InputError
from .progress import Progress
from .threads import limit_frame_threads, one_blas_thread

log = logging.getLogger(__name__)

I = TypeVar("I", bound=Hashable)
R = TypeVar("R")


@dataclass
class Skips:
    """Items left out because their files were bad (``--skip-bad``): item -> message; and every
    item tried, for the count. One object may follow several passes over the same items (the
    report trains, then evaluates three times): each item counts once.

    >>> s = Skips("utterances")
    >>> s.tried.update(["a", "b", "c"]); s.add("b", InputError("b.c3d", "not a C3D file"))
    >>> s.summary()
    '1 of 3 utterances skipped: b.c3d: not a C3D file'
    """

    noun: str = "utterances"
    bad: dict[Any, str] = field(default_factory=dict)
    tried: set = field(default_factory=set)

    def add(self, item: Any, exc: BaseException) -> None:
        if item not in self.bad:
            self.bad[item] = str(exc)
            log.warning("skipped: %s", exc)

    def __bool__(self) -> bool:
        """True when something was skipped."""
        return bool(self.bad)

    def summary(self) -> str:
        """``"k of n <noun> skipped: <message>"`` (one message per line when several)."""
        head = f"{len(self.bad)} of {len(self.tried | set(self.bad))} {self.noun} skipped"
        if len(self.bad) == 1:
            return f"{head}: {next(iter(self.bad.values()))}"
        return head + ":" + "".join(f"\n  {msg}" for msg in self.bad.values())


@dataclass
class _Done(Generic[R]):
    """What a worker sends back for one item: its result or its error, and the file warnings
    the item raised."""

    result: R | None = None
    error: FacetrajError | None = None
    warnings: list[FileWarning] = field(default_factory=list)


def portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else a plain copy that does (same message; a facetraj
    error stays one, as an :class:`InputError` when it names a file)."""
    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:  # any failure to pickle or rebuild: the exception's own code ran
        if isinstance(exc, InputError):
            return InputError(exc.path, exc.problem)
        if isinstance(exc, FacetrajError):
            return FacetrajError(str(exc))
        return RuntimeError(f"{type(exc).__name__}: {exc}")


#: called in the parent before worker processes fork: what every worker would otherwise load
#: for itself (``engine.method.kernels`` loads the compiled kernels here), loaded once
_BEFORE_FORK: list[Callable[[], None]] = []


def before_fork(fn: Callable[[], None]) -> None:
    """Have ``fn()`` called in the parent before :func:`fan_out` forks its workers (once per
    registration, whatever the number of calls)."""
    if fn not in _BEFORE_FORK:
        _BEFORE_FORK.append(fn)


def prepare_fork() -> None:
    """Run the :func:`before_fork` hooks: call it right before any ``fork`` (``fan_out`` does):
    no thread is then half-way through loading what a child would inherit locked."""
    for prepare in _BEFORE_FORK:
        prepare()


#: what a worker process runs, inherited by fork (not pickled)
_WORKER: tuple[Callable[[Any], Any], Sequence[Any]] | None = None


def _worker_init(fn: Callable[[Any], Any], items: Sequence[Any]) -> None:
    global _WORKER
    _WORKER = (fn, items)
    one_blas_thread()            # the processes share the cores (engine.threads)
    FILE_WARNINGS.quiet = True   # the parent logs them


def _run_in_worker(index: int) -> _Done:
    assert _WORKER is not None
    fn, items = _WORKER
    mark = FILE_WARNINGS.mark()
    try:
        with limit_frame_threads(1):    # one process per core already
            done = _Done(result=fn(items[index]))
    except FacetrajError as exc:
        done = _Done(error=portable(exc))  # type: ignore[arg-type]
    except BaseException as exc:
        # a bug: raised as it is (its traceback comes with it), unless it would not unpickle
        safe = portable(exc)
        if safe is exc:
            raise
        raise safe from None
    done.warnings = FILE_WARNINGS.since(mark)
    return done


def fan_out(fn: Callable[[I], R], items: Sequence[I], workers: int = 1, *,
            skip: Skips | None = None, progress: Progress | None = None,
            describe: Callable[[I], str] = str) -> list[tuple[I, R]]:
    """``(item, fn(item))`` for every item, in order, computed in ``workers`` processes (forked;
    serially for 1, or where fork is unavailable). A :class:`~engine.errors.FacetrajError` of an
    item stops the work (raised as it is), or with ``skip`` leaves the item out (recorded there).
    ``progress(fraction, describe(item))`` as the items are taken in order."""
    items = list(items)
    if skip is not None:
        skip.tried.update(items)
    workers = max(1, min(workers, len(items)))
    import multiprocessing as mp  # here: the app imports this module at start

    if workers > 1 and "fork" in mp.get_all_start_methods():
        return _in_processes(fn, items, workers, skip, progress, describe)
    out: list[tuple[I, R]] = []
    for k, item in enumerate(items):
        if progress:
            progress(k / len(items), describe(item))
        try:
            out.append((item, fn(item)))
        except FacetrajError as exc:
            if skip is None:
                exc.item = item         # what --skip-bad would have left out
                raise
            skip.add(item, exc)
    if progress:
        progress(1.0, "done")
    return out


def _in_processes(fn: Callable[[I], R], items: list[I], workers: int, skip: Skips | None,
                  progress: Progress | None, describe: Callable[[I], str]) -> list[tuple[I, R]]:
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    out: list[tuple[I, R]] = []
    prepare_fork()
    pool = ProcessPoolExecutor(workers, mp.get_context("fork"), initializer=_worker_init,
                               initargs=(fn, items))
    try:
        futures = [pool.submit(_run_in_worker, k) for k in range(len(items))]
        for k, (fut, item) in enumerate(zip(futures, items, strict=True)):
            if progress:
                progress(k / len(items), describe(item))
            try:
                done = fut.result()
            except BrokenProcessPool:
                raise FacetrajError(
                    f"a worker process stopped unexpectedly (out of memory, or a crash in a file "
                    f"reader) while {describe(item)} or one of the {workers - 1} beside it was in "
                    f"work; run with --jobs 1 to see which file it was") from None
            FILE_WARNINGS.merge(done.warnings)
            if done.error is not None:
                if skip is None:
                    done.error.item = item
                    raise done.error
                skip.add(item, done.error)
                continue
            out.append((item, done.result))
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    if progress:
        progress(1.0, "done")
    return out
