"""Which implementation runs the per-frame hot paths of synthesis: the compiled kernels
(``facetraj_engine.method.compiled_lsf``, ``compiled_search``, ``compiled_weights``) or the numpy
reference (``facetraj_engine.method.lsf``, ``facetraj_engine.method.lsf_index``, ``facetraj_engine.method.synthesis``).

The numpy functions are the reference: each compiled kernel computes the same formula, frame by
frame in one loop, and is tested equal to it to rounding (``tests/test_kernels.py``). The
kernels come two ways, the same source compiled by numba either way:

- prebuilt (:mod:`facetraj_engine.method.aot` builds them, :mod:`facetraj_engine.method.prebuilt` loads them):
  compiled at install into an extension that loads in about 2 ms without numba; used whenever
  it is built and current;
- just in time: numba imported when a kernel is first asked for, never by importing the engine
  (its import and first call: about 0.5 s of CPU and 140 MiB), so where they are not prebuilt
  neither ``facetraj --version`` nor the app's first frame pays for it, and the command line
  uses them only where they pay that back (:func:`choice_for`); work fanned out over processes
  loads them once before forking.

``$FACETRAJ_KERNELS`` (or :func:`use_kernels`) chooses: ``compiled`` (the default: prebuilt,
else just in time), ``jit`` (numba's just-in-time kernels even where prebuilt ones exist) or
``numpy`` (the reference); numba missing, or failing to import or compile, falls back to the
reference with a warning in the log.

numba keeps the just-in-time machine code (``cache=True``) beside the modules (``__pycache__``),
or where ``$NUMBA_CACHE_DIR`` says, or in the user cache folder when the install is read-only; the
first run after an install compiles (about 10 s), later ones load the cache; where nothing can be
written the kernels compile without a cache in every process (:func:`jit`).
"""

from __future__ import annotations

import contextlib
import functools
import logging
import os
import threading
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from types import ModuleType
from typing import TypeVar

from ..fanout import before_fork

log = logging.getLogger(__name__)

#: environment variable choosing the kernels: ``compiled`` (default), ``jit`` or ``numpy``
KERNELS_ENV = "FACETRAJ_KERNELS"
CHOICES = ("compiled", "jit", "numpy")

_choice: ContextVar[str | None] = ContextVar("kernel_choice", default=None)
_lock = threading.Lock()
#: held while :func:`warm_up` compiles or reads the cache (one warm-up at a time)
_warming = threading.Lock()
#: the loaded just-in-time kernel modules by name; ``None``: failed to load (the reference is used)
_loaded: dict[str, ModuleType | None] = {}
#: the prebuilt extension once looked for (``None``: not built, stale or broken)
_prebuilt: list[ModuleType | None] = []


def kernel_choice() -> str:
    """``compiled``, ``jit`` or ``numpy``: the choice of :func:`use_kernels` in this thread (and
    context), else ``$FACETRAJ_KERNELS``, else ``compiled``.

    >>> with use_kernels("numpy"):
    ...     kernel_choice()
    'numpy'
    """
    return _made() or "compiled"


def _made() -> str | None:
    """The choice made by :func:`use_kernels` in this context, else by ``$FACETRAJ_KERNELS``;
    ``None`` when neither made one."""
    choice = _choice.get() or os.environ.get(KERNELS_ENV, "").strip().lower()
    return choice if choice in CHOICES else None


@contextlib.contextmanager
def use_kernels(choice: str) -> Iterator[None]:
    """Synthesis in this thread (and its context) uses ``choice`` (``compiled``, ``jit`` or
    ``numpy``) until the end of the ``with`` block."""
    if choice not in CHOICES:
        raise ValueError(f"kernels must be one of {CHOICES}, got {choice!r}")
    token = _choice.set(choice)
    try:
        yield
    finally:
        _choice.reset(token)


#: seconds of speech from which the just-in-time kernels save a new process more than loading
#: them costs it (numba's import and cache read: about 0.5 s of CPU and 140 MiB). On 100 files of
#: 3-5 s through ``facetraj synth`` they saved about 1.5 ms of CPU a second of speech in the
#: phonetic mode and 3 ms in the modes that search the LSF index (benchmarks/profile_notes.md)
PAYS_OFF_S = {"phonetic": 300.0, "acoustic": 150.0, "robust": 150.0}


def choice_for(seconds: float, mode: str) -> str:
    """The kernels for a process that synthesizes ``seconds`` of speech in ``mode`` and exits
    (the command line; for work split between processes, the seconds of one): ``compiled``
    when they are prebuilt or loaded already or pay for their loading (:data:`PAYS_OFF_S`), else
    ``numpy``; a choice made by :func:`use_kernels` or ``$FACETRAJ_KERNELS`` stands.

    >>> with use_kernels("compiled"):
    ...     choice_for(1.0, "phonetic")
    'compiled'
    """
    if _made() is None and seconds >= PAYS_OFF_S.get(mode, 150.0):
        return "compiled"
    return ready_choice()


def ready_choice() -> str:
    """The kernels for work that must not wait for numba's import or compiling (a live stream,
    fed as the audio comes): a choice made by :func:`use_kernels` or ``$FACETRAJ_KERNELS``
    stands, else ``compiled`` when they are prebuilt or once :func:`loaded`, else ``numpy``.

    >>> with use_kernels("numpy"):
    ...     ready_choice()
    'numpy'
    """
    return _made() or ("compiled" if loaded() else "numpy")


F = TypeVar("F", bound=Callable)


def never_waiting(method: F) -> F:
    """``method`` (a stream's ``feed`` or ``flush``) runs with :func:`ready_choice`: the numpy
    reference until the compiled kernels are loaded (by :func:`warm_up`, in the background),
    never a block held up for half a second, or ten on the first run after an install."""
    @functools.wraps(method)
    def run(*args, **kwargs):
        with use_kernels(ready_choice()):
            return method(*args, **kwargs)

    return run  # type: ignore[return-value]


def jit(fn=None, **flags):
    """``numba.njit`` as the kernel modules compile: ``cache=True`` (the machine code kept for
    the next process), ``nogil=True`` (frame threads run side by side), ``error_model="numpy"``
    (a division by zero gives inf or NaN, as in numpy), and ``flags``; without the cache when
    numba finds nowhere writable to keep it (a read-only install without a user cache folder:
    the kernels are compiled again in every process)."""
    if fn is None:
        return lambda f: jit(f, **flags)
    from numba import njit

    flags = {"cache": True, "nogil": True, "error_model": "numpy", **flags}
    try:
        return njit(**flags)(fn)
    except RuntimeError:                       # "cannot cache function ...: no locator available"
        return njit(**{**flags, "cache": False})(fn)


def _load(name: str) -> ModuleType | None:
    """``facetraj_engine.method.<name>`` imported (numba with it) once; ``None`` when it cannot be."""
    with _lock:
        if name not in _loaded:
            try:
                import importlib

                _loaded[name] = importlib.import_module(f"{__package__}.{name}")
            except Exception as exc:            # numba missing or broken: the reference runs
                log.warning("compiled kernels unavailable (%s: %s); using numpy", name, exc)
                _loaded[name] = None
        return _loaded[name]


def prebuilt() -> ModuleType | None:
    """The prebuilt kernels (:func:`facetraj_engine.method.prebuilt.load`, looked for once), or ``None``."""
    with _lock:
        if not _prebuilt:
            from .prebuilt import load

            _prebuilt.append(load())
        return _prebuilt[0]


def compiled(name: str) -> ModuleType | None:
    """What holds the compiled kernels of module ``name`` (``compiled_lsf``, ``compiled_search``,
    ``compiled_weights``) when they are chosen and load: the prebuilt extension (every kernel,
    same names) or the just-in-time module; else ``None`` (the caller runs the numpy reference)."""
    choice = kernel_choice()
    if choice == "numpy":
        return None
    if choice == "compiled" and prebuilt() is not None:
        return prebuilt()
    return _load(name)


def loaded() -> bool:
    """Whether the compiled kernels are ready to run without a wait: prebuilt, or numba's
    imported with nothing left to load."""
    if prebuilt() is not None and _made() != "jit":
        return True
    return bool(_loaded) and all(m is not None for m in _loaded.values())


def warm_up() -> bool:
    """Load and run every just-in-time kernel once on a tiny input (numba's import, and its
    cache read or compilation), e.g. in a background thread before the first synthesis, unless
    prebuilt ones are there (and not ``jit`` chosen); whether the compiled kernels are usable."""
    if _made() != "jit" and prebuilt() is not None:
        return True
    with _warming:
        ok = True
        for name in ("compiled_lsf", "compiled_search", "compiled_weights"):
            module = _load(name)
            if module is None:
                ok = False
                continue
            try:
                module.warm_up()
            except Exception as exc:                # a compile error: use the reference from now on
                log.warning("compiled kernels failed (%s: %s); using numpy", name, exc)
                with _lock:
                    _loaded[name] = None
                ok = False
        return ok


def _before_fork() -> None:
    """Worker processes about to fork (``facetraj_engine.fanout``): the compiled kernels loaded here
    once, when chosen, rather than in every worker (half a second of CPU each); a warm-up under
    way in another thread (the app's, in the background) finishes first either way, so that no
    child inherits numba half-way through compiling (its locks held by a thread it has not)."""
    if kernel_choice() != "numpy":
        warm_up()
    else:
        with _warming:
            pass


before_fork(_before_fork)
