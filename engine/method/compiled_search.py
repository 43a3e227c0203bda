"""The acoustic-only candidate search compiled by numba: the LSF index's search for the codewords
nearest by eq 5, frame by frame in one loop. The reference is
``facetraj_engine.method.lsf_index.LsfIndex.nearest``: the same distances, in the same float32, tested
to choose the same codewords (``tests/test_kernels.py``).

Per frame: eq 5's weights ``h``, the weighted absolute distance to every cell centroid, the
``probe`` nearest cells opened, the distance to each of their codewords, and the ``count``
smallest kept by a selection (the ``count``-th smallest value, then the codewords at or below
it, in the opened cells' order). The reference sums each distance's 18 terms by a BLAS matrix
product, this kernel in LSF order: the two differ by float32 rounding, so a codeword at the
edge of the ``count`` chosen can differ when two distances are equal to float32 rounding (no
frame of 60 s of the default corpus's test speech).

Imported only through :mod:`facetraj_engine.method.kernels` (it imports numba).
"""

from __future__ import annotations

import numpy as np

from .kernels import jit


@jit
def _weights32(w: np.ndarray, h: np.ndarray, wc: np.ndarray) -> None:
    """Eq 5's weights of LSF vector ``w`` (as ``synthesis.perceptual_weights``, in float64) and
    ``w`` itself, both rounded to float32 into ``h`` and ``wc``."""
    p = w.shape[0]
    for k in range(p):
        left = w[k] - (w[k - 1] if k > 0 else 0.0)
        right = (w[k + 1] if k < p - 1 else np.pi) - w[k]
        h[k] = np.float32(1.0 / max(min(left, right), 1e-6))
        wc[k] = np.float32(w[k])


@jit
def _distances(h: np.ndarray, wc: np.ndarray, cols: np.ndarray, lo: int, out: np.ndarray) -> None:
    """Eq 5 in float32 from ``wc`` (weights ``h``) to the columns ``lo:lo + len(out)`` of
    ``cols`` (``(P, n)``, C order) into ``out``: ``sum_k h_k |w_k - L_k|``, the terms added in
    LSF order."""
    out[:] = np.float32(0.0)
    for k in range(cols.shape[0]):
        hk, wk = h[k], wc[k]
        col = cols[k, lo:lo + out.shape[0]]
        for j in range(out.shape[0]):
            out[j] += hk * abs(wk - col[j])


@jit
def _kth_smallest(v: np.ndarray, kth: int) -> np.float32:
    """The ``kth`` smallest (from 0) of ``v``, which it reorders: Hoare's selection."""
    lo, hi = 0, v.shape[0] - 1
    while lo < hi:
        pivot = v[(lo + hi) // 2]
        i, j = lo, hi
        while i <= j:
            while v[i] < pivot:
                i += 1
            while v[j] > pivot:
                j -= 1
            if i <= j:
                v[i], v[j] = v[j], v[i]
                i += 1
                j -= 1
        if kth <= j:
            hi = j
        elif kth >= i:
            lo = i
        else:
            break
    return v[kth]


@jit
def _kth_value(d: np.ndarray, kth: int, scratch: np.ndarray) -> np.float32:
    """The ``kth`` smallest (from 0) of ``d``: the values counted into 256 bins between their
    least and greatest (a monotone binning, so the ``kth`` lies in the bin where the counts
    reach it), then :func:`_kth_smallest` among that bin's values only."""
    lo, hi = d.min(), d.max()
    if not hi > lo:
        return lo
    bins = 256
    scale = bins / (np.float64(hi) - np.float64(lo))
    counts = np.zeros(bins + 1, dtype=np.int64)
    for j in range(d.shape[0]):
        counts[min(int((np.float64(d[j]) - lo) * scale), bins - 1)] += 1
    below, b = 0, 0
    while below + counts[b] <= kth:
        below += counts[b]
        b += 1
    n = 0
    for j in range(d.shape[0]):
        if min(int((np.float64(d[j]) - lo) * scale), bins - 1) == b:
            scratch[n] = d[j]
            n += 1
    return _kth_smallest(scratch[:n], kth - below)


@jit
def _first_smallest(d: np.ndarray, count: int, keep: np.ndarray, scratch: np.ndarray) -> None:
    """The places of the ``count`` smallest of ``d`` into ``keep``, as ``lsf_index._smallest``:
    the ``count``-th smallest value, then the places at or below it, the first ones (the
    nearest alone: the first smallest)."""
    width = d.shape[0]
    if count == 1:
        best = 0
        for j in range(1, width):
            if d[j] < d[best]:
                best = j
        keep[0] = best
        return
    if count >= width:
        for j in range(width):
            keep[j] = j
        return
    kth = _kth_value(d, count - 1, scratch)
    n = 0
    for j in range(width):
        if d[j] <= kth:
            keep[n] = j
            n += 1
            if n == count:
                break


@jit
def _nearest_cells(dc: np.ndarray, probe: int, opened: np.ndarray) -> None:
    """The ``probe`` cells of smallest distance ``dc`` into ``opened``, nearest first (of equal
    distances, the lower cell first)."""
    n = 0
    for c in range(dc.shape[0]):
        if n == probe and not dc[c] < dc[opened[n - 1]]:
            continue
        i = min(n, probe - 1)
        while i > 0 and dc[c] < dc[opened[i - 1]]:
            opened[i] = opened[i - 1]
            i -= 1
        opened[i] = c
        n = min(n + 1, probe)


@jit
def nearest_frames(w: np.ndarray, centroids: np.ndarray, cell_lsf: np.ndarray,
                   offsets: np.ndarray, order: np.ndarray, count: int, probe: int) -> np.ndarray:
    """``LsfIndex.nearest`` of LSF vectors ``w`` (``(T, P)``, float64): ``(T, count)`` codebook
    indices, ascending. ``centroids`` ``(P, C)`` and ``cell_lsf`` ``(P, 5L)`` (the codebook
    grouped by cell, ``order[offsets[c]:offsets[c + 1]]``) in float32; ``count`` and ``probe``
    as the reference adjusts them (``count`` at most the members of ``probe`` cells)."""
    n_frames, p = w.shape
    n_cells = centroids.shape[1]
    sizes = offsets[1:] - offsets[:-1]
    width_max = np.sort(sizes)[n_cells - probe:].sum()
    out = np.empty((n_frames, count), dtype=np.int64)
    h = np.empty(p, dtype=np.float32)
    wc = np.empty(p, dtype=np.float32)
    dc = np.empty(n_cells, dtype=np.float32)
    d = np.empty(width_max, dtype=np.float32)
    ids = np.empty(width_max, dtype=np.int64)
    keep = np.empty(count, dtype=np.int64)
    scratch = np.empty(width_max, dtype=np.float32)
    opened = np.empty(probe, dtype=np.int64)
    for t in range(n_frames):
        _weights32(w[t], h, wc)
        _distances(h, wc, centroids, 0, dc)
        _nearest_cells(dc, probe, opened)
        width = 0
        for c in opened:
            lo, hi = offsets[c], offsets[c + 1]
            _distances(h, wc, cell_lsf, lo, d[width:width + hi - lo])
            ids[width:width + hi - lo] = order[lo:hi]
            width += hi - lo
        _first_smallest(d[:width], count, keep, scratch)
        row = out[t]
        for i in range(count):
            row[i] = ids[keep[i]]
        row.sort()
    return out


def warm_up() -> None:
    """Run the kernel once on a tiny input (loads or compiles it)."""
    lsf = np.sort(np.random.default_rng(0).uniform(0.1, 3.0, (12, 4)), axis=1)
    nearest_frames(lsf[:2], np.ascontiguousarray(lsf[:3].T, dtype=np.float32),
                   np.ascontiguousarray(lsf.T, dtype=np.float32), np.array([0, 4, 8, 12]),
                   np.arange(12), 5, 2)


@jit
def _winnable(u: int, centres: np.ndarray, s: np.ndarray, bound: float, count: int,
              out: np.ndarray) -> int:
    """The codebook contexts a query of centre phone ``u`` can pick (eq 4's bound, as
    ``similarity.top_context_phones``; ``centres`` the codebook contexts' centre phones),
    ascending, into ``out``; their number."""
    row = s[u]
    best, reach = -np.inf, 0
    for j in range(centres.shape[0]):
        v = row[centres[j]]
        if v > best:
            best, reach = v, 1
        elif v == best:
            reach += 1
    low = best - bound - 1e-12
    n = 0
    for j in range(centres.shape[0]):
        if reach < count or row[centres[j]] >= low:
            out[n] = j
            n += 1
    return n


@jit
def top_context_scores(q: np.ndarray, codebook: np.ndarray, s: np.ndarray, tables: np.ndarray,
                       cols: np.ndarray, bound: float, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Eq 4's ``count`` best codebook contexts of each query (row of ``q``), best first, of
    equal scores the lower index first, as ``similarity.top_context_phones``: a query is scored
    against the contexts its centre phone can pick (:func:`_winnable`, found once per centre),
    each score the terms ``tables[j, q[i, cols[j]], codebook[l, cols[j]]]`` (``xi^-i S``) added
    in column order."""
    n_q, n_cb = q.shape[0], codebook.shape[0]
    full = (q.shape[1] - 1) // 2
    top = np.empty((n_q, count), dtype=np.int64)
    best = np.empty((n_q, count))
    found = np.full(s.shape[0], -1, dtype=np.int64)        # centre phone -> its row of winnable
    winnable = np.empty((min(s.shape[0], n_q), n_cb), dtype=np.int64)
    sizes = np.empty(winnable.shape[0], dtype=np.int64)
    centres = codebook[:, full].copy()
    rows = 0
    for i in range(n_q):
        u = q[i, full]
        if found[u] < 0:
            found[u] = rows
            sizes[rows] = _winnable(u, centres, s, bound, count, winnable[rows])
            rows += 1
        cand = winnable[found[u], :sizes[found[u]]]
        filled = 0
        for ctx in cand:
            n = tables[0, q[i, cols[0]], codebook[ctx, cols[0]]]
            for j in range(1, cols.shape[0]):
                n += tables[j, q[i, cols[j]], codebook[ctx, cols[j]]]
            if filled == count and not n > best[i, count - 1]:
                continue
            slot = min(filled, count - 1)
            while slot > 0 and n > best[i, slot - 1]:       # after the equal ones: lower index
                best[i, slot] = best[i, slot - 1]
                top[i, slot] = top[i, slot - 1]
                slot -= 1
            best[i, slot] = n
            top[i, slot] = ctx
            filled = min(filled + 1, count)
    return top, best
