"""Eqs 5-8 (paper section 2.3) compiled by numba, frame by frame in one loop: eq 5's weighted
distances to the frame's candidate codewords, eq 6's weights on every gamma of an evenly spaced
grid, eq 7's approximated LSFs and their error, the gamma of least error, and eq 8's PC vector.
The reference is ``facetraj_engine.method.synthesis.weight_frames`` (with ``grid_weights``): the same
formulas, its matrix products here sums in index order, so the results equal it to rounding
(``tests/test_kernels.py``). Used for a few candidates per frame only (the phonetic mode's):
on the acoustic-only 128 numpy's vectorised ``exp`` and BLAS products are faster.

Imported only through :mod:`facetraj_engine.method.kernels` (it imports numba).
"""

from __future__ import annotations

import numpy as np

from .kernels import jit


@jit
def _frame(w: np.ndarray, cand: np.ndarray, cb_lsf: np.ndarray, cb_pcs: np.ndarray,
           g0: float, step: float, n_g: int, h: np.ndarray, d: np.ndarray, e: np.ndarray,
           what: np.ndarray, err: np.ndarray) -> int:
    """Eqs 5-7 of one frame into the scratch arrays (``e``: the weights, ``(G, I)``); the index
    of the gamma of least error (the first of equal ones)."""
    p = w.shape[0]
    n_c = cand.shape[0]
    for k in range(p):                                       # eq 5's weights
        left = w[k] - (w[k - 1] if k > 0 else 0.0)
        right = (w[k + 1] if k < p - 1 else np.pi) - w[k]
        h[k] = 1.0 / max(min(left, right), 1e-6)
    low = np.inf
    for i in range(n_c):                                     # eq 5
        row = cb_lsf[cand[i]]
        acc = 0.0
        for k in range(p):
            acc += abs(row[k] - w[k]) * h[k]
        d[i] = acc
        low = min(low, acc)
    for i in range(n_c):                                     # eq 6, every gamma of the grid
        x = d[i] - low
        e[0, i] = np.exp(-g0 * x)
        ratio = np.exp(-step * x)
        for j in range(1, n_g):
            e[j, i] = e[j - 1, i] * ratio
    best = 0
    for j in range(n_g):
        total = 0.0
        for i in range(n_c):
            total += e[j, i]
        for i in range(n_c):
            e[j, i] /= total
        what[j, :] = 0.0                                     # eq 7
        for i in range(n_c):
            v = e[j, i]
            row = cb_lsf[cand[i]]
            for k in range(p):
                what[j, k] += v * row[k]
        acc = 0.0
        for k in range(p):
            acc += abs(what[j, k] - w[k]) * h[k]
        err[j] = acc
        if acc < err[best]:
            best = j
    return best


@jit
def weight_frames(w: np.ndarray, candidates: np.ndarray, cb_lsf: np.ndarray, cb_pcs: np.ndarray,
                  g0: float, step: float, n_g: int
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``synthesis.weight_frames`` on the gamma grid ``g0 + j step`` (``j < n_g``): per frame
    its PC vector (eq 8), the gamma index chosen, the candidates' weights, the approximated LSFs
    (eq 7) and their error."""
    n_frames, p = w.shape
    n_c = candidates.shape[1]
    pcs = np.zeros((n_frames, cb_pcs.shape[1]))
    chosen = np.empty(n_frames, dtype=np.int64)
    weights = np.empty((n_frames, n_c))
    lsf_hat = np.empty((n_frames, p))
    error = np.empty(n_frames)
    h, d = np.empty(p), np.empty(n_c)
    e, what, err = np.empty((n_g, n_c)), np.empty((n_g, p)), np.empty(n_g)
    for t in range(n_frames):
        cand = candidates[t]
        best = _frame(w[t], cand, cb_lsf, cb_pcs, g0, step, n_g, h, d, e, what, err)
        chosen[t] = best
        weights[t] = e[best]
        lsf_hat[t] = what[best]
        error[t] = err[best]
        out = pcs[t]
        for i in range(n_c):                                 # eq 8
            v = e[best, i]
            row = cb_pcs[cand[i]]
            for k in range(out.shape[0]):
                out[k] += v * row[k]
    return pcs, chosen, weights, lsf_hat, error


def warm_up() -> None:
    """Run the kernel once on a tiny input (loads or compiles it)."""
    lsf = np.sort(np.random.default_rng(0).uniform(0.1, 3.0, (6, 4)), axis=1)
    weight_frames(lsf[:2], np.array([[0, 1, 2], [3, 4, 5]]), lsf, np.ones((6, 2)), 0.2, 0.2, 10)
