"""The compiled kernels built ahead of time: the numba kernels of ``compiled_lsf``,
``compiled_search`` and ``compiled_weights`` compiled once, at install, into a Python extension
(``numba.pycc``), so that a process uses them without importing numba (about 0.5 s of CPU and
140 MiB a process, which made a single file of a minute cheaper in numpy).

The extension holds the same functions compiled from the same source by the same compiler as
the just-in-time kernels, for this machine's processor; it is used only while it matches its
source: ``prebuilt.fingerprint`` is compiled into it (``built_from``) and checked when
:mod:`facetraj_engine.method.prebuilt` loads it. A missing or stale extension falls back to numba's
just-in-time kernels (:mod:`facetraj_engine.method.kernels`).

Built by ``python -m facetraj_engine.method.aot`` (``make`` does it after installing) into this folder, or
into ``$FACETRAJ_KERNELS_DIR`` where it is looked for too (a read-only install).
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import sys
import tempfile
from pathlib import Path

from .prebuilt import DIR_ENV, HERE, MODULE, fingerprint, folder, load

log = logging.getLogger(__name__)

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
                                          "(f8[:,::1], i8[:,::1], f8[:,::1], f8[:,::1], f8, f8, i8)"),
}


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
    """``python -m facetraj_engine.method.aot [--check] [--force] [--into DIR]``: build the extension
    unless it is there and current (``--force``: build anyway), or only say whether it is
    (``--check``: exit 0) or not (exit 1)."""
    parser = argparse.ArgumentParser(prog="python -m facetraj_engine.method.aot", description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="only say whether it is current")
    parser.add_argument("--force", action="store_true", help="build even when it is current")
    parser.add_argument("--into", type=Path, help=f"the folder (default: ${DIR_ENV} or {HERE})")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    if args.into is not None:
        os.environ[DIR_ENV] = str(args.into)
    current = load() is not None            # the fingerprint: the one rule for "stale"
    if args.check or (current and not args.force):
        log.info("prebuilt kernels in %s: %s", folder(), "current" if current else "missing or stale")
        return 0 if current else 1
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
