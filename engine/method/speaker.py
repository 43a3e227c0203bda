"""Speaker normalisation of the input LSFs for acoustic-only synthesis.

A live voice is never the training voice. A shorter vocal tract (a female or child voice) puts
every formant, and so the LSFs that cluster around them, at higher frequencies than the training
voice's; the codebook search (eq 5) then finds codewords of the wrong sounds. Like vocal tract
length normalisation in speech recognition, the input LSFs are mapped through a piecewise-linear
frequency warp ``w -> alpha w`` (below a knee, then a straight line to pi, so that the warped
LSFs stay ascending in (0, pi)), with ``alpha`` chosen per speaker or per utterance as the one on
a grid whose warped frames lie nearest (eq 5's distance) to the codebook.
"""

from __future__ import annotations

import numpy as np

from .synthesis import lsf_distances, nearest_codewords

#: the knee of the warp, as a fraction of pi, for alpha <= 1 (scaled down for alpha > 1)
KNEE = 0.8


def warp_lsf(w: np.ndarray, alpha: float) -> np.ndarray:
    """Warp LSFs ``w`` (radians, ``(..., P)``): ``alpha w`` below the knee ``b = 0.8 pi /
    max(1, alpha)``, then the straight line from ``(b, alpha b)`` to ``(pi, pi)``.

    ``alpha < 1`` lowers the frequencies (a shorter vocal tract's LSFs toward a longer one's).

    Examples
    --------
    >>> np.round(warp_lsf(np.array([1.0, 0.9 * np.pi, np.pi]), 0.8) / np.pi, 4).tolist()
    [0.2546, 0.82, 1.0]
    """
    w = np.asarray(w, dtype=np.float64)
    knee = KNEE * np.pi / max(1.0, alpha)
    upper = alpha * knee + (np.pi - alpha * knee) * (w - knee) / (np.pi - knee)
    return np.where(w <= knee, alpha * w, upper)


def warp_grid(lo: float = 0.76, hi: float = 1.2, step: float = 0.02) -> np.ndarray:
    """The warp factors searched by :func:`choose_warp`.

    >>> warp_grid(0.9, 1.0, 0.05).tolist()
    [0.9, 0.95, 1.0]
    """
    return np.round(np.arange(lo, hi + step / 2, step), 6)


def choose_warp(w: np.ndarray, cb_lsf: np.ndarray, alphas: np.ndarray | None = None,
                max_frames: int = 400) -> float:
    """The warp factor whose warped frames are nearest to the codebook: the one minimising the
    median over frames of eq 5's distance to the nearest codeword.

    ``w`` is ``(T, P)`` input LSFs of one speaker or utterance; at most ``max_frames`` evenly
    spaced frames are used (the choice needs a few seconds of speech, not all of it).
    """
    alphas = warp_grid() if alphas is None else np.asarray(alphas, dtype=np.float64)
    w = np.asarray(w, dtype=np.float64)
    if len(w) > max_frames:
        w = w[np.linspace(0, len(w) - 1, max_frames).round().astype(int)]
    cost = np.empty(len(alphas))
    for k, alpha in enumerate(alphas):
        ww = warp_lsf(w, float(alpha))
        best = nearest_codewords(ww, cb_lsf, 1)[:, 0]
        d = lsf_distances(ww, cb_lsf[best][:, None, :])[:, 0]                # eq 5
        cost[k] = np.median(d)
    return float(alphas[int(np.argmin(cost))])
