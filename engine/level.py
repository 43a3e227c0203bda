"""A signal's level, kept out of what facetraj computes (issue 38): the same recording at any
gain that floating point can represent gives the same energy decisions, LSFs, labels and face.

- LPC's equations are scale-free: :func:`facetraj_engine.method.lsf.lsf_at` brings the signal to a
  peak in [0.5, 1) by a power of two (:func:`unit_exponent`: exact, and no sample squared
  overflows);
- short-time energy is measured relative to the peak (:func:`peak_scaling`: the power of two
  first, then the mantissa), so that its floor and the speech/silence threshold see the same
  values at any gain;
- PocketSphinx hears 16-bit samples at a fixed share of full scale
  (:func:`facetraj_engine.labels.alignment.pcm16`); a streamed file is scaled to a peak of 1
  (:func:`to_full_scale`).

What is left between two gains is rounding (their ratio's mantissa), far under what any output
file stores: a float WAV scaled by 1e200 gives the same output file as the same audio unscaled
(tests/test_level.py).
"""

from __future__ import annotations

import numpy as np


def peak(x: np.ndarray) -> float:
    """``max |x|`` without a copy of ``x`` (0 for an empty signal; NaN and inf as they are).

    >>> peak(np.array([0.25, -0.75])), peak(np.zeros(0))
    (0.75, 0.0)
    """
    x = np.asarray(x)
    return max(float(x.max()), -float(x.min())) if x.size else 0.0


def unit_exponent(x: np.ndarray | float) -> int:
    """The power of two ``k`` that brings the peak of ``x`` (a signal, or its peak) into
    [0.5, 1): 0 for silence or a peak that is not finite.

    >>> unit_exponent(np.array([0.6])), unit_exponent(np.array([3.0])), unit_exponent(1e200)
    (0, -2, -665)
    >>> unit_exponent(np.zeros(4)), unit_exponent(float("inf"))
    (0, 0)
    """
    p = float(x) if np.ndim(x) == 0 else peak(x)
    return -int(np.frexp(p)[1]) if 0.0 < p < np.inf else 0


def peak_scaling(x: np.ndarray) -> tuple[int, float]:
    """``(k, f)`` such that ``ldexp(x, k) * f`` has a peak of exactly 1 (``(0, 1.0)`` for silence
    or a peak that is not finite): the power of two first, so that no factor overflows however
    small the peak. The same recording at two gains comes out equal to rounding.

    >>> peak_scaling(np.array([0.25, -0.5])), peak_scaling(np.array([3.0]))
    ((0, 2.0), (-2, 1.3333333333333333))
    """
    p = peak(x)
    if not 0.0 < p < np.inf:
        return 0, 1.0
    k = unit_exponent(p)
    return k, 1.0 / float(np.ldexp(p, k))


def to_full_scale(x: np.ndarray) -> np.ndarray:
    """``x`` scaled to a peak of exactly 1 (:func:`peak_scaling`; silence as it is).

    >>> to_full_scale(np.array([1e200, -5e199])).tolist()
    [1.0, -0.5]
    """
    k, f = peak_scaling(x)
    return np.ldexp(np.asarray(x, dtype=np.float64), k) * f
