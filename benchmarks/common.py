"""Shared pieces of the benchmarks: the machine description, the benchmark context (corpus, loaded
utterances, a trained model), timing helpers, and the result table in text and Markdown.
"""

from __future__ import annotations

import logging
import math
import os
import platform
import re
import resource
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy

from facetraj_engine.data import PhoneSegment, Utterance
from facetraj_engine.io.corpus import Corpus, load_corpus
from facetraj_engine.method.model import Model
from facetraj_engine.method.training import MarkerSetup, train

log = logging.getLogger(__name__)

REPO = Path(__file__).resolve().parent.parent

#: utterances used in smoke mode (train, test): small enough for CI (< 60 s for everything)
SMOKE_TRAIN = 12
SMOKE_TEST = 3


# ---------------------------------------------------------------------- the result table
@dataclass
class BenchRow:
    """One measured number.

    Attributes
    ----------
    group : ``train``, ``synth``, ``stages``, ``scaling``, ``eval``, ``labels``, ``playback``, ``startup``
        or ``live``.
    name : what was measured.
    value : the number (NaN when it could not be measured).
    unit : ``s``, ``MiB``, ``x RT`` (times faster than real time), ``corr``, ``ms``...
    aim : the issue's aim for this number, as text (empty when there is none).
    ok : whether the aim is met (``None`` when there is no aim); judged on wall time.
    note : anything needed to read the number.
    cpu : the same number computed from this process's CPU time instead of wall time (NaN when
        not applicable). On a shared machine wall time includes waiting for a core; with
        multi-threaded BLAS CPU time can exceed wall time.
    """

    group: str
    name: str
    value: float
    unit: str
    aim: str = ""
    ok: bool | None = None
    note: str = ""
    cpu: float = float("nan")

    def cell(self, v: float | None = None) -> str:
        v = self.value if v is None else v
        if not math.isfinite(v):
            return "n/a"
        if self.unit == "corr":
            return f"{v:.4f}"
        if abs(v) >= 100:
            return f"{v:,.0f}"
        if abs(v) >= 10:
            return f"{v:.1f}"
        return f"{v:.3g}"

    def verdict(self) -> str:
        return "" if self.ok is None else ("met" if self.ok else "MISSED")


def format_table(rows: Sequence[BenchRow]) -> str:
    """The rows as a fixed-width text table (printed by ``python -m benchmarks``)."""
    heads = ("group", "benchmark", "value", "by CPU", "unit", "aim", "", "note")
    cells = [(r.group, r.name, r.cell(), r.cell(r.cpu) if math.isfinite(r.cpu) else "", r.unit, r.aim,
              r.verdict(), r.note) for r in rows]
    widths = [max(len(h), *(len(c[i]) for c in cells)) if cells else len(h)
              for i, h in enumerate(heads)]
    widths[-1] = len(heads[-1])
    line = "  ".join(h.ljust(w) for h, w in zip(heads, widths, strict=True)).rstrip()
    out = [line, "-" * len(line)]
    for c in cells:
        out.append("  ".join(x.rjust(w) if i in (2, 3) else x.ljust(w)
                             for i, (x, w) in enumerate(zip(c, widths, strict=True))).rstrip())
    return "\n".join(out)


def markdown_table(rows: Sequence[BenchRow]) -> str:
    """The rows as a Markdown table."""
    out = ["| group | benchmark | value (wall) | value (CPU time) | unit | aim | | note |",
           "|---|---|---:|---:|---|---|---|---|"]
    for r in rows:
        cpu = r.cell(r.cpu) if math.isfinite(r.cpu) else ""
        out.append(f"| {r.group} | {r.name} | {r.cell()} | {cpu} | {r.unit} | {r.aim} | {r.verdict()} "
                   f"| {r.note} |")
    return "\n".join(out)


# ---------------------------------------------------------------------- the machine
def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def ram_gib() -> float:
    """This machine's memory (GiB): ``MemTotal`` of /proc/meminfo, else the OS's page count (NaN
    when neither says)."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                return int(line.split()[1]) / 1024**2
    except OSError:
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    except (ValueError, OSError, AttributeError):
        return float("nan")


def machine_info() -> dict[str, str]:
    """CPU model, cores, RAM, OS, Python, numpy and scipy versions."""
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        usable = os.cpu_count() or 0
    return {
        "CPU": _cpu_model(),
        "cores": f"{os.cpu_count()} logical ({usable} usable by this process)",
        "RAM": f"{ram_gib():.1f} GiB",
        "OS": f"{platform.system()} {platform.release()}",
        "Python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "BLAS threads": ", ".join(f"{k}={os.environ[k]}" for k in
                                  ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
                                  if k in os.environ) or "library default",
        "load average at start": " ".join(f"{x:.1f}" for x in os.getloadavg()),
    }


def peak_rss_mib() -> float:
    """Peak resident set size of this process so far (``getrusage``), MiB."""
    kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return kb / 1024 if sys.platform != "darwin" else kb / 1024**2


# ---------------------------------------------------------------------- timing
@dataclass(frozen=True)
class Timing:
    """Wall and CPU seconds of one call."""

    wall: float
    cpu: float


def timed(fn: Callable[[], object]) -> tuple[Timing, object]:
    """Call ``fn`` once; its wall and process CPU time, and its result."""
    c0, t0 = time.process_time(), time.perf_counter()
    out = fn()
    return Timing(time.perf_counter() - t0, time.process_time() - c0), out


def best_time(fn: Callable[[], object], repeat: int = 3, min_total_s: float = 0.0) -> Timing:
    """The fastest (by wall time) of ``repeat`` calls of ``fn`` (more while under ``min_total_s``)."""
    best = Timing(float("inf"), float("inf"))
    total = 0.0
    count = 0
    while count < repeat or total < min_total_s:
        t, _ = timed(fn)
        if t.wall < best.wall:
            best = t
        total += t.wall
        count += 1
        if count >= 50:
            break
    return best


def profile_top(fn: Callable[[], object], n: int = 6) -> list[tuple[str, float, float]]:
    """cProfile ``fn``: the ``n`` functions with the most own time, as ``(name, seconds, share)``."""
    import cProfile
    import pstats

    prof = cProfile.Profile()
    prof.enable()
    fn()
    prof.disable()
    stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
    total = sum(v[2] for v in stats.values()) or 1.0
    top = sorted(stats.items(), key=lambda kv: -kv[1][2])[:n]
    out = []
    for (path, line, func), v in top:
        if path == "~":  # a builtin: "<built-in method numpy...c_einsum>" -> "c_einsum (numpy C)"
            quoted = re.search(r"'([^']+)'", func)
            name = (quoted.group(1) if quoted else func.strip("<>").split()[-1].split(".")[-1]) + " (C)"
        else:
            name = f"{Path(path).parent.name}/{Path(path).name}:{line}({func})"
        out.append((name, float(v[2]), float(v[2] / total)))
    return out


# ---------------------------------------------------------------------- the context
@dataclass
class BenchContext:
    """What every benchmark needs: the corpus, loaded utterances and a model trained once.

    Attributes
    ----------
    corpus : the corpus (default ``data_samples/``; the toy corpus when it is missing in smoke mode).
    smoke : the tiny CI size.
    train_utts, test_utts : the loaded utterances of the two splits (a subset in smoke mode).
    setup : marker roles from ``corpus.json``.
    load_s : wall time spent reading the utterances from disk.
    """

    corpus: Corpus
    smoke: bool
    train_utts: list[Utterance]
    test_utts: list[Utterance]
    setup: MarkerSetup
    load_s: float
    _model: Model | None = field(default=None, repr=False)

    @property
    def model(self) -> Model:
        """A model trained (once) on ``train_utts`` with the default configuration."""
        if self._model is None:
            self._model = train(self.train_utts, self.setup)
        return self._model

    @property
    def train_audio_s(self) -> float:
        return float(sum(u.duration for u in self.train_utts))


def _toy_corpus() -> Path:
    """Build the tests' toy corpus in a temporary folder (smoke mode without ``data_samples/``)."""
    sys.path.insert(0, str(REPO / "tests"))
    try:
        from toycorpus import build_toy_corpus  # type: ignore[import-not-found]
    finally:
        sys.path.pop(0)
    root = Path(tempfile.mkdtemp(prefix="facetraj-bench-toy-"))
    return build_toy_corpus(root)


def default_corpus_dir(smoke: bool) -> Path:
    """``data_samples/`` (or ``$FACETRAJ_CORPUS``); in smoke mode the toy corpus when it is absent."""
    from facetraj.paths import default_corpus

    root = default_corpus()
    if (root / "corpus.json").exists():
        return root
    if smoke:
        log.warning("%s has no corpus.json; smoke benchmarks run on the toy corpus", root)
        return _toy_corpus()
    raise FileNotFoundError(f"{root}/corpus.json not found: build the default corpus (make corpus) "
                            f"or pass --corpus")


def load_context(corpus_dir: str | os.PathLike[str] | None = None, smoke: bool = False) -> BenchContext:
    """Open the corpus and load its utterances (the first few of each split in smoke mode)."""
    root = Path(corpus_dir) if corpus_dir is not None else default_corpus_dir(smoke)
    corpus = load_corpus(root)
    info = corpus.info
    train_ids = list(info.train)[:SMOKE_TRAIN] if smoke else list(info.train)
    test_ids = list(info.test)[:SMOKE_TEST] if smoke else list(info.test)
    t0 = time.perf_counter()
    train_utts = [corpus.utterance(u) for u in train_ids]
    test_utts = [corpus.utterance(u) for u in test_ids]
    load_s = time.perf_counter() - t0
    setup = MarkerSetup(info.fixed_markers, info.upper_lip, info.lower_lip, info.lip_corners)
    log.info("corpus %s: %d train, %d test utterances loaded in %.1f s", root, len(train_utts),
             len(test_utts), load_s)
    return BenchContext(corpus, smoke, train_utts, test_utts, setup, load_s)


def concatenate_input(utts: Sequence[Utterance], seconds: float) -> tuple[np.ndarray, int,
                                                                          list[PhoneSegment]]:
    """Audio and phone labels of exactly ``seconds`` of speech, made by joining ``utts`` (cycled).

    The last phone is cut at ``seconds``. All utterances must share one sample rate.
    """
    if not utts:
        raise ValueError("no utterances to build the input from")
    rate = utts[0].sample_rate
    n_target = int(round(seconds * rate))
    audio_parts: list[np.ndarray] = []
    phones: list[PhoneSegment] = []
    n = 0
    k = 0
    while n < n_target:
        u = utts[k % len(utts)]
        if u.sample_rate != rate:
            raise ValueError("utterances with different sample rates")
        offset = n / rate
        audio_parts.append(u.audio)
        phones.extend(PhoneSegment(s.start + offset, s.end + offset, s.label) for s in u.phones)
        n += len(u.audio)
        k += 1
    audio = np.concatenate(audio_parts)[:n_target]
    end = n_target / rate
    cut = [s for s in phones if s.start < end - 1e-3]
    cut[-1] = PhoneSegment(cut[-1].start, end, cut[-1].label)
    return audio, rate, cut


def wait_for_window(cond, timeout: float, poll_ms: int = 20, what: str = "ready") -> None:
    """Run the Qt event loop in ``poll_ms`` passes until ``cond()`` holds (the app's window
    benchmarks); a TimeoutError after ``timeout`` seconds."""
    from PyQt6.QtCore import QEventLoop, QTimer

    end = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > end:
            raise TimeoutError(f"the window did not get {what} in time")
        loop = QEventLoop()
        QTimer.singleShot(poll_ms, loop.quit)
        loop.exec()
