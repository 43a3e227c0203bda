"""Synthesis benchmark (paper section 2.3): real-time factor of :func:`engine.pipeline.synthesize` for
1 s, 10 s and 60 s of input, phonetic (N = 3) and acoustic-only, both with the default settings
(acoustic-only: eqs 6-8 over the K = 128 codewords nearest by eq 5, found in the model's LSF index;
the whole-codebook search of the paper is timed by the scaling benchmark).

The input is test-split speech joined end to end (with its phone labels) and cut to length. The
real-time factor is input duration / wall time: 200 means 200 times faster than real time. Each
call includes the LSF analysis of the input, eqs 4-8, smoothing and the PC-to-marker rebuild.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

from engine.config import SynthConfig
from engine.pipeline import synthesize

from .common import BenchContext, BenchRow, best_time, concatenate_input

log = logging.getLogger(__name__)

DURATIONS = (1.0, 10.0, 60.0)
SMOKE_DURATIONS = (1.0, 2.0)
AIMS = {"phonetic": 200.0, "acoustic": 50.0}


def run(ctx: BenchContext, durations: Sequence[float] | None = None) -> list[BenchRow]:
    """Real-time factors for each duration and mode; return the table rows."""
    durations = tuple(durations or (SMOKE_DURATIONS if ctx.smoke else DURATIONS))
    model = ctx.model
    source = ctx.test_utts or ctx.train_utts
    n_cw = model.codebook.lsf.shape[0]
    rows = []
    for mode in ("phonetic", "acoustic"):
        cfg = SynthConfig(mode=mode)
        for seconds in durations:
            audio, rate, phones = concatenate_input(source, seconds)
            labels = phones if mode == "phonetic" else None

            def call(audio=audio, rate=rate, labels=labels, cfg=cfg) -> None:
                synthesize(model, audio, rate, labels, cfg)

            call()  # warm-up
            tm = best_time(call, repeat=3 if seconds <= 10 else 1, min_total_s=0.5 if seconds <= 10 else 0.0)
            t = tm.wall
            rtf = seconds / t
            aim = AIMS[mode]
            log.info("synth %s %.0f s: %.3f s (%.0fx real time)", mode, seconds, t, rtf)
            what = ("N = 3" if mode == "phonetic" else
                    f"K = {cfg.acoustic_prefilter} of {n_cw} codewords, {cfg.acoustic_probe} of "
                    f"{model.lsf_index().n_cells} index cells")
            rows.append(BenchRow("synth", f"{mode}, {seconds:g} s input", rtf, "x RT",
                                 aim=f">= {aim:.0f}x", ok=None if ctx.smoke else rtf >= aim,
                                 note=f"{t * 1000:.1f} ms; {what}", cpu=seconds / tm.cpu))
    return rows
