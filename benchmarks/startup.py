"""Cold-start and whole-corpus evaluation benchmarks (issue #15).

Cold start: ``facetraj --screenshot`` (the app on the default corpus with the cached model, as a
user's second start) timed as a whole process, from launch to exit after the first frame is
rendered and written; and ``import facetraj_app.main_window`` alone. Each is the median of several runs
in new processes (the first start, which may train and cache the model, is not counted).

Evaluation: ``facetraj_engine.evaluation.scores.evaluate`` over the whole default corpus (train and test,
phonetic and acoustic-only, both smoothings, as ``facetraj eval --acoustic`` runs it), serially
and with one worker process per core; the two results are checked equal.
"""

from __future__ import annotations

import logging
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .common import REPO, BenchContext, BenchRow, timed

log = logging.getLogger(__name__)

COLD_START_AIM_S = 3.0
RUNS = 5
SMOKE_RUNS = 1


def _process_seconds(argv: list[str], runs: int) -> list[float]:
    """Wall seconds of ``runs`` runs of ``argv``, each a new process, as a user's start: Python
    keeps the modules' compiled bytecode (``__pycache__``) from the first start, even where the
    environment says not to (``PYTHONDONTWRITEBYTECODE``, set on the build machines), which
    would compile every facetraj module again at every start."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    out = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(argv, cwd=REPO, check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, env=env)
        out.append(time.perf_counter() - t0)
    return out


def cold_start(ctx: BenchContext) -> list[BenchRow]:
    """Whole-process medians of ``facetraj --screenshot`` and of importing the main window."""
    runs = SMOKE_RUNS if ctx.smoke else RUNS
    corpus = str(ctx.corpus.root)
    with tempfile.TemporaryDirectory() as tmp:
        shot = [sys.executable, "-m", "facetraj", "-q", "gui", corpus, "--screenshot",
                str(Path(tmp) / "first.png")]
        _process_seconds(shot, 1)              # trains and caches the model, compiles the modules
        starts = _process_seconds(shot, runs)
    imports = _process_seconds([sys.executable, "-c", "import facetraj_app.main_window"], runs)
    med = statistics.median(starts)
    log.info("cold start: median %.2f s of %s", med, [round(s, 2) for s in starts])
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return [
        BenchRow("startup", "cold start to first frame (facetraj --screenshot, whole process)",
                 med, "s", aim=f"<= {COLD_START_AIM_S:g} s",
                 ok=None if ctx.smoke else med <= COLD_START_AIM_S,
                 note=f"median of {runs}; runs {min(starts):.2f}-{max(starts):.2f} s; "
                      f"cached model; load average {load:.1f}"),
        BenchRow("startup", "import facetraj_app.main_window (whole process)", statistics.median(imports),
                 "s", note=f"median of {runs}; runs {min(imports):.2f}-{max(imports):.2f} s"),
    ]


def evaluation(ctx: BenchContext) -> list[BenchRow]:
    """``evaluate()`` on the whole corpus, serially and in one process per core."""
    from facetraj_engine.config import SynthConfig
    from facetraj_engine.evaluation.scores import default_workers, evaluate

    configs = [SynthConfig(), SynthConfig(mode="acoustic")]
    workers = default_workers()

    def run(n: int):
        return evaluate(ctx.model, ctx.corpus, ("train", "test"), configs,
                        ("triangular", "spline"), workers=n)

    t1, serial = timed(lambda: run(1))
    tn, parallel = timed(lambda: run(workers))
    same = parallel.scores == serial.scores
    n_utt = len(ctx.corpus.info.train) + len(ctx.corpus.info.test)
    note = f"{n_utt} utterances, phonetic + acoustic-only, both smoothings"
    return [
        BenchRow("eval", "whole-corpus evaluation, 1 process", t1.wall, "s", note=note,
                 cpu=t1.cpu),
        BenchRow("eval", f"whole-corpus evaluation, {workers} processes", tn.wall, "s",
                 note=f"{t1.wall / tn.wall:.2f}x faster; scores equal to the serial run: {same}"),
    ]
