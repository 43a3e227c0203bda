"""The whole command (issue 28): ``facetraj synth`` on 60 s of speech, and a batch of 100 files.

One file: each run is a new process that imports the command (``facetraj.cli`` and the modules
every synthesis imports, ``facetraj.batch.import_synthesis``: the start-up), then runs
``main(argv)`` once and reports both times; the
real-time factor is 60 s over the run (reading the model, the audio and its labels, synthesis,
writing the output), start-up reported apart, as is ``facetraj --version`` (the command's cold
start). Phonetic: the labels in a TextGrid beside the audio (hand-checked: the paper's mode);
acoustic-only: ``--mode acoustic``. The median of the runs is reported.

Batch: 100 files of 3-5 s of test speech, each with its TextGrid beside it, synthesized to
``.npz`` by ``facetraj synth MODEL DIR -o OUT -j N`` with 1 and with 2 workers (``--overwrite``:
every file every time), the whole process timed; its peak memory is the largest process's
(the command's own peak resident set, ``VmHWM``, and its largest worker's, ``getrusage``; Linux).
"""

from __future__ import annotations

import json
import logging
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from facetraj_engine.data import PhoneSegment
from facetraj_engine.io.audio import write_audio
from facetraj_engine.io.labelfiles import write_textgrid

from .common import REPO, BenchContext, BenchRow, concatenate_input

log = logging.getLogger(__name__)

AIMS = {"phonetic": 1000.0, "acoustic": 300.0}     # issue 28, as the synthesis benchmark's
BATCH_AIM = 1.6
RUNS, SMOKE_RUNS = 5, 1
BATCH_FILES, SMOKE_BATCH_FILES = 100, 6

#: run in a new process: the command's start-up (imports), then ``main(argv)`` once
_DRIVER = """
import json, resource, sys, time
t0 = time.perf_counter()
import facetraj.cli, facetraj.batch
facetraj.batch.import_synthesis()
t1 = time.perf_counter()
code = facetraj.cli.main(sys.argv[1:])
t2 = time.perf_counter()
own = next(int(ln.split()[1]) for ln in open("/proc/self/status") if ln.startswith("VmHWM:"))
workers = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
print(json.dumps({"startup": t1 - t0, "run": t2 - t1, "code": code, "rss_kib": max(own, workers)}))
"""


def _drive(argv: Sequence[str]) -> dict:
    """The driver in a new process; its report and the whole process's wall seconds."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _DRIVER, *argv], cwd=REPO, check=True,
                         capture_output=True, text=True)
    report = json.loads(out.stdout.strip().splitlines()[-1])
    report["process"] = time.perf_counter() - t0
    if report["code"] != 0:
        raise RuntimeError(f"facetraj {' '.join(argv)} exited {report['code']}: {out.stderr}")
    return report


def _write_input(folder: Path, name: str, audio: np.ndarray, rate: int,
                 phones: Sequence[PhoneSegment]) -> Path:
    """``name.wav`` and its TextGrid beside it (times rounded as a TextGrid keeps them)."""
    segs: list[PhoneSegment] = []
    for p in phones:
        start = max(round(p.start, 4), segs[-1].end if segs else 0.0)
        segs.append(PhoneSegment(start, round(p.end, 4), p.label))
    wav = folder / f"{name}.wav"
    write_audio(wav, audio, rate)
    write_textgrid(folder / f"{name}.TextGrid", {"phones": segs}, len(audio) / rate)
    return wav


def _model_file(ctx: BenchContext, folder: Path) -> Path:
    return ctx.model.save(folder / "model.npz")


def one_file(ctx: BenchContext, seconds: float | None = None) -> list[BenchRow]:
    """``facetraj synth`` on ``seconds`` (60; 2 in smoke mode) of speech, phonetic and
    acoustic-only, to ``.npz`` (and phonetic to ``.tsv`` and ``.c3d``); start-up apart."""
    seconds = seconds or (2.0 if ctx.smoke else 60.0)
    runs = SMOKE_RUNS if ctx.smoke else RUNS
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        model = _model_file(ctx, folder)
        audio, rate, phones = concatenate_input(ctx.test_utts or ctx.train_utts, seconds)
        wav = _write_input(folder, "speech", audio, rate, phones)
        cases = [("phonetic", "npz", []), ("acoustic", "npz", ["--mode", "acoustic"]),
                 ("phonetic", "tsv", []), ("phonetic", "c3d", [])]
        for mode, fmt, extra in cases:
            argv = ["-q", "synth", str(model), str(wav), "-o", str(folder / f"out.{fmt}"),
                    "--overwrite", *extra]
            _drive(argv)                                     # warm-up: the page cache
            reports = [_drive(argv) for _ in range(runs)]
            run = statistics.median(r["run"] for r in reports)
            start = statistics.median(r["startup"] for r in reports)
            whole = statistics.median(r["process"] for r in reports)
            main_row = fmt == "npz"
            rows.append(BenchRow(
                "cli", f"facetraj synth, {mode}, {seconds:g} s to .{fmt}", seconds / run, "x RT",
                aim=f">= {AIMS[mode]:.0f}x" if main_row else "",
                ok=None if ctx.smoke or not main_row else seconds / run >= AIMS[mode],
                note=f"{run * 1000:.0f} ms (runs {min(r['run'] for r in reports) * 1000:.0f}-"
                     f"{max(r['run'] for r in reports) * 1000:.0f}), start-up excluded: "
                     f"{start * 1000:.0f} ms of imports, {whole:.2f} s the whole process; "
                     f"median of {runs}"))
        versions = []
        for _ in range(runs + 1):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "facetraj", "--version"], cwd=REPO, check=True,
                           capture_output=True)
            versions.append(time.perf_counter() - t0)
        versions = versions[1:]
        rows.append(BenchRow("cli", "cold start: facetraj --version (whole process)",
                             statistics.median(versions), "s",
                             note=f"median of {runs}; runs {min(versions):.2f}-"
                                  f"{max(versions):.2f} s"))
        t0 = time.perf_counter()
        from facetraj_engine.method.model import Model

        Model.load(model)
        rows.append(BenchRow("cli", "model file load (Model.load, part of each run above)",
                             (time.perf_counter() - t0) * 1000, "ms"))
    return rows


def _batch_inputs(ctx: BenchContext, folder: Path, count: int) -> float:
    """``count`` recordings of 3-5 s (test speech joined, each starting at another utterance)
    with their TextGrids; their total seconds."""
    utts = ctx.test_utts or ctx.train_utts
    rng = np.random.default_rng(28)
    total = 0.0
    for k in range(count):
        seconds = float(rng.uniform(3.0, 5.0))
        start = k % len(utts)
        audio, rate, phones = concatenate_input(utts[start:] + utts[:start], seconds)
        _write_input(folder, f"r{k:03d}", audio, rate, phones)
        total += seconds
    return total


def batch(ctx: BenchContext) -> list[BenchRow]:
    """A batch of 100 files (6 in smoke mode) with 1 and 2 workers."""
    count = SMOKE_BATCH_FILES if ctx.smoke else BATCH_FILES
    rows, times = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        model = _model_file(ctx, folder)
        inputs = folder / "in"
        inputs.mkdir()
        total = _batch_inputs(ctx, inputs, count)
        for jobs in (1, 2, 1, 2):            # alternating: a drift in the machine's speed is shared
            argv = ["-q", "synth", str(model), str(inputs), "-o", str(folder / "out"),
                    "--format", "npz", "--overwrite", "-j", str(jobs)]
            times.setdefault(jobs, []).append(_drive(argv))
        for jobs, reports in times.items():
            best = min(reports, key=lambda r: r["process"])
            rows.append(BenchRow(
                "cli", f"batch of {count} files of 3-5 s, {jobs} worker{'s' * (jobs > 1)}",
                best["process"], "s",
                note=f"{total:.0f} s of speech, {total / best['process']:.0f}x real time; "
                     f"fastest of {len(reports)}, the whole process "
                     f"({best['startup']:.2f} s of start-up); peak memory of the largest "
                     f"process {best['rss_kib'] / 1024:.0f} MiB"))
        speedup = min(r["process"] for r in times[1]) / min(r["process"] for r in times[2])
        rows.append(BenchRow("cli", f"batch of {count} files: 2 workers against 1", speedup, "x",
                             aim=f">= {BATCH_AIM:g}x",
                             ok=None if ctx.smoke else speedup >= BATCH_AIM,
                             note="the model loaded once and shared by the forked workers"))
        rows.append(BenchRow("cli", f"batch of {count} files: peak memory, largest process",
                             max(r["rss_kib"] for rs in times.values() for r in rs) / 1024, "MiB",
                             note="peak resident set of the command (VmHWM) and of its workers (getrusage)"))
    return rows
