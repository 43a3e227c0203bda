"""The closure step's per-interval work (``facetraj_engine.method.closure``): each interval and pause
touches only its own frames, with results equal to the bit to the formula over every frame."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.method.closure import ClosurePlan, ClosureStats, bump, close_lips, rest_in_pauses


def _close_lips_every_frame(pcs, times, plan, stats, a0, g, taper_s):
    """The step as its docstring states it, every interval's bump over the whole input."""
    a = a0 + pcs @ g
    c = np.zeros(len(pcs))
    for (t0, t1), s in zip(plan.intervals, plan.strengths, strict=True):
        idx = np.flatnonzero((times >= t0) & (times < t1))
        if idx.size == 0:
            idx = np.array([int(np.argmin(np.abs(times - 0.5 * (t0 + t1))))])
        move = s * min(0.0, stats.closed - float(a[idx].min()))
        if move < 0:
            c = np.minimum(c, move * bump(times, t0, t1, taper_s))
    return pcs + c[:, None] * stats.direction[None, :]


def _rest_every_frame(pcs, times, plan, stats, taper_s):
    b = np.zeros(len(pcs))
    for t0, t1 in plan.pauses:
        b = np.maximum(b, bump(times, t0, t1, taper_s, inside=True))
    return pcs + b[:, None] * (stats.rest[None, :] - pcs)


def _plan(rng, duration: float, n: int) -> ClosurePlan:
    """Random intervals: some shorter than a frame, some at the input's ends or beyond, some
    overlapping."""
    starts = rng.uniform(-0.05, duration, n)
    lengths = np.where(rng.random(n) < 0.3, rng.uniform(0, 0.01, n), rng.uniform(0.02, 0.3, n))
    intervals = np.column_stack([starts, starts + lengths])
    p0 = np.sort(rng.uniform(0, duration, 2 * (n // 3))).reshape(-1, 2)
    return ClosurePlan(intervals, rng.uniform(0, 1, n), p0)


@pytest.mark.parametrize("taper_s", [0.0, 0.016, 0.05, 0.3])
@pytest.mark.parametrize("seed", range(4))
def test_closure_step_equals_the_formula_over_every_frame(seed: int, taper_s: float) -> None:
    rng = np.random.default_rng(seed)
    times = np.arange(600) / 60.0
    k = 6
    pcs = rng.standard_normal((len(times), k)) * 5
    stats = ClosureStats(-3.0, rng.standard_normal(k), rng.standard_normal(k))
    g = rng.standard_normal(k)
    plan = _plan(rng, times[-1], 40)
    got = close_lips(pcs, times, plan, stats, 0.5, g, taper_s)
    assert np.array_equal(got, _close_lips_every_frame(pcs, times, plan, stats, 0.5, g, taper_s))
    assert not np.array_equal(got, pcs)                       # the intervals moved the lips
    rested = rest_in_pauses(pcs, times, plan, stats, taper_s)
    assert np.array_equal(rested, _rest_every_frame(pcs, times, plan, stats, taper_s))
    assert not np.array_equal(rested, pcs)
