"""``python -m benchmarks [--smoke] [--corpus DIR] [--out FILE] [--only GROUP ...]``

Runs the training, synthesis, scaling, corpus scaling and phone-labelling benchmarks (and the app's
playback and label-edit benchmarks, ``benchmarks/playback.py`` and ``benchmarks/label_edit.py``,
when a display is available), prints one table and writes it, with the machine described, to
``docs/benchmarks.md``.

``--smoke`` runs a tiny size (a few utterances, short inputs) that CI can afford in well under a
minute; it writes the Markdown only when ``--out`` is given, so that it never replaces the
full-size results.
"""

from __future__ import annotations

import argparse
import datetime as dt
import importlib
import importlib.util
import logging
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from facetraj_engine.threads import limit_frame_threads, one_blas_thread

from . import cli, corpus_scale, labels, live, scaling, startup, synth, train
from .common import (
    REPO,
    BenchContext,
    BenchRow,
    concatenate_input,
    format_table,
    load_context,
    machine_info,
    markdown_table,
    profile_top,
)

log = logging.getLogger("benchmarks")

GROUPS = ("train", "synth", "cli", "scaling", "corpus", "eval", "labels", "playback", "startup",
          "live", "edit")
DEFAULT_OUT = REPO / "docs" / "benchmarks.md"
#: hand-written profile notes (per stage, before and after a change), copied into the Markdown
NOTES = REPO / "benchmarks" / "profile_notes.md"


def display_available() -> tuple[bool, str]:
    """Whether a Qt window can open here, and why not."""
    from facetraj_app.display import has_display

    if has_display():
        return True, ""
    return False, "no DISPLAY (run under xvfb-run, as make bench does)"


def run_playback(smoke: bool, corpus: Path | None = None) -> list[BenchRow]:
    """Call ``benchmarks.playback.main(argv)`` when it exists and a display is available."""
    if importlib.util.find_spec("benchmarks.playback") is None:
        reason = "benchmarks/playback.py does not exist yet"
        print(f"playback benchmark skipped: {reason}")
        return [BenchRow("playback", "app playback", float("nan"), "", note=f"skipped: {reason}")]
    ok, reason = display_available()
    if not ok:
        print(f"playback benchmark skipped: {reason}")
        return [BenchRow("playback", "app playback", float("nan"), "", note=f"skipped: {reason}")]
    module = importlib.import_module("benchmarks.playback")
    try:
        argv = (["--corpus", str(corpus)] if corpus is not None else []) + (["--smoke"] if smoke else [])
        out = module.main(argv)
    except Exception as exc:  # the app benchmark is another module; report, do not crash ours
        log.exception("playback benchmark failed")
        return [BenchRow("playback", "app playback", float("nan"), "", note=f"failed: {exc}")]
    if isinstance(out, list) and all(isinstance(r, BenchRow) for r in out):
        return out
    return [BenchRow("playback", "app playback (see its own output)", float("nan"), "",
                     note=f"benchmarks.playback.main returned {out!r}")]


def run_edit(smoke: bool, corpus: Path | None = None) -> list[BenchRow]:
    """The label editor's edit-to-face benchmark (``benchmarks/label_edit.py``) when a display
    is available."""
    ok, reason = display_available()
    if not ok:
        print(f"label edit benchmark skipped: {reason}")
        return [BenchRow("edit", "label edit to the new faces on screen", float("nan"), "",
                         note=f"skipped: {reason}")]
    from . import label_edit

    argv = (["--corpus", str(corpus)] if corpus is not None else []) + (["--smoke"] if smoke else [])
    return label_edit.main(argv)


def run_all(ctx: BenchContext, only: Sequence[str] = GROUPS, factors: Sequence[int] | None = None,
            prefilters: Sequence[int] | None = None) -> list[BenchRow]:
    """Run the selected benchmark groups on ``ctx``; return all rows in order."""
    rows: list[BenchRow] = []
    if "train" in only:
        rows += train.run(ctx)
    if "synth" in only:
        with one_blas_thread():                   # as the app, the CLI and the evaluation run it
            rows += synth.run(ctx)
            rows += synth.stages(ctx, 2.0 if ctx.smoke else synth.STAGE_SECONDS, 2 if ctx.smoke else 7)
    if "cli" in only:
        rows += cli.one_file(ctx)
        rows += cli.batch(ctx)
    if "scaling" in only:
        with limit_frame_threads(1):              # how the search grows, on one core
            rows += scaling.run(ctx, factors, prefilters)
    if "corpus" in only:                          # the real commands on a corpus 1, 4, 16 times
        rows += corpus_scale.run(ctx)
    if "eval" in only:
        rows += startup.evaluation(ctx)
    if "labels" in only:
        rows += labels.run(ctx)
    if "playback" in only:
        rows += run_playback(ctx.smoke, ctx.corpus.root)
    if "startup" in only:
        rows += startup.cold_start(ctx) if display_available()[0] else [BenchRow(
            "startup", "cold start", float("nan"), "", note="skipped: no display")]
    if "live" in only:
        rows += live.run(ctx)
    if "edit" in only:
        rows += run_edit(ctx.smoke, ctx.corpus.root)
    return rows


def profiles(ctx: BenchContext) -> dict[str, list[tuple[str, float, float]]]:
    """Where synthesis spends its time: cProfile of 10 s phonetic and 2 s acoustic-only input."""
    from facetraj_engine.config import SynthConfig
    from facetraj_engine.method.pipeline import synthesize

    source = ctx.test_utts or ctx.train_utts
    model = ctx.model
    out = {}
    for mode, seconds in (("phonetic", 10.0), ("acoustic", 2.0)):
        audio, rate, phones = concatenate_input(source, seconds)
        labels = phones if mode == "phonetic" else None
        out[f"{mode}, {seconds:g} s input"] = profile_top(
            lambda audio=audio, rate=rate, labels=labels, mode=mode: synthesize(
                model, audio, rate, labels, SynthConfig(mode=mode)))
    return out


def write_markdown(path: Path, rows: Sequence[BenchRow], ctx: BenchContext, elapsed_s: float,
                   info: dict[str, str] | None = None,
                   prof: dict[str, list[tuple[str, float, float]]] | None = None) -> Path:
    """``docs/benchmarks.md``: the machine, the corpus, the table, and how to read it."""
    info = info or machine_info()
    size = (f"{len(ctx.train_utts)} training utterances ({ctx.train_audio_s / 60:.1f} min of speech), "
            f"{len(ctx.test_utts)} test utterances")
    lines = [
        "# Benchmarks",
        "",
        f"Written by `python -m benchmarks{' --smoke' if ctx.smoke else ''}` (`make bench`) on "
        f"{dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC in {elapsed_s:.0f} s.",
        "",
        "## Machine",
        "",
        *[f"- {k}: {v}" for k, v in info.items()],
        "",
        f"## Corpus\n\n`{ctx.corpus.root.name}/` ({ctx.corpus.info.name or 'unnamed'}): {size}.",
        "",
        "## Results",
        "",
        markdown_table(rows),
        "",
        "## Aims",
        "",
        *([f"- {r.name}: {r.cell()} {r.unit} (aim {r.aim}): **{r.verdict()}**"
           for r in rows if r.ok is not None] or ["- not judged (smoke size)"]),
        "",
        *corpus_scale.section(rows),
        *(["## Where synthesis spends its time (cProfile, own time)", ""] if prof else []),
        *[line for name, top in (prof or {}).items() for line in (
            f"{name}:", "", "| function | s | share |", "|---|---:|---:|",
            *[f"| `{f}` | {t:.3f} | {100 * sh:.0f} % |" for f, t, sh in top], "")],
        *(NOTES.read_text(encoding="utf-8").splitlines() if NOTES.exists() else []),
        "## How to read it",
        "",
        "- `value (CPU time)` is the same figure computed from this process's CPU time: on a shared "
        "machine wall time includes waiting for a core (it is the one judged against the aims); "
        "multi-threaded BLAS can make CPU time exceed wall time.",
        "- `x RT` is the real-time factor, input duration / wall time (200 = 200 times faster than "
        "real time). Every synthesis call includes the LSF analysis of the input, eqs 4-8, "
        "smoothing and the rebuild of the markers from the PCs.",
        "- Training times are measured inside one `facetraj_engine.method.training.train()` call by wrapping "
        "the "
        "engine's functions; the codebook row is the remainder of the call. Peak memory is traced "
        "in a second call.",
        "- `s/s` (labels) is seconds of computation per second of speech (lower is better): "
        "PocketSphinx forced alignment of the transcript (two passes; the fit check adds a free "
        "phone-loop recognition to reject text that does not match) and phone recognition.",
        "- Scaling replicates the trained codebook with jitter; the growth exponent e fits "
        "time ~ size^e between the smallest and largest codebook, on a fixed input.",
        "- The machine is shared (2 cores, other jobs running): synthesis of up to 10 s of input is "
        "timed as the best of at least 3 runs and 0.5 s of repeats (as `timeit` does), longer inputs "
        "by a single run; a scaling run is repeated the same way when it takes under a second.",
        "",
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n\n")[0])
    parser.add_argument("--smoke", action="store_true", help="tiny size for CI")
    parser.add_argument("--corpus", type=Path, default=None, help="corpus folder (default data_samples/)")
    parser.add_argument("--out", type=Path, default=None,
                        help=f"Markdown output (default {DEFAULT_OUT.relative_to(REPO)} when "
                             f"every group runs; none in smoke mode or with --only)")
    parser.add_argument("--only", nargs="+", choices=GROUPS, default=list(GROUPS))
    parser.add_argument("--factors", nargs="+", type=int, default=None,
                        help="codebook growth factors of the scaling benchmark (default 1 4 16)")
    parser.add_argument("--prefilters", nargs="+", type=int, default=None,
                        help="prefilter sizes K of the scaling benchmark (default 32 128 512)")
    args = parser.parse_args(argv)
    if not logging.getLogger().handlers:
        logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s", stream=sys.stderr)
    t0 = time.perf_counter()
    info = machine_info()
    ctx = load_context(args.corpus, args.smoke)
    rows = run_all(ctx, args.only, args.factors, args.prefilters)
    prof = profiles(ctx) if "synth" in args.only else None
    print(format_table(rows))
    partial = set(args.only) != set(GROUPS)          # a part never replaces the whole table
    out = args.out if args.out is not None else (None if args.smoke or partial else DEFAULT_OUT)
    if out is not None:
        write_markdown(out, rows, ctx, time.perf_counter() - t0, info, prof)
        print(f"written {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
