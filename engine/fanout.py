"""Work fanned out over processes, one item (an utterance, a recording) at a time, with the
serial run's errors.

:func:`fan_out` runs ``fn(item)`` for every item, serially or in worker processes (forked, so
that the model and the corpus are inherited, not pickled). Either way a bad file gives the same
outcome:

- by default, the first item in order whose file is bad stops the work with its own
  :class:`~facetraj_engine.errors.FacetrajError` (``file: problem``; its ``item`` attribute names the
  item), as the serial run does; the items still waiting are cancelled;
- with a :class:`Skips` (the commands' ``--skip-bad``), the item is left out, its message kept,
  and the work goes on; the command ends with :meth:`Skips.summary` ("1 of 3 utterances skipped:
  ...") and exit status 3 (its result is incomplete).

A worker's error comes back as it was raised (every facetraj error pickles, and anything that
does not is replaced by a plain copy before it leaves the worker); a worker that dies (killed,
out of memory, a crash in a file reader) is an error naming the item it was working on (with a
:class:`Skips`, that item is skipped), never a traceback. :func:`forked_map` is the worker
processes under both this and ``facetraj synth``'s batch. The warnings about files a worker
logs (``facetraj_engine.errors.warn_file``) are sent to the parent, which logs each once.
"""

from __future__ import annotations

import logging
import os
import pickle
import selectors
import signal
import struct
import traceback
from collections.abc import Callable, Hashable, Iterator, Sequence
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
#: for itself (``facetraj_engine.method.kernels`` loads the compiled kernels here), loaded once
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


# --------------------------------------------------------------------------- worker processes
# Forked once, they take their items themselves: each takes the next item's index from a counter
# they share, runs ``fn`` on it and sends the result back through its own pipe; the parent only
# reads. With a pool that hands items out itself (``concurrent.futures``) a worker waits for the
# parent's thread between items, and where the workers fill the cores that thread waits for a
# core: a batch of 100 files took 0.52 s with two workers, against 0.42 s for two separate
# processes of 50 files each (benchmarks/profile_notes.md).
_LENGTH = struct.Struct("<Q")


@dataclass
class WorkerDied:
    """The result of an item whose worker stopped while working on it: ``status`` is what
    ``os.waitstatus_to_exitcode`` gave (a negative signal number when killed)."""

    status: int

    def how(self) -> str:
        return f"killed by signal {-self.status}" if self.status < 0 else \
            f"exit status {self.status}"

    def describe(self) -> str:
        return f"the worker process stopped while working on it ({self.how()}: out of memory, " \
               f"or a crash in a file reader)"


class _Raised:
    """What a worker sends when ``fn`` raised: the exception (made picklable), re-raised in the
    parent."""

    def __init__(self, exc: BaseException):
        self.exc = exc


def _send(fd: int, message: Any) -> None:
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    view = memoryview(_LENGTH.pack(len(data)) + data)
    while view:
        view = view[os.write(fd, view):]


def _child(fn: Callable[[Any], Any], items: Sequence[Any], counter, fd: int,
           initializer: Callable[..., None] | None, initargs: tuple) -> None:
    """A worker's life: set up, then items taken from ``counter`` until none is left."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)       # the parent stops the work (module doc)
    code = 0
    try:
        if initializer is not None:
            initializer(*initargs)
        while True:
            with counter.get_lock():
                i = counter.value
                if i >= len(items):
                    break
                counter.value = i + 1
            _send(fd, ("take", i))
            try:
                result = fn(items[i])
            except BaseException as exc:               # a bug in fn: the parent raises it
                traceback.print_exc()                  # its traceback, where it happened
                _send(fd, ("done", i, _Raised(portable(exc))))
                code = 1
                break
            _send(fd, ("done", i, result))
    except BaseException:
        traceback.print_exc()
        code = 1
    finally:
        os._exit(code)


class _Worker:
    """The parent's view of one child: its pid, its pipe, the item it works on."""

    def __init__(self, pid: int, fd: int):
        self.pid, self.fd = pid, fd
        self.buffer = bytearray()
        self.working: int | None = None

    def messages(self, data: bytes) -> Iterator[tuple]:
        self.buffer += data
        while len(self.buffer) >= _LENGTH.size:
            (size,) = _LENGTH.unpack_from(self.buffer)
            if len(self.buffer) < _LENGTH.size + size:
                return
            message = pickle.loads(bytes(self.buffer[_LENGTH.size:_LENGTH.size + size]))
            del self.buffer[:_LENGTH.size + size]
            yield message


def can_fork() -> bool:
    """Whether :func:`forked_map` can run here (``fork`` exists: not on Windows); where it
    cannot, the work runs in this process."""
    return hasattr(os, "fork")


def forked_map(fn: Callable[[Any], Any], items: Sequence[Any], workers: int,
               initializer: Callable[..., None] | None = None, initargs: tuple = ()
               ) -> Iterator[tuple[int, Any]]:
    """``(index, fn(items[index]))`` for every item, as the ``workers`` forked children finish
    them (each set up once by ``initializer(*initargs)``); ``(index, WorkerDied)`` for an item
    whose worker died. An exception ``fn`` raises is raised here. Closing the iterator early
    (``break``, an error) lets the items in work finish and takes no more."""
    import multiprocessing as mp

    counter = mp.get_context("fork").Value("q", 0)
    running: dict[int, _Worker] = {}
    sel = selectors.DefaultSelector()
    left = len(items)

    def spawn() -> None:
        prepare_fork()
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:                                   # the child: never returns
            os.close(r)
            for other in running.values():
                os.close(other.fd)
            _child(fn, items, counter, w, initializer, initargs)
        os.close(w)
        running[r] = _Worker(pid, r)
        sel.register(r, selectors.EVENT_READ)

    try:
        for _ in range(max(1, min(workers, len(items)))):
            spawn()
        while running:
            for key, _ in sel.select():
                worker = running[key.fd]
                data = os.read(key.fd, 1 << 16)
                for message in worker.messages(data):
                    if message[0] == "take":
                        worker.working = message[1]
                        continue
                    _, i, result = message
                    worker.working, left = None, left - 1
                    if isinstance(result, _Raised):
                        raise result.exc
                    yield i, result
                if data:
                    continue
                sel.unregister(key.fd)                  # end of pipe: the worker is gone
                os.close(key.fd)
                del running[key.fd]
                _, status = os.waitpid(worker.pid, 0)
                code = os.waitstatus_to_exitcode(status)
                if worker.working is not None:
                    left -= 1
                    yield worker.working, WorkerDied(code)
                    if counter.value < len(items):      # another in its place
                        spawn()
                elif code != 0:                         # before its first item: its set-up
                    raise FacetrajError(f"a worker process stopped as it was set up "
                                        f"({WorkerDied(code).how()}); run with --jobs 1 to see why")
        if left > 0:
            raise RuntimeError(f"{left} items were neither done nor reported")
    finally:
        with counter.get_lock():
            counter.value = len(items)                  # take nothing more
        for worker in running.values():                 # the items in work finish
            try:
                while os.read(worker.fd, 1 << 16):
                    pass
            except OSError:
                pass
            os.close(worker.fd)
            os.waitpid(worker.pid, 0)
        sel.close()


def _worker_setup() -> None:
    """A corpus command's worker process: the processes share the cores (``facetraj_engine.threads``),
    and the parent logs the file warnings."""
    one_blas_thread()
    FILE_WARNINGS.quiet = True


def _run_one(fn: Callable[[Any], Any], item: Any) -> _Done:
    """``fn(item)`` in a worker: its result, or its facetraj error, and the file warnings it
    raised; a bug is raised as it is (``forked_map`` sends it to the parent)."""
    mark = FILE_WARNINGS.mark()
    try:
        with limit_frame_threads(1):    # one process per core already
            done = _Done(result=fn(item))
    except FacetrajError as exc:
        done = _Done(error=portable(exc))  # type: ignore[arg-type]
    done.warnings = FILE_WARNINGS.since(mark)
    return done


def fan_out(fn: Callable[[I], R], items: Sequence[I], workers: int = 1, *,
            skip: Skips | None = None, progress: Progress | None = None,
            describe: Callable[[I], str] = str) -> list[tuple[I, R]]:
    """``(item, fn(item))`` for every item, in order, computed in ``workers`` processes (forked;
    serially for 1, or where fork is unavailable). A :class:`~facetraj_engine.errors.FacetrajError` of an
    item stops the work (raised as it is), or with ``skip`` leaves the item out (recorded there).
    ``progress(fraction, describe(item))`` as the items are taken in order."""
    items = list(items)
    if skip is not None:
        skip.tried.update(items)
    workers = max(1, min(workers, len(items)))
    if workers > 1 and can_fork():
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
    """:func:`fan_out` in forked workers (:func:`forked_map`), the results taken in order."""
    import functools

    out: list[tuple[I, R]] = []
    waiting: dict[int, Any] = {}
    k = 0
    for i, done in forked_map(functools.partial(_run_one, fn), items, workers, _worker_setup):
        waiting[i] = done
        while k in waiting:
            done, item = waiting.pop(k), items[k]
            if progress:
                progress(k / len(items), describe(item))
            k += 1
            if isinstance(done, WorkerDied):
                done = _Done(error=FacetrajError(
                    f"a worker process stopped unexpectedly (out of memory, or a crash in a file "
                    f"reader) while working on {describe(item)}; run with --jobs 1 to see why"))
            FILE_WARNINGS.merge(done.warnings)
            if done.error is not None:
                if skip is None:
                    done.error.item = item
                    raise done.error
                skip.add(item, done.error)
                continue
            out.append((item, done.result))
    if progress:
        progress(1.0, "done")
    return out
