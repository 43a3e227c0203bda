"""The whole command (issue 28): ``facetraj synth`` on 61 s of speech, and a batch of 100 files.

One file, two measures. ``main()``: each run is a new process that imports the command
(``facetraj.cli`` and the modules every synthesis imports, ``facetraj.batch.import_synthesis``:
the start-up), then runs ``main(argv)`` once and reports both times; the real-time factor is
61 s over the run (reading the model, the audio and its labels, synthesis, writing the output),
start-up reported apart, as is ``facetraj --version`` (the command's cold start). The whole
process (issue 48): ``python -m facetraj synth ...`` timed from outside, start-up and exit
included, as a user times it, for each output format. Phonetic: the labels in a TextGrid beside
the audio (hand-checked: the paper's mode); acoustic-only: ``--mode acoustic``. The median of
the runs is reported. The text writer (issue 48): ``write_trajectories`` of the 61 s face to
``.tsv``, and to ``.csv`` with two label columns (the app's export: phone and word), in this
process, against ``numpy.savetxt`` of the same numbers (the bytes it reproduces).

Batch: 100 files of 3-5 s of test speech, each with its TextGrid beside it, synthesized to
``.npz`` by ``facetraj synth MODEL DIR -o OUT -j N`` with 1 and with 2 workers (``--overwrite``:
every file every time), the whole process timed; its peak memory is the largest process's
(the command's own peak resident set, ``VmHWM``, and its largest worker's, ``getrusage``; Linux).
"""

from __future__ import annotations

import json
import logging
import os
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

AIMS = {"phonetic": 500.0, "acoustic": 300.0}      # issue 35: main(), x real time, to .npz
#: issue 48: the whole process, seconds, 61 s of speech
WHOLE_AIMS = {("phonetic", "tsv"): 0.30, ("acoustic", "tsv"): 0.35}
FORMATS = ("npz", "tsv", "csv", "c3d")
SECONDS = 61.0
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


def _command(argv: Sequence[str]) -> float:
    """Wall seconds of ``python -m facetraj ARGV``, timed from outside (start-up and exit in)."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "facetraj", *argv], cwd=REPO, capture_output=True,
                         text=True)
    seconds = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"facetraj {' '.join(argv)} exited {out.returncode}: {out.stderr}")
    return seconds


def _synth_argv(model: Path, wav: Path, out: Path, mode: str) -> list[str]:
    return ["-q", "synth", str(model), str(wav), "-o", str(out), "--overwrite",
            *(["--mode", "acoustic"] if mode == "acoustic" else [])]


def one_file(ctx: BenchContext, seconds: float | None = None) -> list[BenchRow]:
    """``facetraj synth`` on ``seconds`` (61; 2 in smoke mode) of speech, phonetic and
    acoustic-only: ``main()`` to ``.npz`` (start-up apart), the whole process to each format,
    the text writer; the command's cold start."""
    seconds = seconds or (2.0 if ctx.smoke else SECONDS)
    runs = SMOKE_RUNS if ctx.smoke else RUNS
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        model = _model_file(ctx, folder)
        audio, rate, phones = concatenate_input(ctx.test_utts or ctx.train_utts, seconds)
        wav = _write_input(folder, "speech", audio, rate, phones)
        rows = [_main_row(ctx, mode, _synth_argv(model, wav, folder / "out.npz", mode), seconds,
                          runs) for mode in AIMS]
        for mode in AIMS:
            rows += [_whole_row(ctx, mode, fmt, _synth_argv(model, wav, folder / f"out.{fmt}", mode),
                                seconds, runs) for fmt in FORMATS]
        rows += writer_rows(ctx, audio, rate, phones, runs)
        rows.append(_cold_start(runs))
        t0 = time.perf_counter()
        from facetraj_engine.method.model import Model

        Model.load(model)
        rows.append(BenchRow("cli", "model file load (Model.load, part of each run above)",
                             (time.perf_counter() - t0) * 1000, "ms"))
    return rows


def _main_row(ctx: BenchContext, mode: str, argv: list[str], seconds: float, runs: int
              ) -> BenchRow:
    """``main()`` of the command to ``.npz``, x real time (issue 35's figure)."""
    _drive(argv)                                             # warm-up: the page cache
    reports = [_drive(argv) for _ in range(runs)]
    run = statistics.median(r["run"] for r in reports)
    start = statistics.median(r["startup"] for r in reports)
    return BenchRow(
        "cli", f"facetraj synth, {mode}, {seconds:g} s to .npz: main()", seconds / run, "x RT",
        aim=f">= {AIMS[mode]:.0f}x", ok=None if ctx.smoke else seconds / run >= AIMS[mode],
        note=f"{run * 1000:.0f} ms (runs {min(r['run'] for r in reports) * 1000:.0f}-"
             f"{max(r['run'] for r in reports) * 1000:.0f}), start-up excluded: "
             f"{start * 1000:.0f} ms of imports; median of {runs}")


def _whole_row(ctx: BenchContext, mode: str, fmt: str, argv: list[str], seconds: float,
               runs: int) -> BenchRow:
    """The whole ``facetraj synth`` process to ``fmt``, timed from outside (issue 48)."""
    _command(argv)                                           # warm-up: the page cache
    times = [_command(argv) for _ in range(runs)]
    whole = statistics.median(times)
    aim = WHOLE_AIMS.get((mode, fmt))
    return BenchRow(
        "cli", f"facetraj synth, {mode}, {seconds:g} s to .{fmt}: the whole process", whole, "s",
        aim=f"<= {aim:g} s" if aim else "", ok=None if ctx.smoke or not aim else whole <= aim,
        note=f"{seconds / whole:.0f}x real time; runs {min(times):.3f}-{max(times):.3f} s; "
             f"median of {runs}; load average {os.getloadavg()[0]:.1f}")


def writer_rows(ctx: BenchContext, audio: np.ndarray, rate: int,
                phones: Sequence[PhoneSegment], runs: int) -> list[BenchRow]:
    """The text writer on the face of ``audio``: to ``.tsv``, and to ``.csv`` with the phone and
    word columns (the app's export), in this process (fastest of ``runs``), against
    ``numpy.savetxt`` of the same numbers (the bytes it reproduces)."""
    import io

    from facetraj_engine.analysis.apertures import frame_labels
    from facetraj_engine.config import SynthConfig
    from facetraj_engine.io.export import write_trajectories
    from facetraj_engine.method.pipeline import synthesize

    model = ctx.model
    res = synthesize(model, audio, rate, phones, SynthConfig(mode="phonetic"))
    m, n = res.markers, len(res.markers)
    column = frame_labels(phones, res.times)        # the app's export: the phone and the word
    labels = {"phone": column, "word": column}
    table = np.column_stack([res.times, m.reshape(n, -1)])
    fmt = ["%.6f"] + ["%.4f"] * (table.shape[1] - 1)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for suffix, extra, what in ((".tsv", None, ""), (".csv", labels, ", two label columns")):
            path = Path(tmp) / f"face{suffix}"
            t = _fastest(lambda path=path, extra=extra: write_trajectories(
                path, m, model.marker_rate, model.marker_names, labels=extra), runs)
            ref = _fastest(lambda: np.savetxt(io.BytesIO(), table, fmt=fmt, delimiter=","), runs)
            rows.append(BenchRow(
                "cli", f"text writer: {n} frames x {m.shape[1]} markers to {suffix}{what}", t * 1000,
                "ms", note=f"{path.stat().st_size / 1e6:.1f} MB; numpy.savetxt of the numbers "
                           f"{ref * 1000:.0f} ms ({ref / t:.0f}x); fastest of {runs}"))
    return rows


def _fastest(fn, runs: int) -> float:
    best = float("inf")
    for _ in range(max(runs, 3)):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _cold_start(runs: int) -> BenchRow:
    versions = []
    for _ in range(runs + 1):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "facetraj", "--version"], cwd=REPO, check=True,
                       capture_output=True)
        versions.append(time.perf_counter() - t0)
    versions = versions[1:]
    return BenchRow("cli", "cold start: facetraj --version (whole process)",
                    statistics.median(versions), "s",
                    note=f"median of {runs}; runs {min(versions):.2f}-{max(versions):.2f} s")


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
