"""The compiled kernels built ahead of time: the numba kernels of ``compiled_lsf``,
``compiled_search`` and ``compiled_weights`` compiled once, at install, into a Python extension
(``numba.pycc``), so that a process uses them without importing numba (about 0.5 s of CPU and
140 MiB a process, which made a single file of a minute cheaper in numpy).

The extension holds the same functions compiled from the same source by the same compiler as
the just-in-time kernels, for this machine's processor; it is used only while it matches its
source: :func:`fingerprint` (the three kernel modules, this one, the constants they take from
``lsf`` and the processor) is compiled into it (``built_from``) and checked at load. A missing or
stale extension falls back to numba's just-in-time kernels (:mod:`engine.method.kernels`).

Built by ``python -m engine.method.aot`` (``make`` does it after installing) into this folder, or
into ``$FACETRAJ_KERNELS_DIR`` where it is looked for too (a read-only install).
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.machinery
import importlib.util
import logging
import os
import platform
import shutil
import sys
import tempfile
from pathlib import Path
from types import ModuleType

log = logging.getLogger(__name__)

#: the extension's module name (``PyInit__kernels_aot``)
MODULE = "_kernels_aot"
DIR_ENV = "FACETRAJ_KERNELS_DIR"
HERE = Path(__file__).resolve().parent

#: the exported kernels: module, numba signature (the arrays' layouts as the callers pass them)
EXPORTS = {
    "lsf_frames": ("compiled_lsf", "Tuple((f8[:,:], f8[:,:], b1[:]))"
                                   "(f8[::1], i8[::1], f8[::1], i8, f8[::1], f8[:,::1], f8, i8)"),
    "nearest_frames": ("compiled_search",
                       "i8[:,:](f8[:,::1], f4[:,::1], f4[:,::1], i8[::1], i8[::1], i8, i8)"),
    "top_context_scores": ("compiled_search", "Tuple((i8[:,:], f8[:,:]))"
                                              "(i8[:,::1], i8[:,::1], f8[:,::1], f8[:,:,::1], "
                                              "i8[::1], f8, i8)"),
    "weight_frames": ("compiled_weights", "Tuple((f8[:,:], i8[:], f8[:,:], f8[:,:], f8[:]))"
                                          "(f8[:,::1], i8[:,::1], f8[:,:], f8[:,:], f8, f8, i8)"),
}


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
    """A 60-bit digest of what the extension was compiled from: the kernels' sources, this
    module, the ``lsf`` constants they read, Python's and numba's ABI tags, the processor."""
    from . import lsf

    h = hashlib.sha256()
    for name in ("compiled_lsf", "compiled_search", "compiled_weights", "aot"):
        h.update((HERE / f"{name}.py").read_bytes())
    h.update(repr((lsf.ROOT_GRID, lsf.WHITE_NOISE_CORRECTION)).encode())
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
        log.debug("no prebuilt kernels in %s (python -m engine.method.aot builds them)", folder())
        return None
    try:
        spec = importlib.util.spec_from_file_location(MODULE, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        built_from = module.built_from()
    except Exception as exc:                   # a broken file: the just-in-time kernels run
        log.warning("prebuilt kernels %s unusable (%s); rebuild with python -m engine.method.aot",
                    path, exc)
        return None
    if built_from != fingerprint():
        log.warning("prebuilt kernels %s are stale (their source, or the processor, changed); "
                    "rebuild with python -m engine.method.aot", path)
        return None
    return module


def build(into: Path | None = None) -> Path:
    """Compile :data:`EXPORTS` (and ``built_from``, returning :func:`fingerprint`) into the
    extension in ``into`` (default :func:`folder`), for this processor; written beside and moved
    into place, so a failed build leaves the last one whole. Its path."""
    import importlib

    from numba.pycc import CC
    from numba.pycc import compiler as pycc_compiler

    into = Path(into) if into is not None else folder()
    into.mkdir(parents=True, exist_ok=True)
    stamp = fingerprint()
    with tempfile.TemporaryDirectory(dir=into, prefix=".aot-") as tmp:
        cc = CC(MODULE)
        cc.output_dir = tmp
        cc.target_cpu = "host"
        cc.verbose = False
        for name, (module, signature) in EXPORTS.items():
            kernel = getattr(importlib.import_module(f"{__package__}.{module}"), name)
            cc.export(name, signature)(kernel.py_func)
        cc.export("built_from", "i8()")(_constant(stamp))
        flags = pycc_compiler.Flags
        pycc_compiler.Flags = _releasing_the_gil()    # as the jit kernels' nogil=True: frame threads
        try:                                       # run side by side (pycc has no option for it)
            cc.compile()
        finally:
            pycc_compiler.Flags = flags
        built = next(Path(tmp).glob(f"{MODULE}*"))
        for old in into.glob(f"{MODULE}.*"):
            if old.suffix in (".so", ".pyd") and old.name != built.name:
                old.unlink()
        target = into / built.name
        shutil.move(str(built), str(target))
    return target


def _releasing_the_gil():
    from numba.core.compiler import Flags

    class ReleasingTheGil(Flags):
        """numba's compile flags with ``release_gil`` set: the exported functions' Python
        wrappers let go of the GIL while the kernel runs (``njit(nogil=True)``)."""

        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.release_gil = True

    return ReleasingTheGil


def _constant(value: int):
    def built_from():
        return value
    return built_from


def main(argv: list[str] | None = None) -> int:
    """``python -m engine.method.aot [--check] [--into DIR]``: build the extension, or say
    whether it is there and current (exit 0) or not (exit 1)."""
    parser = argparse.ArgumentParser(prog="python -m engine.method.aot", description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="only say whether it is current")
    parser.add_argument("--into", type=Path, help=f"the folder (default: ${DIR_ENV} or {HERE})")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    if args.into is not None:
        os.environ[DIR_ENV] = str(args.into)
    if args.check:
        ok = load() is not None
        log.info("prebuilt kernels in %s: %s", folder(), "current" if ok else "missing or stale")
        return 0 if ok else 1
    try:
        path = build()
    except Exception as exc:     # no compiler, no numba.pycc: the just-in-time kernels will run
        log.error("could not build the prebuilt kernels (%s: %s); numba's just-in-time kernels "
                  "will be used", type(exc).__name__, exc)
        return 1
    log.info("built %s", path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
