"""Work fanned out over processes, one item (an utterance, a recording, a sentence to build) at
a time: the one fan-out of the project (the corpus commands, ``facetraj synth``'s batch, the
corpus builder).

:func:`fan_out` runs ``fn(item)`` for every item, serially or in worker processes (forked, so
that the model and the corpus are inherited, not pickled), and yields ``(item, result)`` as the
caller takes them: in the items' order (``ordered``, the default: the same sums in the same
order whatever the number of workers) or as they finish. It is a stream: the workers run at most
``ahead`` items beyond the last one the caller has taken, so that what waits to be taken stays
bounded whatever the number of items (the corpus is read, analysed and let go one item at a
time). Either way a bad file gives the same outcome:

- by default, the first item in order whose file is bad stops the work with its own
  :class:`~facetraj_engine.errors.FacetrajError` (``file: problem``; its ``item`` attribute names the
  item), as the serial run does; the items still waiting are not started;
- with a :class:`Skips` (the commands' ``--skip-bad``), the item is left out, its message kept,
  and the work goes on; the command ends with :meth:`Skips.summary` ("1 of 3 utterances skipped:
  ...") and exit status 3 (its result is incomplete).

A worker's error comes back as it was raised (every facetraj error pickles, and anything that
does not is replaced by a plain copy before it leaves the worker). A worker that dies (killed,
out of memory, a crash in a file reader) fails the item it was working on, named, and only that
item: another worker takes its place for the rest; the failure is a
:class:`~facetraj_engine.errors.FacetrajError` like a bad file's (stops the work, or with a
:class:`Skips` is recorded there), never a traceback. A bug in ``fn`` (any other exception) is
raised here as it is. The warnings about files a worker logs (``facetraj_engine.errors.warn_file``) are
sent to the parent, which logs each once.
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

#: items a worker may run ahead of the last one taken, per worker (:func:`fan_out`'s ``ahead``)
AHEAD_PER_WORKER = 4


@dataclass
class Skips:
    """Items left out because their files were bad (``--skip-bad``): item -> message; and every
    item tried, for the count. One object may follow several passes over the same items (the
    report trains, then evaluates three times): each item counts once. ``verb`` says what
    happened to them (``facetraj synth``'s batch: ``failed``).

    >>> s = Skips("utterances")
    >>> s.tried.update(["a", "b", "c"]); s.add("b", InputError("b.c3d", "not a C3D file"))
    >>> s.summary()
    '1 of 3 utterances skipped: b.c3d: not a C3D file'
    """

    noun: str = "utterances"
    bad: dict[Any, str] = field(default_factory=dict)
    tried: set = field(default_factory=set)
    verb: str = "skipped"

    def add(self, item: Any, exc: BaseException) -> None:
        if item not in self.bad:
            self.bad[item] = str(exc)
            log.warning("%s: %s", self.verb, exc)

    def __bool__(self) -> bool:
        """True when something was skipped."""
        return bool(self.bad)

    def summary(self) -> str:
        """``"k of n <noun> skipped: <message>"`` (one message per line when several)."""
        head = f"{len(self.bad)} of {len(self.tried | set(self.bad))} {self.noun} {self.verb}"
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


def can_fork() -> bool:
    """Whether :func:`fan_out` can run workers here (``fork`` exists: not on Windows); where it
    cannot, the work runs in this process."""
    return hasattr(os, "fork")


# --------------------------------------------------------------------------- the one entry
def fan_out(fn: Callable[[I], R], items: Sequence[I], workers: int = 1, *,
            skip: Skips | None = None, progress: Progress | None = None,
            describe: Callable[[I], str] = str, ordered: bool = True,
            setup: Callable[[], None] | None = None, ahead: int | None = None
            ) -> Iterator[tuple[I, R]]:
    """``(item, fn(item))`` for every item, computed in ``workers`` processes (forked; serially
    for 1, or where fork is unavailable), taken in order (``ordered``) or as they finish.

    A :class:`~facetraj_engine.errors.FacetrajError` of an item, or its worker's death, stops the work
    (raised, ``item`` set), or with ``skip`` leaves the item out (recorded there).
    ``progress(fraction, describe(item))`` as the items are taken, ``(1.0, "done")`` at the end.
    ``setup()`` is called once in every process that runs items (each worker; this one when
    serial). The workers run at most ``ahead`` items (default :data:`AHEAD_PER_WORKER` per
    worker) beyond the last one taken. A generator: nothing runs until the first is asked for,
    and closing it early starts no further item."""
    items = list(items)
    if skip is not None:
        skip.tried.update(items)
    workers = max(1, min(workers, len(items)))
    if workers > 1 and can_fork():
        runs = _in_processes(fn, items, workers, ordered, setup,
                             ahead or AHEAD_PER_WORKER * workers)
    else:
        runs = _here(fn, items, setup)
    try:
        for k, (i, done) in enumerate(runs):
            item = items[i]
            if progress:
                progress(k / len(items), describe(item))
            if isinstance(done, _Died):
                done = _Done(error=FacetrajError(
                    f"a worker process stopped unexpectedly ({done.how()}: out of memory, or a "
                    f"crash in a file reader) while working on {describe(item)}; run with "
                    f"--jobs 1 to see why"))
            FILE_WARNINGS.merge(done.warnings)
            if done.error is not None:
                if skip is None:
                    done.error.item = item          # what --skip-bad would have left out
                    raise done.error
                skip.add(item, done.error)
                continue
            yield item, done.result
    finally:
        runs.close()                                # the workers stopped and reaped, now
    if progress:
        progress(1.0, "done")


def _here(fn: Callable[[Any], Any], items: list, setup: Callable[[], None] | None
          ) -> Iterator[tuple[int, _Done]]:
    """The items run in this process, one at a time as they are asked for; their file warnings
    logged as they are raised."""
    if setup is not None:
        setup()
    for i, item in enumerate(items):
        try:
            yield i, _Done(result=fn(item))
        except FacetrajError as exc:
            yield i, _Done(error=exc)


# --------------------------------------------------------------------------- worker processes
# Forked once, they take their items themselves: each takes the next item's index from a counter
# they share, runs ``fn`` on it and sends the result back through its own pipe; the parent only
# reads. With a pool that hands items out itself (``concurrent.futures``) a worker waits for the
# parent's thread between items, and where the workers fill the cores that thread waits for a
# core (benchmarks/profile_notes.md). A semaphore of ``ahead`` slots bounds the items taken and
# not yet handed to the caller: a worker takes a slot before an item, the parent gives it back
# when the caller has taken that item.
_LENGTH = struct.Struct("<Q")


@dataclass
class _Died:
    """The result of an item whose worker stopped while working on it: ``status`` is what
    ``os.waitstatus_to_exitcode`` gave (a negative signal number when killed)."""

    status: int

    def how(self) -> str:
        return f"killed by signal {-self.status}" if self.status < 0 else \
            f"exit status {self.status}"


class _Raised:
    """What a worker sends when ``fn`` raised a bug: the exception (made picklable), re-raised
    in the parent."""

    def __init__(self, exc: BaseException):
        self.exc = exc


def _send(fd: int, message: Any) -> None:
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    view = memoryview(_LENGTH.pack(len(data)) + data)
    while view:
        view = view[os.write(fd, view):]


def _run_one(fn: Callable[[Any], Any], item: Any) -> _Done | _Raised:
    """``fn(item)`` in a worker: its result, or its facetraj error, and the file warnings it
    raised; a bug is sent as it is (raised in the parent), after its traceback."""
    mark = FILE_WARNINGS.mark()
    try:
        with limit_frame_threads(1):    # one process per core already
            done = _Done(result=fn(item))
    except FacetrajError as exc:
        done = _Done(error=portable(exc))  # type: ignore[arg-type]
    except BaseException as exc:                   # a bug in fn: the parent raises it
        traceback.print_exc()                      # its traceback, where it happened
        return _Raised(portable(exc))
    done.warnings = FILE_WARNINGS.since(mark)
    return done


def _child(fn: Callable[[Any], Any], items: Sequence[Any], shared: tuple, fd: int,
           setup: Callable[[], None] | None) -> None:
    """A worker's life: set up, then items taken from the shared counter (a slot first) until
    none is left."""
    counter, slots = shared
    signal.signal(signal.SIGINT, signal.SIG_IGN)       # the parent stops the work
    code = 0
    try:
        one_blas_thread()                              # the processes share the cores
        FILE_WARNINGS.quiet = True                     # the parent logs them
        if setup is not None:
            setup()
        while True:
            slots.acquire()
            with counter.get_lock():
                i = counter.value
                if i >= len(items):
                    break
                counter.value = i + 1
            _send(fd, ("take", i))
            done = _run_one(fn, items[i])
            _send(fd, ("done", i, done))
            if isinstance(done, _Raised):
                code = 1
                break
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
        self.done = 0

    def messages(self, data: bytes) -> Iterator[tuple]:
        self.buffer += data
        while len(self.buffer) >= _LENGTH.size:
            (size,) = _LENGTH.unpack_from(self.buffer)
            if len(self.buffer) < _LENGTH.size + size:
                return
            message = pickle.loads(bytes(self.buffer[_LENGTH.size:_LENGTH.size + size]))
            del self.buffer[:_LENGTH.size + size]
            yield message


class _Processes:
    """The forked workers of one :func:`fan_out`, read by the parent: :meth:`finished` gives
    ``(index, _Done | _Died)`` as the workers finish items; :meth:`taken` gives a slot back."""

    def __init__(self, fn: Callable[[Any], Any], items: Sequence[Any], workers: int,
                 setup: Callable[[], None] | None, ahead: int):
        import multiprocessing as mp

        ctx = mp.get_context("fork")
        self.fn, self.items, self.setup, self.workers = fn, items, setup, workers
        self.shared = (ctx.Value("q", 0), ctx.Semaphore(max(ahead, workers)))
        self.running: dict[int, _Worker] = {}
        self.sel = selectors.DefaultSelector()

    def spawn(self) -> None:
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:                                   # the child: never returns
            os.close(r)
            for other in self.running.values():
                os.close(other.fd)
            _child(self.fn, self.items, self.shared, w, self.setup)
        os.close(w)
        self.running[r] = _Worker(pid, r)
        self.sel.register(r, selectors.EVENT_READ)

    def taken(self) -> None:
        """The caller has taken an item: a worker may start another."""
        self.shared[1].release()

    def finished(self) -> Iterator[tuple[int, Any]]:
        for _ in range(self.workers):
            self.spawn()
        while self.running:
            for key, _ in self.sel.select():
                worker = self.running[key.fd]
                data = os.read(key.fd, 1 << 16)
                for message in worker.messages(data):
                    if message[0] == "take":
                        worker.working = message[1]
                        continue
                    _, i, done = message
                    worker.working, worker.done = None, worker.done + 1
                    if isinstance(done, _Raised):
                        raise done.exc
                    yield i, done
                if not data:                           # end of pipe: the worker is gone
                    yield from self._gone(key.fd, worker)

    def _gone(self, fd: int, worker: _Worker) -> Iterator[tuple[int, _Died]]:
        """A worker's pipe closed: reaped; the item it was on failed, another in its place."""
        self.sel.unregister(fd)
        os.close(fd)
        del self.running[fd]
        _, status = os.waitpid(worker.pid, 0)
        code = os.waitstatus_to_exitcode(status)
        if code != 0 and worker.working is None and not worker.done:    # in its set-up
            raise FacetrajError(f"a worker process stopped as it was set up "
                                f"({_Died(code).how()}); run with --jobs 1 to see why")
        if code != 0 and self.shared[0].value < len(self.items):
            self.spawn()
        if worker.working is not None:
            yield worker.working, _Died(code)

    def close(self) -> None:
        """Take no more items, let the ones in work finish, reap every worker."""
        counter, slots = self.shared
        with counter.get_lock():
            counter.value = len(self.items)
        for _ in range(len(self.running)):
            slots.release()                            # a worker waiting for a slot: it stops
        for worker in self.running.values():
            try:
                while os.read(worker.fd, 1 << 16):
                    pass
            except OSError:
                pass
            os.close(worker.fd)
            os.waitpid(worker.pid, 0)
        self.running.clear()
        self.sel.close()


def _in_processes(fn: Callable[[Any], Any], items: list, workers: int, ordered: bool,
                  setup: Callable[[], None] | None, ahead: int
                  ) -> Iterator[tuple[int, _Done | _Died]]:
    """The items run in ``workers`` forked processes; ``(index, outcome)`` in order, or as they
    finish; a slot given back as each is handed on."""
    procs = _Processes(fn, items, workers, setup, ahead)
    waiting: dict[int, Any] = {}
    k = 0
    try:
        for i, done in procs.finished():
            if not ordered:
                yield i, done
                procs.taken()
                k += 1
                continue
            waiting[i] = done
            while k in waiting:
                yield k, waiting.pop(k)
                procs.taken()
                k += 1
        if k < len(items):
            raise RuntimeError(f"{len(items) - k} items were neither done nor reported")
    finally:
        procs.close()
