"""Codebook scaling benchmark: acoustic-only synthesis (paper section 2.3, eq 5 over the whole
codebook 5L) as the codebook grows x1, x4, x16, and what the nearest-neighbour prefilter
(``SynthConfig(acoustic_prefilter=K)``) buys, with its accuracy cost.

The larger codebooks replicate the trained one with jitter (LSFs + N(0, 0.01 rad), re-sorted;
PCs + 5 % of each PC's standard deviation), which keeps the codeword density realistic. The
accuracy cost of the prefilter is the correlation between its synthesized trajectories and the
full search's on the same input (1 = identical), averaged over the moving coordinates as in the
"whole face" figure, and, for the x1 codebook, the whole-face correlation with the original
markers on test utterances, scored as in Table 2.
"""

from __future__ import annotations

import inspect
import logging
import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from engine.codebook import Codebook
from engine.config import SynthConfig
from engine.evaluation import speech_mask, trajectory_correlations
from engine.model import Model, Synthesis, synthesize
from engine.synthesis import nearest_codewords

from .common import BenchContext, BenchRow, Timing, concatenate_input, timed

log = logging.getLogger(__name__)

FACTORS = (1, 4, 16)
SMOKE_FACTORS = (1, 4)
PREFILTERS = (32, 128, 512)
SMOKE_PREFILTERS = (32,)
INPUT_S = 5.0
SMOKE_INPUT_S = 1.0
LSF_JITTER = 0.01
PC_JITTER = 0.05
#: test utterances scored against the original markers (full search vs prefilter, x1 codebook)
N_TEST_UTTS = 8
#: prefilter runs whose distance temporaries would exceed this are skipped (shared machine)
MAX_TEMP_BYTES = 2.5 * 1024**3


def prefilter_temp_bytes(n_frames: int, n_codewords: int, order: int) -> float:
    """Peak temporaries of ``engine.synthesis.nearest_codewords`` as written when this benchmark
    was: a float32 ``(chunk, 5L, P)`` difference and its absolute value per chunk of frames.
    An implementation without a fixed integer ``chunk`` default is assumed to bound its memory."""
    chunk = inspect.signature(nearest_codewords).parameters.get("chunk")
    if chunk is None or not isinstance(chunk.default, int):
        return 0.0
    return 2.0 * min(chunk.default, n_frames) * n_codewords * order * 4


def replicate_codebook(cb: Codebook, factor: int, rng: np.random.Generator) -> Codebook:
    """The codebook repeated ``factor`` times, copies after the first jittered (LSF order kept)."""
    if factor == 1:
        return cb
    n = cb.n_per_phone
    lsf = [cb.lsf]
    pcs = [cb.pcs]
    pc_sd = np.nanstd(cb.pcs, axis=0)
    for _ in range(factor - 1):
        j = np.sort(cb.lsf + rng.normal(0.0, LSF_JITTER, cb.lsf.shape), axis=1)
        lsf.append(np.clip(j, 1e-3, np.pi - 1e-3))
        pcs.append(cb.pcs + rng.normal(0.0, 1.0, cb.pcs.shape) * PC_JITTER * pc_sd)
    return Codebook(
        contexts=np.tile(cb.contexts, (factor, 1)), lsf=np.concatenate(lsf),
        pcs=np.concatenate(pcs), token_utt=np.tile(cb.token_utt, factor),
        token_start=np.tile(cb.token_start, factor), token_end=np.tile(cb.token_end, factor),
        n_per_phone=n)


def agreement(model: Model, a: np.ndarray, b: np.ndarray) -> float:
    """Whole-face correlation between two synthesized ``(T, M, 3)`` trajectories on all frames."""
    mask = np.ones(a.shape[0], dtype=bool)
    return trajectory_correlations(a, b, mask, model)["whole_face"]


def _timed(model: Model, audio: np.ndarray, rate: int, cfg: SynthConfig) -> tuple[Timing, Synthesis]:
    tm, res = timed(lambda: synthesize(model, audio, rate, None, cfg))
    return tm, res  # type: ignore[return-value]


def original_correlation(model: Model, ctx: BenchContext, prefilter: int | None) -> float:
    """Mean whole-face correlation with the original markers, acoustic-only, on test utterances."""
    scores = []
    for utt in ctx.test_utts[:N_TEST_UTTS]:
        res = synthesize(model, utt.audio, utt.sample_rate, None,
                         SynthConfig(mode="acoustic", acoustic_prefilter=prefilter),
                         n_frames=utt.n_frames)
        mask = speech_mask(utt.audio, utt.sample_rate, res.times)
        orig = model.normalise_markers(utt.markers)
        scores.append(trajectory_correlations(orig, res.markers, mask, model)["whole_face"])
    return float(np.nanmean(scores)) if scores else float("nan")


def run(ctx: BenchContext, factors: Sequence[int] | None = None,
        prefilters: Sequence[int] | None = None, seconds: float | None = None) -> list[BenchRow]:
    """Acoustic-only synthesis time per codebook size, full search and prefiltered."""
    factors = tuple(factors or (SMOKE_FACTORS if ctx.smoke else FACTORS))
    prefilters = tuple(prefilters or (SMOKE_PREFILTERS if ctx.smoke else PREFILTERS))
    seconds = seconds or (SMOKE_INPUT_S if ctx.smoke else INPUT_S)
    base = ctx.model
    audio, rate, _ = concatenate_input(ctx.test_utts or ctx.train_utts, seconds)
    rng = np.random.default_rng(0)
    rows: list[BenchRow] = []
    full_times: dict[int, float] = {}
    pre_times: dict[tuple[int, int], float] = {}
    full_cpu: dict[int, float] = {}
    pre_cpu: dict[tuple[int, int], float] = {}
    synthesize(base, audio[: rate // 2], rate, None, SynthConfig(mode="acoustic"))  # warm-up
    for factor in factors:
        model = replace(base, codebook=replicate_codebook(base.codebook, factor, rng))
        size = model.codebook.lsf.shape[0]
        tm_full, full = _timed(model, audio, rate, SynthConfig(mode="acoustic"))
        t_full = tm_full.wall
        full_times[factor] = t_full
        full_cpu[factor] = tm_full.cpu
        rows.append(BenchRow("scaling", f"acoustic, full search, codebook x{factor}",
                             seconds / t_full, "x RT",
                             aim=">= 50x" if factor == 1 else "",
                             ok=None if ctx.smoke or factor != 1 else seconds / t_full >= 50,
                             note=f"{size} codewords; {t_full * 1000 / full.times.size:.2f} ms/frame",
                             cpu=seconds / tm_full.cpu))
        for k in prefilters:
            if k >= size:
                continue
            temp = prefilter_temp_bytes(full.times.size, size, base.config.lpc_order)
            if temp > MAX_TEMP_BYTES:
                rows.append(BenchRow("scaling", f"acoustic, prefilter K={k}, codebook x{factor}",
                                     float("nan"), "x RT",
                                     note=f"skipped: nearest_codewords would allocate "
                                          f"{temp / 1024**3:.1f} GiB of temporaries"))
                continue
            tm_pre, pre = _timed(model, audio, rate, SynthConfig(mode="acoustic", acoustic_prefilter=k))
            t_pre = tm_pre.wall
            pre_times[(factor, k)] = t_pre
            pre_cpu[(factor, k)] = tm_pre.cpu
            agree = agreement(model, full.markers, pre.markers)
            rows.append(BenchRow("scaling", f"acoustic, prefilter K={k}, codebook x{factor}",
                                 seconds / t_pre, "x RT",
                                 note=f"{t_full / t_pre:.1f}x faster than full search; "
                                      f"correlation with full search {agree:.4f}",
                                 cpu=seconds / tm_pre.cpu))
        log.info("scaling x%d (%d codewords): full %.2f s", factor, size, t_full)
    lo, hi = min(factors), max(factors)
    if hi > lo:
        def exponent(t_lo: float, t_hi: float) -> float:
            return math.log(t_hi / t_lo) / math.log(hi / lo)

        e_full = exponent(full_times[lo], full_times[hi])
        rows.append(BenchRow("scaling", f"growth exponent, full search (time ~ size^e, x{lo}..x{hi})",
                             e_full, "e", aim="< 1", ok=None if ctx.smoke else e_full < 1,
                             cpu=exponent(full_cpu[lo], full_cpu[hi])))
        for k in prefilters:
            have = sorted(f for f in factors if (f, k) in pre_times)
            if len(have) < 2:
                continue
            a, b = have[0], have[-1]

            def exp_k(t: dict[tuple[int, int], float], a: int = a, b: int = b, k: int = k) -> float:
                return math.log(t[(b, k)] / t[(a, k)]) / math.log(b / a)

            e = exp_k(pre_times)
            rows.append(BenchRow("scaling", f"growth exponent, prefilter K={k} (x{a}..x{b})", e, "e",
                                 aim="< 1", ok=None if ctx.smoke else e < 1, cpu=exp_k(pre_cpu)))
    # accuracy against the original markers (x1 codebook)
    if ctx.test_utts:
        n = min(len(ctx.test_utts), N_TEST_UTTS)
        c_full = original_correlation(base, ctx, None)
        rows.append(BenchRow("scaling", "test whole-face correlation, acoustic full search", c_full,
                             "corr", note=f"first {n} test utterances, triangular"))
        k = prefilters[len(prefilters) // 2]
        c_pre = original_correlation(base, ctx, k)
        rows.append(BenchRow("scaling", f"test whole-face correlation, acoustic prefilter K={k}",
                             c_pre, "corr", note=f"change {c_pre - c_full:+.4f} vs full search"))
    return rows
