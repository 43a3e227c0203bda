"""The LSF analysis (paper section 2.1) compiled by numba, frame by frame in one loop: Hamming
window, autocorrelation, Levinson-Durbin (LPC) and the LSF roots of the sum and difference
polynomials. The reference is ``facetraj_engine.method.lsf`` (``analysis_frames``, ``lpc``,
``poly2lsf``): the same formulas, tested equal to it to rounding (``tests/test_kernels.py``).

The reference computes the autocorrelation through an FFT, the root bracketing grid by a matrix
product; here both are direct sums, so the LPC coefficients differ from it by rounding only, and
the roots, polished by the same Newton iteration to the same tolerance, by about 1e-15 rad. A
frame whose roots cannot all be bracketed on the grid (two closer than pi/128) or polished is
flagged, and its LSFs are computed by the reference (its colleague-matrix eigenvalues).

Imported only through :mod:`facetraj_engine.method.kernels` (it imports numba).
"""

from __future__ import annotations

import numpy as np

from .kernels import jit
from .lsf import ROOT_GRID, WHITE_NOISE_CORRECTION, root_grid


@jit(fastmath={"reassoc", "contract"})
def _autocorrelation(frame: np.ndarray, r: np.ndarray) -> None:
    """``r[k] = sum_n x[n] x[n+k]`` for the lags ``k`` of ``r``, as ``lsf.autocorrelation`` (its
    sums reassociated: vectorised, equal to rounding)."""
    n = frame.shape[0]
    for k in range(r.shape[0]):
        acc = 0.0
        for i in range(n - k):
            acc += frame[i] * frame[i + k]
        r[k] = acc


@jit
def _levinson(r: np.ndarray, a: np.ndarray) -> None:
    """Levinson-Durbin on ``r[0..P]`` into ``a[0..P]`` (``a[0] = 1``), as ``lsf.levinson``."""
    order = a.shape[0] - 1
    prev = np.empty(order + 1)
    a[:] = 0.0
    a[0] = 1.0
    err = r[0]
    for i in range(1, order + 1):
        acc = 0.0
        for j in range(1, i):
            acc += a[j] * r[i - j]
        acc = r[i] + acc
        k = -acc / err if err > 0 else 0.0
        for j in range(1, i):
            prev[j] = a[j]
        for j in range(1, i):
            a[j] = prev[j] + k * prev[i - j]
        a[i] = k
        err = err * (1.0 - k * k)


@jit
def _bracket(c: np.ndarray, basis: np.ndarray, values: np.ndarray, xg: np.ndarray, cr: np.ndarray,
             x: np.ndarray, lo: np.ndarray, hi: np.ndarray, neg_lo: np.ndarray, at: int) -> bool:
    """The grid step of ``lsf.chebyshev_real_roots`` for Chebyshev series ``c``: its values on
    ``x = cos w`` (``basis``), one root per sign change, each root's bracket ``[lo, hi]`` and
    regula falsi start ``x`` and the series' coefficients ``cr[:, root]``, for the roots
    ``at .. at + m - 1``; ``False`` when there are not ``m`` sign changes."""
    m = c.shape[0] - 1
    grid = xg.shape[0] - 1
    values[:] = 0.0
    for k in range(m + 1):
        ck = c[k]
        for j in range(grid + 1):
            values[j] += ck * basis[k, j]
    found = 0
    for j in range(grid):
        if (values[j] < 0) != (values[j + 1] < 0):
            found += 1
    if found != m:
        return False
    slot = at
    for j in range(grid):
        f_lo, f_hi = values[j + 1], values[j]
        if (f_lo < 0) == (f_hi < 0):
            continue
        lo[slot], hi[slot] = xg[j + 1], xg[j]             # x descends as w ascends
        x[slot] = lo[slot] + (hi[slot] - lo[slot]) * (f_lo / (f_lo - f_hi))
        neg_lo[slot] = f_lo < 0
        cr[:, slot] = c
        slot += 1
    return True


@jit
def _polish(cr: np.ndarray, x: np.ndarray, lo: np.ndarray, hi: np.ndarray, neg_lo: np.ndarray,
            b1: np.ndarray, b2: np.ndarray, d1: np.ndarray, d2: np.ndarray, done: np.ndarray,
            tol: float, max_iter: int) -> bool:
    """Newton's method on every root at once (Clenshaw values and derivatives of its series
    ``cr[:, root]``, bisection when a step leaves the bracket), as
    ``lsf.chebyshev_real_roots``: a root leaves the iteration after a step below ``tol``;
    ``False`` when one is not polished in ``max_iter`` steps. ``b1 .. d2``: scratch."""
    m = cr.shape[0] - 1
    n = x.shape[0]
    done[:] = False
    left = n
    for _ in range(max_iter):
        for r in range(n):                          # Clenshaw, the roots side by side
            b1[r], b2[r], d1[r], d2[r] = cr[m, r], 0.0, 0.0, 0.0
        for k in range(m - 1, 0, -1):
            for r in range(n):
                x2 = 2.0 * x[r]
                nd = 2.0 * b1[r] + x2 * d1[r] - d2[r]
                d2[r] = d1[r]
                d1[r] = nd
                nb = cr[k, r] + x2 * b1[r] - b2[r]
                b2[r] = b1[r]
                b1[r] = nb
        for r in range(n):
            if done[r]:
                continue
            f = cr[0, r] + x[r] * b1[r] - b2[r]
            fp = b1[r] + x[r] * d1[r] - d2[r]
            if (f < 0) == neg_lo[r]:
                lo[r] = x[r]
            else:
                hi[r] = x[r]
            step = f / fp
            new = x[r] - step
            if abs(step) <= tol:
                done[r] = True
                left -= 1
                x[r] = new
            elif new >= lo[r] and new <= hi[r]:
                x[r] = new
            else:
                x[r] = 0.5 * (lo[r] + hi[r])
        if left == 0:
            return True
    return False


@jit
def _frame_series(a: np.ndarray, g: np.ndarray, cp: np.ndarray, cq: np.ndarray) -> None:
    """The Chebyshev series of P(z) and Q(z) of LPC polynomial ``a``, trivial roots divided out,
    as ``lsf._sum_difference`` and ``lsf.lsf_chebyshev_series``."""
    order = a.shape[0] - 1
    half = order // 2
    for c, sign in ((cp, -1.0), (cq, 1.0)):
        for k in range(order + 1):                 # P or Q coefficient k, a extended by a zero
            ext = a[k] if k <= order else 0.0
            rev = a[order + 1 - k] if order + 1 - k <= order else 0.0
            poly = ext + rev if sign < 0 else ext - rev
            g[k] = poly if k == 0 else poly + sign * g[k - 1]
        c[0] = g[half]
        for k in range(1, half + 1):
            c[k] = 2.0 * g[half - k]


@jit
def lsf_frames(pad: np.ndarray, starts: np.ndarray, window: np.ndarray, order: int,
               xg: np.ndarray, basis: np.ndarray, tol: float, max_iter: int
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """LSF vectors ``(T, P)`` of the frames ``pad[s:s + n] * window`` (``s`` in ``starts``), their
    LPC polynomials ``(T, P+1)`` and whether each frame's roots were found (else its LSFs are
    NaN: compute them from its LPC polynomial by the reference).

    Per frame: the autocorrelation lags 0..P (the white-noise correction on lag 0, an all-zero
    frame's lag 0 set to 1), Levinson-Durbin, and the roots of P(z) and Q(z), sorted."""
    n = window.shape[0]
    n_frames = starts.shape[0]
    half = order // 2
    lsf = np.empty((n_frames, order))
    polys = np.empty((n_frames, order + 1))
    ok = np.ones(n_frames, dtype=np.bool_)
    frame = np.empty(n)
    r = np.empty(order + 1)
    g = np.empty(order + 1)
    cp = np.empty(half + 1)
    cq = np.empty(half + 1)
    values = np.empty(xg.shape[0])
    cr = np.empty((half + 1, order))
    x, lo, hi = np.empty(order), np.empty(order), np.empty(order)
    neg_lo, done = np.empty(order, dtype=np.bool_), np.empty(order, dtype=np.bool_)
    b1, b2, d1, d2 = np.empty(order), np.empty(order), np.empty(order), np.empty(order)
    for t in range(n_frames):
        s = starts[t]
        for i in range(n):
            frame[i] = pad[s + i] * window[i]
        _autocorrelation(frame, r)
        r[0] *= 1.0 + WHITE_NOISE_CORRECTION
        if not r[0] > 0:
            r[0] = 1.0
        a = polys[t]
        _levinson(r, a)
        _frame_series(a, g, cp, cq)
        row = lsf[t]
        if not (_bracket(cp, basis, values, xg, cr, x, lo, hi, neg_lo, 0)
                and _bracket(cq, basis, values, xg, cr, x, lo, hi, neg_lo, half)
                and _polish(cr, x, lo, hi, neg_lo, b1, b2, d1, d2, done, tol, max_iter)):
            ok[t] = False
            row[:] = np.nan
            continue
        for k in range(order):
            row[k] = np.arccos(min(max(x[k], -1.0), 1.0))
        row.sort()
    return lsf, polys, ok


def warm_up() -> None:
    """Run the kernel once on a tiny input (loads or compiles it)."""
    xg, basis = root_grid(9, ROOT_GRID)
    lsf_frames(np.sin(np.arange(64.0)), np.array([0, 8]), np.hamming(32), 18, xg,
               np.ascontiguousarray(basis), 1e-9, 12)
