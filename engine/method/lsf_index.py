"""A coarse index over the codebook's LSF vectors, for acoustic-only synthesis.

Acoustic-only synthesis (paper section 2.3, no labels) scores every frame against the whole
codebook by eq 5, which costs time linear in its size 5L. The index is built once at training: a
k-means partition of the codeword LSF vectors into about ``sqrt(5L)`` cells. At synthesis a frame
ranks the cell centroids by eq 5's perceptually weighted distance, opens the ``probe`` nearest
cells and keeps the ``count`` codewords nearest by eq 5 among their members; eqs 6-8 then run on
those only. The work per frame grows with the number of cells plus the members of the opened
cells, about ``sqrt(5L)`` each, instead of 5L (an inverted-file search; Jegou et al. 2011).
``docs/algorithm.md`` gives the measured accuracy cost against the full search.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from .synthesis import perceptual_weights

log = logging.getLogger(__name__)


def kmeans(x: np.ndarray, n_clusters: int, iterations: int = 10,
           seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Lloyd's k-means in the Euclidean metric, started from ``n_clusters`` distinct data points
    drawn with ``numpy.random.default_rng(seed)``; a cell left empty keeps its centroid.

    Returns ``(centroids (C, P), labels (n,))``.

    Examples
    --------
    >>> x = np.array([[0.0], [0.1], [0.2], [5.0], [5.1]])
    >>> c, labels = kmeans(x, 2)
    >>> sorted(np.round(c[:, 0], 2).tolist()), labels[0] != labels[-1]
    ([0.1, 5.05], np.True_)
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    if not 1 <= n_clusters <= n:
        raise ValueError(f"n_clusters must be between 1 and {n}, got {n_clusters}")
    rng = np.random.default_rng(seed)
    centroids = x[rng.choice(n, n_clusters, replace=False)].copy()
    x2 = np.einsum("ij,ij->i", x, x)
    # |x|^2 - 2 x.c + |c|^2, the terms added in place a block of rows at a time: about 16,000
    # distances, which stay in the processor's cache (docs/benchmarks.md, corpus scaling);
    # scaling by -2 is exact, so the sums and the cells are the bits of the plain expression
    step = max(1, (1 << 14) // n_clusters)

    def assign(c: np.ndarray) -> np.ndarray:
        c2 = np.einsum("ij,ij->i", c, c)
        minus_2c = -2.0 * c.T
        labels = np.empty(n, dtype=np.intp)
        for i in range(0, n, step):
            d = x[i:i + step] @ minus_2c
            d += x2[i:i + step, None]
            d += c2
            labels[i:i + step] = d.argmin(axis=1)
        return labels

    labels = assign(centroids)
    for _ in range(iterations):
        counts = np.bincount(labels, minlength=n_clusters)
        sums = np.stack([np.bincount(labels, weights=col, minlength=n_clusters) for col in x.T], axis=1)
        filled = counts > 0
        centroids[filled] = sums[filled] / counts[filled, None]
        new = assign(centroids)
        if np.array_equal(new, labels):
            break
        labels = new
    return centroids, labels


@dataclass
class LsfIndex:
    """The coarse (inverted-file) index of a codebook's LSF vectors.

    Attributes
    ----------
    centroids : ``(C, P)`` cell centroids in LSF space (radians).
    order : ``(5L,)`` codebook indices sorted by cell; cell ``c`` holds
        ``order[offsets[c]:offsets[c + 1]]``.
    offsets : ``(C + 1,)`` start of each cell in ``order``.
    """

    centroids: np.ndarray
    order: np.ndarray
    offsets: np.ndarray
    #: the float32 grouped codebook of the last ``cb_lsf`` searched (kept with that array)
    _search_lsf: tuple[np.ndarray, np.ndarray] | None = field(default=None, init=False,
                                                             repr=False, compare=False)

    @property
    def n_cells(self) -> int:
        return int(self.centroids.shape[0])

    @property
    def n_codewords(self) -> int:
        return int(self.order.shape[0])

    @property
    def sizes(self) -> np.ndarray:
        return np.diff(self.offsets)

    def min_probe(self, count: int) -> int:
        """The fewest cells whose members are sure to number at least ``count``."""
        total = np.cumsum(np.sort(self.sizes))
        return int(min(np.searchsorted(total, count) + 1, self.n_cells))

    def grouped(self, cb_lsf: np.ndarray) -> np.ndarray:
        """The codebook LSFs ``cb_lsf`` grouped by cell (``cb_lsf[order]``), for callers that
        search a few frames at a time and pass it to :meth:`nearest` on every call."""
        return np.asarray(cb_lsf, dtype=np.float64)[self.order]

    def _cell_lsf(self, cb_lsf: np.ndarray, grouped: np.ndarray | None) -> np.ndarray:
        """:meth:`grouped` transposed, ``(P, 5L)``, in float32 for the search, made once per
        codebook array: a cell's codewords are the columns ``offsets[c]:offsets[c + 1]``."""
        if self._search_lsf is None or self._search_lsf[0] is not cb_lsf:
            cells = (self.layout(cb_lsf) if grouped is None else
                     np.ascontiguousarray(np.asarray(grouped, dtype=np.float32).T))
            self._search_lsf = (cb_lsf, cells)
        return self._search_lsf[1]

    def layout(self, cb_lsf: np.ndarray) -> np.ndarray:
        """The search layout of ``cb_lsf``: :meth:`grouped`, transposed to ``(P, 5L)``, float32;
        made in two passes over the codebook (to float32, then taken in cell order)."""
        return np.take(np.asarray(cb_lsf).T.astype(np.float32), self.order, axis=1)

    def nearest(self, w: np.ndarray, cb_lsf: np.ndarray, count: int, probe: int,
                chunk: int | None = None, grouped: np.ndarray | None = None,
                first: np.ndarray | None = None) -> np.ndarray:
        """The ``count`` codewords nearest to each frame by eq 5, among the members of the
        ``probe`` cells whose centroids are nearest by eq 5; ``(T, count)`` codebook indices,
        ascending.

        ``w`` is ``(T, P)`` input LSFs, ``cb_lsf`` the codebook the index was built on. ``probe``
        is raised when the opened cells could hold fewer than ``count`` codewords; probing every
        cell finds the exact nearest. The distances are computed cell by cell, for all the frames
        of a chunk that open the cell at once, so the cell's codewords are a slice, not a gather,
        laid out ``(P, size)`` so that the innermost loops run along the cell's codewords, and in
        float32 (half the memory traffic of the search's largest arrays; the distances only rank
        the codewords: eqs 5-8 are computed again in float64 on the ``count`` found). ``grouped``
        may pass :meth:`grouped` of ``cb_lsf``, computed once. ``first`` ``(T,)``: where to write
        each frame's nearest of those distances, what ``count=1`` finds when it probes as many
        cells (:meth:`probes`).

        Examples
        --------
        >>> lsf = np.sort(np.random.default_rng(2).uniform(0.1, 3.0, (500, 6)), axis=1)
        >>> ix = build_index(lsf)
        >>> w = lsf[[7, 300]] + 0.001
        >>> ix.nearest(w, lsf, count=1, probe=3)[:, 0].tolist()
        [7, 300]
        """
        if cb_lsf.shape[0] != self.n_codewords:
            raise ValueError(f"the index covers {self.n_codewords} codewords, the codebook has "
                             f"{cb_lsf.shape[0]}: rebuild it (build_index)")
        count = min(count, self.n_codewords)
        probe = self.probes(count, probe)
        cell_lsf = self._cell_lsf(cb_lsf, grouped)                        # (P, 5L) by cell
        return self._search(w, cell_lsf, count, probe, chunk, first)

    def probes(self, count: int, probe: int) -> int:
        """The cells :meth:`nearest` opens for ``count`` codewords when asked for ``probe``."""
        return min(max(probe, self.min_probe(min(count, self.n_codewords))), self.n_cells)

    def _search(self, w: np.ndarray, cell_lsf: np.ndarray, count: int, probe: int,
                chunk: int | None, first: np.ndarray | None = None) -> np.ndarray:
        """:meth:`nearest`, chunk by chunk of frames."""
        n_frames, order = w.shape[0], w.shape[1]
        width_max = int(np.sort(self.sizes)[-probe:].sum())
        chunk = chunk or max(1, min(1024, int(4e6 // max(self.n_cells * order, width_max))))
        out = np.empty((n_frames, count), dtype=np.int64)
        centroids = np.ascontiguousarray(self.centroids.T, dtype=np.float32)     # (P, C)
        for a in range(0, n_frames, chunk):
            b = min(a + chunk, n_frames)
            d, cells, ends = self._distances(w[a:b], cell_lsf, centroids, probe)
            out[a:b] = self._codewords(_smallest(d, count, ends[:, -1]), cells, ends)
            if first is not None:
                first[a:b] = self._codewords(d.argmin(axis=1)[:, None], cells, ends)[:, 0]
        out.sort(axis=1)            # in codebook order: the same whatever frames share a call
        return out

    def _distances(self, w: np.ndarray, cell_lsf: np.ndarray, centroids: np.ndarray, probe: int
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Eq 5 from each frame of ``w`` ``(t, P)`` to the members of its ``probe`` nearest cells
        ``(t, width)``: row t holds its cells ``cells[t]`` side by side, each a block ending at
        ``ends[t, slot]``, then inf; the cells and the ends."""
        order, sizes = w.shape[1], self.sizes
        h = perceptual_weights(np.asarray(w, dtype=np.float64)).astype(np.float32)
        wc = np.asarray(w, dtype=np.float32)                                     # eq 5
        dc = np.empty((len(w), self.n_cells), dtype=np.float32)                 # eq 5, (t, C)
        step = max(1, int(CENTROID_BLOCK // (order * self.n_cells)))
        near = np.empty(min(step, len(w)) * order * self.n_cells, dtype=np.float32)
        for a in range(0, len(w), step):             # a few frames at a time, in one buffer
            b = min(a + step, len(w))
            diff = abs_differences(wc[a:b], centroids, near[:(b - a) * order * self.n_cells]
                                   .reshape(b - a, order, self.n_cells))
            np.matmul(h[a:b, None, :], diff, out=dc[a:b, None, :])
        cells = (np.argpartition(dc, probe - 1, axis=1)[:, :probe] if probe < self.n_cells
                 else np.broadcast_to(np.arange(self.n_cells), dc.shape))
        sz = sizes[cells]                                                        # (t, probe)
        ends = np.cumsum(sz, axis=1)                   # each opened cell's block in its row ends
        width = int(ends[:, -1].max())
        # row t: its cells side by side; a cell's block starts at t * width + its start in the row
        at = (np.arange(len(w))[:, None] * width + ends - sz).ravel()
        # d, then as many values more as the largest cell: every row of ``runs`` below is in it
        widest = int(sizes.max())
        padded = np.full(len(w) * width + widest, np.inf, dtype=np.float32)
        d = padded[:len(w) * width]
        # d's runs of the largest cell's length, one starting at each value: a frame's block of
        # a cell is the start of the run at its place in d (written a row at a time, not a
        # value at a time through indices)
        runs = np.lib.stride_tricks.as_strided(padded, (len(d), widest),
                                               (padded.itemsize, padded.itemsize))
        flat = cells.ravel()
        by_cell = np.argsort(flat, kind="stable")
        bounds = np.searchsorted(flat[by_cell], np.arange(self.n_cells + 1))
        offsets, bounds = self.offsets.tolist(), bounds.tolist()          # Python ints: cheap
        opened = np.flatnonzero((np.diff(bounds) > 0) & (sizes > 0)).tolist()
        # one buffer for every cell's (f, P, size) differences: a block's memory is written again
        # while the processor still holds it, not taken new from the allocator for each cell
        most = max((min(bounds[c + 1] - bounds[c], max(1, int(BLOCK // (sizes[c] * order))))
                    * sizes[c] for c in opened), default=0)
        buffer = np.empty(int(most) * order, dtype=np.float32)
        for c in opened:
            lo, hi = offsets[c], offsets[c + 1]
            step = max(1, int(BLOCK // ((hi - lo) * order)))     # bound the (f, P, size) temporary
            for r0 in range(bounds[c], bounds[c + 1], step):
                pairs = by_cell[r0:min(r0 + step, bounds[c + 1])]
                rows = pairs // probe
                diff = abs_differences(wc[rows], cell_lsf[:, lo:hi], buffer[:len(rows) * order * (
                    hi - lo)].reshape(len(rows), order, hi - lo))                # (f, P, size)
                block = np.matmul(h[rows, None, :], diff)[:, 0]                  # eq 5, (f, size)
                runs[at[pairs], :hi - lo] = block
        return d.reshape(len(w), width), cells, ends

    def _codewords(self, cols: np.ndarray, cells: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """The codebook indices of columns ``cols`` ``(t, k)`` of :meth:`_distances`' rows: the
        block ends of all rows, each row shifted by its offset, ascend, so one search finds
        every column's cell, then its place in it."""
        rows = np.arange(len(cols))[:, None]
        width = int(ends[:, -1].max())
        probe = cells.shape[1]
        slot = np.searchsorted((ends + rows * width).ravel(), (cols + rows * width).ravel(),
                               side="right").reshape(cols.shape) - rows * probe
        sz = self.sizes[cells]
        within = cols - (ends - sz)[rows, slot]
        return self.order[self.offsets[cells[rows, slot]] + within]


def abs_differences(w: np.ndarray, lsf: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``|w_k - L_ik|`` (eq 5) of frames ``w`` ``(f, P)`` and LSF vectors ``lsf`` ``(P, I)``, in
    ``out`` ``(f, P, I)``: each frame's ``w_k`` laid along the vectors, then ``lsf`` taken from
    each frame's values as one flat row. The values of ``abs(w[:, :, None] - lsf)``, which numpy
    computes a row of ``I`` at a time (0.5 ns a value against 0.3 here, I = 150).

    >>> w = np.array([[1.0, 2.0]], dtype=np.float32)
    >>> lsf = np.array([[0.5, 1.5, 3.0], [2.0, 1.0, 2.5]], dtype=np.float32)
    >>> abs_differences(w, lsf, np.empty((1, 2, 3), np.float32)).tolist()
    [[[0.5, 0.5, 2.0], [0.0, 1.0, 0.5]]]
    """
    np.copyto(out, w[:, :, None])
    flat = out.reshape(len(w), -1)
    np.subtract(flat, lsf.ravel(), out=flat)
    np.abs(out, out=out)
    return out


#: the most values of one block of eq 5's differences in :meth:`LsfIndex._distances` (16 MB)
BLOCK = 4e6
#: the most values of one block of eq 5's differences to the cell centroids (256 kB: a block
#: stays in the processor's cache through its three passes)
CENTROID_BLOCK = 6.4e4

#: rows of a search grouped by their number of values, for the partition (:func:`_smallest`)
WIDTH_GROUPS = 4


def _smallest(d: np.ndarray, count: int, widths: np.ndarray | None = None) -> np.ndarray:
    """Columns of the ``count`` smallest values of each row of ``d``, ascending (of equal values
    at the edge, the first columns): the ``count``-th smallest value of each row by a partition
    (values only: faster than ``argpartition``), then the columns at or below it. ``widths``:
    each row's values are its first ``widths[t]`` (at least ``count``; the rest inf, left out):
    the rows are taken in :data:`WIDTH_GROUPS` groups of like widths, each as wide as its widest.

    >>> _smallest(np.array([[5.0, 1.0, 3.0, 1.0], [0.0, 9.0, 9.0, 9.0]]), 2).tolist()
    [[1, 3], [0, 1]]
    >>> _smallest(np.array([[5.0, 1.0, 3.0, 1.0], [9.0, 9.0, 0.0, 0.0]]), 1).tolist()
    [[1], [2]]
    >>> _smallest(np.array([[5.0, 1.0, 3.0, 1.0], [9.0, 0.0, np.inf, np.inf]]), 2, [4, 2]).tolist()
    [[1, 3], [0, 1]]
    >>> _smallest(np.array([[3.0, 3.0, 3.0, 1.0], [2.0, 2.0, 0.0, 2.0]]), 2).tolist()
    [[0, 3], [0, 2]]
    """
    rows, width = d.shape
    if count >= width:
        return np.broadcast_to(np.arange(width), (rows, width))
    if count == 1:                    # the nearest alone (the voice match): the first smallest
        return d.argmin(axis=1)[:, None]
    if widths is not None and rows >= 2 * WIDTH_GROUPS:
        out = np.empty((rows, count), dtype=np.int64)
        by_width = np.argsort(widths, kind="stable")
        for group in np.array_split(by_width, WIDTH_GROUPS):
            out[group] = _smallest(d[group, :int(np.max(widths[group]))], count)
        return out
    kth = np.partition(d, count - 1, axis=1)[:, count - 1]
    at = np.flatnonzero(d <= kth[:, None])                     # flat: faster than row and column
    if len(at) > rows * count:          # ties at the edge: all below it, the first ones at it
        r = at // width
        edge = d.ravel()[at] == kth[r]
        first = np.searchsorted(r[edge], np.arange(rows))       # each row's first at the edge
        rank = np.zeros(len(at), dtype=np.int64)
        rank[edge] = np.arange(int(edge.sum())) - first[r[edge]]
        below = np.bincount(r[~edge], minlength=rows)
        at = at[~edge | (rank < count - below[r])]
    return at.reshape(rows, count) - np.arange(0, rows * width, width)[:, None]


def default_cells(n_codewords: int) -> int:
    """The default number of cells: ``round(sqrt(5L))``, at least 1."""
    return max(1, int(round(np.sqrt(n_codewords))))


def build_index(cb_lsf: np.ndarray, n_cells: int | None = None, iterations: int = 10,
                seed: int = 0) -> LsfIndex:
    """Partition the codebook LSFs ``(5L, P)`` into ``n_cells`` k-means cells (default
    ``round(sqrt(5L))``) and return the index.

    Examples
    --------
    >>> lsf = np.sort(np.random.default_rng(1).uniform(0.1, 3.0, (400, 4)), axis=1)
    >>> ix = build_index(lsf)
    >>> ix.n_cells, int(ix.sizes.sum()), sorted(ix.order.tolist()) == list(range(400))
    (20, 400, True)
    """
    cb_lsf = np.asarray(cb_lsf, dtype=np.float64)
    n = cb_lsf.shape[0]
    n_cells = min(n_cells or default_cells(n), n)
    centroids, labels = kmeans(cb_lsf, n_cells, iterations, seed)
    order = np.argsort(labels, kind="stable")
    offsets = np.concatenate([[0], np.cumsum(np.bincount(labels, minlength=n_cells))])
    log.debug("LSF index: %d codewords in %d cells (largest %d)", n, n_cells, np.diff(offsets).max())
    return LsfIndex(centroids, order.astype(np.int64), offsets.astype(np.int64))
