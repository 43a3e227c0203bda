"""Corpus scaling benchmark (issue 41): ``facetraj train`` and ``facetraj eval`` on the default
corpus repeated 1, 4 and 16 times (its files under new names as symbolic links, with a
``corpus.json`` listing them: 16 times is 2.8 hours of training speech).

Each size runs the real commands in one process (``-j 1``: judged) and with their default
(every core), each in a child process: its wall time, its
CPU time (user + system, the child and the workers it forked) and its peak resident memory (the
largest single process among them, as ``/usr/bin/time -v`` reports it: ``os.wait4``'s rusage,
taken by a small process that forks the command).
The machine is shared: every size is run ``repeats`` times, the sizes taking turns, and the
fastest run is kept, as the synthesis benchmark keeps the best of its runs (the other jobs only
ever add time; memory, which they do not move, as the largest). Then the growth exponents
``e`` of ``time ~ size^e`` (from the smallest to the largest size, and between the two largest),
the peak memory's growth per hour of training speech (a straight line through the sizes), and
both extrapolated to 10 hours of training speech.

The aims: at 16 times, training within 2 GB of peak memory and at most 16.5 times the single
corpus's time; the evaluation likewise.
"""

from __future__ import annotations

import json
import logging
import math
import os
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from facetraj_engine.io.corpus import Corpus

from .common import BenchContext, BenchRow, ram_gib

log = logging.getLogger(__name__)

FACTORS = (1, 4, 16)
SMOKE_FACTORS = (1, 2)
REPEATS = 3
SMOKE_REPEATS = 1
#: hours of training speech the figures are extrapolated to
HOURS = 10.0
MEMORY_AIM_MIB = 2048.0
TIME_AIM_RATIO = 16.5


def repeat_corpus(corpus: Corpus, dst: Path, times: int) -> Path:
    """``dst/corpus.json``: ``corpus`` repeated ``times`` times, every utterance's files linked
    under a new name for each copy after the first (``s001_r01``, ...), both splits repeated;
    ``dst`` returned."""
    dst.mkdir(parents=True, exist_ok=True)
    info = corpus.info

    def name(utt_id: str, k: int) -> str:
        return f"{utt_id}_r{k:02d}" if k else utt_id

    for utt_id in info.ids:
        for src in corpus.data_root.glob(f"{utt_id}.*"):
            for k in range(times):
                link = dst / f"{name(utt_id, k)}{src.suffix}"
                if not link.is_symlink():
                    link.symlink_to(src.resolve())
    obj = info.to_json()
    obj.update(data_dir="", train=[name(u, k) for k in range(times) for u in info.train],
               test=[name(u, k) for k in range(times) for u in info.test],
               name=f"{info.name} x{times}",
               description=f"{corpus.root.name} repeated {times} times (symbolic links), for "
                           f"the corpus scaling benchmark")
    (dst / "corpus.json").write_text(json.dumps(obj, indent=1) + "\n", encoding="utf-8")
    return dst


@dataclass
class Run:
    """One run of a command in a child process."""

    wall: float
    cpu: float
    peak_mib: float
    status: int


#: A small process that forks the command and reports what ``os.wait4`` says of it, run with
#: ``python -S`` (no site-packages: a few MB). Measured straight from this process, a child's
#: peak would read as this process's (Linux keeps the larger of the parent's pages it was forked
#: with and its own), as ``/usr/bin/time`` measures its child, not itself.
_MEASURE = """
import json, os, sys, time
t = time.perf_counter()
pid = os.fork()
if pid == 0:
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.execv(sys.argv[1], sys.argv[1:])
_, status, ru = os.wait4(pid, 0)
print(json.dumps([time.perf_counter() - t, ru.ru_utime + ru.ru_stime, ru.ru_maxrss,
                  os.waitstatus_to_exitcode(status)]))
"""


def run_command(argv: Sequence[str]) -> Run:
    """Run ``argv`` (its output thrown away) and measure it from outside: wall time, CPU time of
    the process and the workers it waited for, and the largest single process's peak resident
    memory (``os.wait4`` in a small process that forks it)."""
    done = subprocess.run([sys.executable, "-S", "-c", _MEASURE, *argv], capture_output=True,
                          text=True, check=False)
    wall, cpu, peak_kib, status = json.loads(done.stdout.strip().splitlines()[-1])
    if status != 0:
        log.warning("%s: exit status %d\n%s", " ".join(argv), status, done.stderr[-2000:])
    return Run(wall, cpu, peak_kib / 1024.0, status)


@dataclass
class Size:
    """One size of the corpus: its factor, hours of training speech, and the runs of each
    command."""

    factor: int
    train_hours: float
    root: Path
    runs: dict[str, list[Run]] = field(default_factory=lambda: {c: [] for c in COMMANDS})

    def wall(self, command: str) -> float:
        return min(r.wall for r in self.runs[command])

    def cpu(self, command: str) -> float:
        return min(r.cpu for r in self.runs[command])

    def peak(self, command: str) -> float:
        return max(r.peak_mib for r in self.runs[command])


def _facetraj(*args: str) -> list[str]:
    return [sys.executable, "-m", "facetraj.cli", "-q", *args]


#: the runs of each size: the commands in one process (judged: a job of the other users takes
#: a core from a 2-process run, and the long runs of the large sizes meet more of them, which
#: would decide the ratio), then with their default, every core
COMMANDS = ("train", "eval", "train, every core", "eval, every core")


def measure(sizes: Sequence[Size], repeats: int, workdir: Path) -> None:
    """Train and evaluate every size ``repeats`` times, in one process and on every core, the
    sizes taking turns (each evaluation with the model its size's training wrote)."""
    for r in range(repeats):
        for size in sizes:
            model = workdir / f"model-x{size.factor}.npz"
            train = _facetraj("train", str(size.root), "-o", str(model), "--overwrite")
            evaluate = _facetraj("eval", str(model), str(size.root))
            for command, argv in zip(COMMANDS, ([*train, "-j", "1"], [*evaluate, "-j", "1"],
                                                train, evaluate), strict=True):
                run = run_command(argv)
                size.runs[command].append(run)
                log.info("%s x%d (run %d): %.1f s, %.1f s CPU, %.0f MiB", command, size.factor,
                         r + 1, run.wall, run.cpu, run.peak_mib)


def exponent(sizes: Sequence[Size], command: str, lo: int = 0, hi: int = -1,
             cpu: bool = False) -> float:
    """``e`` of ``time ~ size^e`` between sizes ``lo`` and ``hi``."""
    a, b = sizes[lo], sizes[hi]
    ta, tb = (a.cpu(command), b.cpu(command)) if cpu else (a.wall(command), b.wall(command))
    return math.log(tb / ta) / math.log(b.factor / a.factor)


def memory_line(sizes: Sequence[Size], command: str) -> tuple[float, float]:
    """``(MiB at no speech, MiB per hour of training speech)``: the least-squares line of the
    peak memory against the hours of training speech."""
    hours = np.array([s.train_hours for s in sizes])
    peaks = np.array([s.peak(command) for s in sizes])
    slope, intercept = np.polyfit(hours, peaks, 1)
    return float(intercept), float(slope)


def _rows(sizes: Sequence[Size], smoke: bool) -> list[BenchRow]:
    """Per size and command: time, peak memory; then the ratios judged against the aims, the
    exponents and the extrapolation."""
    rows: list[BenchRow] = []
    base, top = sizes[0], sizes[-1]
    rows += [BenchRow("corpus", f"x{s.factor}: training speech", s.train_hours * 60, "min",
                      note=f"{s.factor} times the corpus's training split") for s in sizes]
    for command in ("train", "eval"):
        for s in sizes:
            note = (f"fastest of {len(s.runs[command])} runs: "
                    + ", ".join(f"{r.wall:.1f}" for r in s.runs[command]) + " s")
            rows.append(BenchRow("corpus", f"{command} x{s.factor}: time", s.wall(command), "s",
                                 note=note, cpu=s.cpu(command)))
            judge = s is top and not smoke
            rows.append(BenchRow("corpus", f"{command} x{s.factor}: peak memory", s.peak(command),
                                 "MiB", aim=f"<= {MEMORY_AIM_MIB:.0f} MiB" if s is top else "",
                                 ok=s.peak(command) <= MEMORY_AIM_MIB if judge else None,
                                 note="largest process (workers included)"))
        ratio = top.wall(command) / base.wall(command)
        rows.append(BenchRow("corpus", f"{command} x{top.factor} / x{base.factor}: time", ratio, "x",
                             aim=f"<= {TIME_AIM_RATIO:g} x" if top.factor == 16 else "",
                             ok=ratio <= TIME_AIM_RATIO if top.factor == 16 and not smoke else None,
                             cpu=top.cpu(command) / base.cpu(command), note="one process"))
        rows += _growth(sizes, command)
        every = f"{command}, every core"
        rows += [BenchRow("corpus", f"{command} x{s.factor}, every core: time", s.wall(every), "s",
                          note=f"{s.wall(command) / s.wall(every):.2f} x one process's; fastest "
                               f"of " + ", ".join(f"{r.wall:.1f}" for r in s.runs[every]) + " s",
                          cpu=s.cpu(every)) for s in sizes]
        rows.append(BenchRow("corpus", f"{command} x{top.factor} / x{base.factor}, every core: "
                                       f"time", top.wall(every) / base.wall(every), "x",
                             cpu=top.cpu(every) / base.cpu(every)))
    return rows


def _growth(sizes: Sequence[Size], command: str) -> list[BenchRow]:
    """A command's growth exponents and its extrapolation to :data:`HOURS` of training speech."""
    base = sizes[0]
    e_all = exponent(sizes, command)
    e_top = exponent(sizes, command, -2, -1) if len(sizes) > 2 else e_all
    factor = HOURS / base.train_hours
    intercept, per_hour = memory_line(sizes, command)
    return [
        BenchRow("corpus", f"{command}: time growth exponent", e_all, "",
                 note=f"time ~ size^e, x{sizes[0].factor} to x{sizes[-1].factor}; "
                      f"x{sizes[-2].factor} to x{sizes[-1].factor}: {e_top:.2f}",
                 cpu=exponent(sizes, command, cpu=True)),
        BenchRow("corpus", f"{command}: peak memory per hour of training speech", per_hour, "MiB",
                 note=f"a line through the sizes: {intercept:.0f} MiB + {per_hour:.0f} MiB/h"),
        BenchRow("corpus", f"{command}: at {HOURS:g} h of training speech (extrapolated): time",
                 base.wall(command) * factor ** max(e_all, e_top) / 60.0, "min",
                 note=f"x{factor:.0f} the default corpus, the larger exponent",
                 cpu=base.cpu(command) * factor ** max(e_all, e_top) / 60.0),
        BenchRow("corpus", f"{command}: at {HOURS:g} h of training speech (extrapolated): "
                           f"peak memory", intercept + per_hour * HOURS, "MiB"),
    ]


def run(ctx: BenchContext, factors: Sequence[int] | None = None,
        repeats: int | None = None) -> list[BenchRow]:
    """The corpus scaling rows on the context's corpus."""
    factors = list(factors or (SMOKE_FACTORS if ctx.smoke else FACTORS))
    repeats = repeats or (SMOKE_REPEATS if ctx.smoke else REPEATS)
    corpus = ctx.corpus
    if ctx.smoke:                                    # a few utterances of the toy corpus
        corpus = corpus.without(corpus.info.train[4:] + corpus.info.test[2:])
    with tempfile.TemporaryDirectory(prefix="facetraj-corpus-scale-") as tmp:
        work = Path(tmp)
        hours = _train_hours(corpus)
        sizes = [Size(f, hours * f, repeat_corpus(corpus, work / f"x{f}", f)) for f in factors]
        measure(sizes, repeats, work)
    return _rows(sizes, ctx.smoke)


def _train_hours(corpus: Corpus) -> float:
    """Hours of training speech (from the audio files' headers)."""
    import soundfile

    from facetraj_engine.io.corpus import audio_path

    return sum(soundfile.info(str(audio_path(corpus.data_root, u))).duration
               for u in corpus.info.train) / 3600.0


# --------------------------------------------------------------------------- the Markdown section
#: a run longer than this is taken as "one machine is not enough" (a night's work)
NIGHT_H = 12.0


class _Figures:
    """The corpus rows by name."""

    def __init__(self, rows: Sequence[BenchRow]):
        self.rows = {r.name: r for r in rows if r.group == "corpus"}
        self.factors = sorted(int(n.split(":")[0][1:]) for n in self.rows
                              if n.endswith(": training speech"))

    def __call__(self, name: str, cpu: bool = False) -> float:
        row = self.rows.get(name)
        return float("nan") if row is None else (row.cpu if cpu else row.value)

    def note(self, name: str) -> str:
        row = self.rows.get(name)
        return "" if row is None else row.note


def section(rows: Sequence[BenchRow]) -> list[str]:
    """The Markdown section of the corpus scaling rows (none when they did not run): the table by
    size, the growth, and from these figures where one machine stops being enough."""
    fig = _Figures(rows)
    if not fig.factors:
        return []
    lines = ["## A lab's whole corpus: training and evaluation as the corpus grows (issue 41)", "",
             "The real commands (`facetraj train`, then `facetraj eval` with the model it wrote, "
             "in one process, `-j 1`, and with their default, every core) on the default corpus "
             "repeated (symbolic links "
             "under new names), each run a child process measured from outside: wall time (the "
             "fastest of the runs, the sizes taking turns: the machine is shared, and the other "
             "jobs only ever add time), CPU time of the child and its workers, and the "
             "peak resident memory of the largest process (`os.wait4`, as `/usr/bin/time -v`). "
             "The ratios and exponents are those of one process: the machine is shared by other "
             "users' jobs, each of which takes a core from a run on both, and the longer runs of "
             "the larger sizes meet more of them. `benchmarks/corpus_scale.py`.", "",
             "| size | training speech | train: time | CPU | peak | every core | eval: time | "
             "CPU | peak | every core |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for f in fig.factors:
        cells = [f"x{f}", f"{fig(f'x{f}: training speech'):.0f} min"]
        for command in ("train", "eval"):
            cells += [f"{fig(f'{command} x{f}: time'):.1f} s",
                      f"{fig(f'{command} x{f}: time', cpu=True):.1f} s",
                      f"{fig(f'{command} x{f}: peak memory'):,.0f} MiB",
                      f"{fig(f'{command} x{f}, every core: time'):.1f} s"]
        lines.append("| " + " | ".join(cells) + " |")
    lines += [""] + [_growth_line(fig, c) for c in ("train", "eval")] + [""] + _one_machine(fig)
    return [*lines, ""]


def _growth_line(fig: _Figures, command: str) -> str:
    lo, hi = fig.factors[0], fig.factors[-1]
    ratio = f"{command} x{hi} / x{lo}: time"
    at = f"{command}: at {HOURS:g} h of training speech (extrapolated)"
    every = f"{command} x{hi} / x{lo}, every core: time"
    return (f"- `{command}`: x{hi} takes {fig(ratio):.1f} times the time of x{lo} in one process "
            f"({fig(ratio, cpu=True):.1f} times its CPU time; on every core {fig(every):.1f} "
            f"times, {fig(every, cpu=True):.1f} times the CPU time); time ~ size^"
            f"{fig(f'{command}: time growth exponent'):.2f} "
            f"({fig.note(f'{command}: time growth exponent').split('; ')[-1]}); peak memory "
            f"{fig.note(f'{command}: peak memory per hour of training speech').split(': ')[-1]}."
            f" At {HOURS:g} h of training speech: about {fig(f'{at}: time'):.0f} min and "
            f"{fig(f'{at}: peak memory') / 1024:.1f} GiB.")


def _limits(fig: _Figures, command: str) -> tuple[float, float]:
    """The hours of training speech at which ``command`` would need all of this machine's
    memory, and at which it would run longer than :data:`NIGHT_H`."""
    per_hour = fig(f"{command}: peak memory per hour of training speech")
    at = fig(f"{command}: at {HOURS:g} h of training speech (extrapolated): peak memory")
    by_memory = (ram_gib() * 1024 - (at - HOURS * per_hour)) / per_hour if per_hour > 0 else math.inf
    lo = fig.factors[0]
    exponent_ = max(fig(f"{command}: time growth exponent"), 1.0)
    base_h = fig(f"x{lo}: training speech") / 60
    by_time = base_h * (NIGHT_H * 3600 / fig(f"{command} x{lo}: time")) ** (1 / exponent_)
    return by_memory, by_time


def _one_machine(fig: _Figures) -> list[str]:
    """Where one machine stops being enough, and what would carry the work further."""
    limits = {c: _limits(fig, c) for c in ("train", "eval")}
    hours, command = min((min(v), c) for c, v in limits.items())
    what = "memory" if limits[command][0] <= limits[command][1] else "time"
    return [
        "### Past one machine", "",
        f"On this machine ({ram_gib():.0f} GiB, {os.cpu_count()} cores), from these "
        f"figures: training would need all the memory at about {limits['train'][0]:,.0f} h of "
        f"training speech and run longer than {NIGHT_H:g} h at about {limits['train'][1]:,.0f} h; "
        f"the evaluation at about {limits['eval'][0]:,.0f} h and {limits['eval'][1]:,.0f} h. One "
        f"machine stops being enough at about **{hours:,.0f} hours of training speech** "
        f"(`{command}`, its {what}): past the largest articulograph corpora (the Haskins HPRC set "
        f"is about 8 hours, mngu0 about 1.5).", "",
        "What would carry it further (not built: the work already divides where a distribution "
        "layer would cut it):", "",
        "- **Training is per-utterance parallel.** Each of its three passes maps an utterance to "
        "a small result (the neutral pose's samples and the codewords' LSF vectors; the moments "
        "of its head-normalised frames; its codewords' PC vectors and closure statistics), merged "
        "in the utterances' order: `facetraj_engine.fanout.fan_out` spreads it over one machine's cores, "
        "and the same results could come from many machines, merged as the workers' are "
        "(`facetraj_engine.method.moments.Moments.merged`). What grows is the model (the codebook, "
        "linear in the speech); past one machine's memory it would be kept on disk and "
        "memory-mapped, or split by centre phone (eq 4 reads only the tokens of the phones "
        "visually similar to the input's).",
        "- **The codebook search is per-frame parallel.** Eqs 5-8 weigh each frame's candidates "
        "independently (`facetraj_engine.threads.map_spans` splits the frames between threads), and eq 4 "
        "scores an input phone against groups of contexts (`facetraj_engine.method.context_index`) whose "
        "number grows with the distinct triphones, not with the corpus's length: the evaluation's "
        "time per utterance stays nearly flat, its total about linear. Split by utterance over "
        "machines that each hold the model, or by phone over machines that each hold their "
        "phones' contexts, it scales out without changing a result; past one machine's memory "
        "the codebook would be memory-mapped rather than copied into each process.",
    ]
