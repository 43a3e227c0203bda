"""The compiled kernels prebuilt at install (:mod:`facetraj_engine.method.aot` builds them): where the
extension is, what it must have been built from, and loading it without numba.

The extension is used only while it matches its source: :func:`fingerprint` (the kernel modules,
the ``lsf`` module whose constants they compile in, the builder, the processor) is compiled into
it (``built_from``) and checked at load. A missing, broken or stale extension gives ``None``
(logged), and :mod:`facetraj_engine.method.kernels` uses numba's just-in-time kernels.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import logging
import os
import platform
from pathlib import Path
from types import ModuleType

log = logging.getLogger(__name__)

#: what the extension is compiled from: the kernels, the module whose constants they read, the
#: builder (its signatures), this module
SOURCES = ("compiled_lsf", "compiled_search", "compiled_weights", "lsf", "aot", "prebuilt")
#: the extension's module name (``PyInit__kernels_aot``)
MODULE = "_kernels_aot"
DIR_ENV = "FACETRAJ_KERNELS_DIR"
HERE = Path(__file__).resolve().parent


def folder() -> Path:
    """Where the extension is built and looked for: ``$FACETRAJ_KERNELS_DIR``, else beside
    this module."""
    env = os.environ.get(DIR_ENV, "").strip()
    return Path(env) if env else HERE


def _processor() -> str:
    """What the machine code was compiled for: the processor's model and feature flags (Linux),
    else what ``platform`` says."""
    try:
        with open("/proc/cpuinfo") as fh:
            lines = []
            for line in fh:
                if not line.strip():
                    break                                   # the first processor is enough
                if line.startswith(("model name", "flags", "Features", "CPU part")):
                    lines.append(line.strip())
        if lines:
            return "\n".join(lines)
    except OSError:
        pass
    return f"{platform.machine()} {platform.processor()}"


def fingerprint() -> int:
    """A 60-bit digest of what the extension was compiled from: :data:`SOURCES`, Python's ABI
    tag, the processor."""
    h = hashlib.sha256()
    for name in SOURCES:
        h.update((HERE / f"{name}.py").read_bytes())
    h.update(importlib.machinery.EXTENSION_SUFFIXES[0].encode())
    h.update(_processor().encode())
    return int(h.hexdigest()[:15], 16)


def _path() -> Path | None:
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = folder() / f"{MODULE}{suffix}"
        if path.is_file():
            return path
    return None


def load() -> ModuleType | None:
    """The built extension when it is there and matches :func:`fingerprint`, else ``None``
    (logged: the just-in-time kernels are used)."""
    path = _path()
    if path is None:
        log.debug("no prebuilt kernels in %s (python -m facetraj_engine.method.aot builds them)", folder())
        return None
    try:
        spec = importlib.util.spec_from_file_location(MODULE, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        built_from = module.built_from()
    except Exception as exc:                   # a broken file: the just-in-time kernels run
        log.warning("prebuilt kernels %s unusable (%s); rebuild with python -m facetraj_engine.method.aot",
                    path, exc)
        return None
    if built_from != fingerprint():
        log.warning("prebuilt kernels %s are stale (their source, or the processor, changed); "
                    "rebuild with python -m facetraj_engine.method.aot", path)
        return None
    return module
