"""``numpy.percentile`` (its default, linear method) and ``numpy.median`` of a set of numbers, to
the bit, without ``numpy.ma``: numpy imports its masked arrays on their first call (to check
for them), and a synthesis's start would wait for that import (issue 48). The same order
statistics (a partition), the same interpolation.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def percentiles(x: np.ndarray, q: Sequence[float]) -> np.ndarray:
    """``numpy.percentile(x, q)`` of all of ``x``: the ``q``-th percentiles (0-100) by linear
    interpolation between the order statistics around ``(n - 1) q / 100``; NaN where ``x`` holds
    a NaN.

    >>> percentiles(np.array([4.0, 1.0, 3.0, 2.0]), [0, 5, 50, 99, 100]).round(2).tolist()
    [1.0, 1.15, 2.5, 3.97, 4.0]
    """
    a = np.array(x, dtype=np.float64).ravel()
    if a.size == 0:
        raise ValueError("no values to take percentiles of")
    n = a.size
    where = (n - 1) * np.true_divide(np.asarray(q, dtype=np.float64), 100)
    below = np.floor(where)
    above = below + 1
    below[where >= n - 1] = above[where >= n - 1] = -1            # numpy's: the last value
    below[where < 0] = above[where < 0] = 0
    below, above = below.astype(np.intp), above.astype(np.intp)
    a.partition(sorted({0, n - 1, *(below % n).tolist(), *(above % n).tolist()}))
    if np.isnan(a[-1]):                                            # NaN sorts last
        return np.full(where.shape, np.nan)
    lo, hi = a[below], a[above]
    t = np.asarray(where - below, dtype=np.float64)
    step = hi - lo
    out = np.add(lo, step * t)
    np.subtract(hi, step * (1 - t), out=out, where=t >= 0.5)
    return out


def median(x: np.ndarray) -> float:
    """``numpy.median(x)`` of all of ``x``: the middle order statistic, or the mean of the two;
    NaN where ``x`` holds a NaN.

    >>> median(np.array([3.0, 1.0, 2.0])), median(np.array([4.0, 1.0, 3.0, 2.0]))
    (2.0, 2.5)
    """
    a = np.array(x, dtype=np.float64).ravel()
    if a.size == 0:
        return float("nan")
    half = a.size // 2
    a.partition(sorted({half - 1 if a.size % 2 == 0 else half, half, a.size - 1}))
    if np.isnan(a[-1]):
        return float("nan")
    return float(a[half]) if a.size % 2 else float((a[half - 1] + a[half]) / 2)
