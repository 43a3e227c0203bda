"""The Pearson correlation every score of the evaluation uses (Table 2's, the per-sensor
tables'), in one place."""

from __future__ import annotations

import numpy as np


def pearson(a: np.ndarray, b: np.ndarray) -> float:
    """Pearson correlation of two 1-D series; NaN when either is constant or shorter than 3.

    Examples
    --------
    >>> round(pearson(np.array([1.0, 2, 3, 4]), np.array([2.0, 4, 6, 8.5])), 4)
    0.9984
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if len(a) < 3:
        return float("nan")
    a = a - a.mean()
    b = b - b.mean()
    den = np.sqrt((a * a).sum() * (b * b).sum())
    return float((a * b).sum() / den) if den > 0 else float("nan")


__all__ = ["pearson"]
