"""Synthesis benchmark (paper section 2.3): real-time factor of :func:`facetraj_engine.method.pipeline.synthesize` for
1 s, 10 s and 60 s of input, phonetic (N = 3) and acoustic-only, both with the default settings
(acoustic-only: eqs 6-8 over the K = 128 codewords nearest by eq 5, found in the model's LSF index;
the whole-codebook search of the paper is timed by the scaling benchmark).

The input is test-split speech joined end to end (with its phone labels) and cut to length. The
real-time factor is input duration / wall time: 200 means 200 times faster than real time. Each
call includes the LSF analysis of the input, eqs 4-8, smoothing and the PC-to-marker rebuild.
Synthesis splits its per-frame stages between one thread per usable core by default
(``facetraj_engine.threads``); each figure is also measured on one frame thread. The per-stage table runs
on one frame thread, so that the stages' times add up to the call's. The compiled kernels
(``facetraj_engine.method.kernels``) are loaded before any timing; the LSF analysis is then one compiled
stage instead of the numpy reference's three (``FACETRAJ_KERNELS=numpy`` times the reference).
"""

from __future__ import annotations

import contextlib
import logging
import time
from collections.abc import Iterator, Sequence
from unittest import mock

from facetraj_engine.config import SynthConfig
from facetraj_engine.method import kernels, lsf, pipeline
from facetraj_engine.method.lsf_index import LsfIndex
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import Synthesis, synthesize
from facetraj_engine.threads import frame_spans, frame_threads, limit_frame_threads

from .common import BenchContext, BenchRow, Timing, best_time, concatenate_input, timed

log = logging.getLogger(__name__)

DURATIONS = (1.0, 10.0, 60.0)
SMOKE_DURATIONS = (1.0, 2.0)
AIMS = {"phonetic": 1000.0, "acoustic": 300.0}     # issue 15
#: the stages of a synthesis call, timed by wrapping the engine function that does each
STAGES = (
    ("LSF analysis: framing (analysis_frames)", lsf, "analysis_frames"),
    ("LSF analysis: LPC (autocorrelation + Levinson)", lsf, "lpc"),
    ("LSF analysis: LSF roots (poly2lsf)", lsf, "poly2lsf"),
    ("LSF analysis, compiled (window, LPC and roots: lsf.compiled_frame_lsf)", lsf,
     "compiled_frame_lsf"),
    ("eq 4 search (top_context_phones)", pipeline, "top_context_phones"),
    ("LSF index search (acoustic candidates)", LsfIndex, "nearest"),
    ("eqs 5-8 (weight_frames)", pipeline, "weight_frames"),
    ("smoothing", pipeline, "smooth"),
    ("PCA back-projection (to_markers)", Model, "to_markers"),
)
STAGE_SECONDS = 10.0


def run(ctx: BenchContext, durations: Sequence[float] | None = None) -> list[BenchRow]:
    """Real-time factors for each duration and mode; return the table rows."""
    durations = tuple(durations or (SMOKE_DURATIONS if ctx.smoke else DURATIONS))
    model = ctx.model
    source = ctx.test_utts or ctx.train_utts
    n_cw = model.codebook.lsf.shape[0]
    rows = []
    threads = frame_threads()
    kernels.warm_up()                          # numba's import and cache read: not timed
    for mode in ("phonetic", "acoustic"):
        cfg = SynthConfig(mode=mode)
        for seconds in durations:
            audio, rate, phones = concatenate_input(source, seconds)
            labels = phones if mode == "phonetic" else None

            def call(audio=audio, rate=rate, labels=labels, cfg=cfg) -> Synthesis:
                return synthesize(model, audio, rate, labels, cfg)

            what = ("N = 3" if mode == "phonetic" else
                    f"K = {cfg.acoustic_prefilter} of {n_cw} codewords, {cfg.acoustic_probe} of "
                    f"{model.lsf_index().n_cells} index cells")
            for n_threads in dict.fromkeys((threads, 1)):
                with limit_frame_threads(n_threads):
                    n_frames = len(call().times)  # warm-up
                    tm = best_time(call, repeat=3 if seconds <= 10 else 1,
                                   min_total_s=0.5 if seconds <= 10 else 0.0)
                t = tm.wall
                rtf = seconds / t
                log.info("synth %s %.0f s, %d frame threads: %.3f s (%.0fx real time)", mode,
                         seconds, n_threads, t, rtf)
                spans = len(frame_spans(n_frames, n_threads))
                note = f"{t * 1000:.1f} ms; {what}; {spans} frame thread{'s' * (spans > 1)}"
                if n_threads == threads:
                    aim = AIMS[mode]
                    rows.append(BenchRow("synth", f"{mode}, {seconds:g} s input", rtf, "x RT",
                                         aim=f">= {aim:.0f}x", ok=None if ctx.smoke else rtf >= aim,
                                         note=note, cpu=seconds / tm.cpu))
                else:
                    rows.append(BenchRow("synth", f"{mode}, {seconds:g} s input, one frame thread",
                                         rtf, "x RT", note=note, cpu=seconds / tm.cpu))
    return rows


@contextlib.contextmanager
def _stage_clock(spent: dict[str, Timing]) -> Iterator[None]:
    """Add each stage's wall and CPU seconds to ``spent`` while inside (the engine functions
    wrapped)."""
    with contextlib.ExitStack() as stack:
        for label, owner, name in STAGES:
            real = getattr(owner, name)

            def clocked(*args, _real=real, _label=label, **kwargs):
                t = Timing(time.perf_counter(), time.process_time())
                try:
                    return _real(*args, **kwargs)
                finally:
                    before = spent.get(_label, Timing(0.0, 0.0))
                    spent[_label] = Timing(before.wall + time.perf_counter() - t.wall,
                                           before.cpu + time.process_time() - t.cpu)

            stack.enter_context(mock.patch.object(owner, name, clocked))
        yield


def stages(ctx: BenchContext, seconds: float = STAGE_SECONDS, repeat: int = 7) -> list[BenchRow]:
    """Milliseconds per stage of phonetic and acoustic-only synthesis of ``seconds`` of input on
    one frame thread, from the fastest (by wall time) of ``repeat`` calls, and the rest of that
    call."""
    source = ctx.test_utts or ctx.train_utts
    audio, rate, phones = concatenate_input(source, seconds)
    rows = []
    for mode in ("phonetic", "acoustic"):
        cfg = SynthConfig(mode=mode)
        labels = phones if mode == "phonetic" else None
        best: dict[str, Timing] = {}
        for _ in range(repeat):
            spent: dict[str, Timing] = {}
            with _stage_clock(spent), limit_frame_threads(1):     # stages one after another
                whole, _ = timed(lambda cfg=cfg, labels=labels: synthesize(ctx.model, audio, rate,
                                                                           labels, cfg))
            if not best or whole.wall < best["whole call"].wall:
                best = {**spent, "whole call": whole}
        call = best.pop("whole call")
        rest = Timing(call.wall - sum(t.wall for t in best.values()),
                      call.cpu - sum(t.cpu for t in best.values()))
        for label, _, _ in STAGES:
            if label in best:
                t = best[label]
                rows.append(BenchRow("stages", f"{mode} {seconds:g} s: {label}", t.wall * 1000, "ms",
                                     note=f"{t.wall / call.wall:.0%} of the call", cpu=t.cpu * 1000))
        rows.append(BenchRow("stages", f"{mode} {seconds:g} s: the rest (labels, gathers, checks)",
                             rest.wall * 1000, "ms", cpu=rest.cpu * 1000))
        rows.append(BenchRow("stages", f"{mode} {seconds:g} s: whole call", call.wall * 1000, "ms",
                             note=f"{seconds / call.wall:.0f}x real time, one frame thread",
                             cpu=call.cpu * 1000))
    return rows
