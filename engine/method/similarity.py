"""The visual phoneme similarity matrix (paper section 2.2, eqs 1-3) and context-phone similarity
(eq 4).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .context_index import ContextIndex


def phone_means(pcs: np.ndarray, phone_of: np.ndarray, n_phones: int) -> np.ndarray:
    """Eq 1: ``m_k = (1/T_k) sum_t P_kt``, the mean PC vector of each phone.

    ``pcs`` is ``(T, K)`` PC vectors, ``phone_of`` ``(T,)`` the phone id each belongs to. Phones
    with no vector get NaN.

    Examples
    --------
    >>> phone_means(np.array([[1.0], [3.0], [10.0]]), np.array([0, 0, 1]), 2).ravel().tolist()
    [2.0, 10.0]
    """
    pcs = np.asarray(pcs, dtype=np.float64)
    sums = np.zeros((n_phones, pcs.shape[1]))
    np.add.at(sums, phone_of, pcs)
    counts = np.bincount(phone_of, minlength=n_phones).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return sums / counts[:, None]


def phone_distances(means: np.ndarray) -> np.ndarray:
    """Eq 2: ``D_ik = || m_i - m_k ||`` (Euclidean).

    Examples
    --------
    >>> phone_distances(np.array([[0.0, 0.0], [3.0, 4.0]])).tolist()
    [[0.0, 5.0], [5.0, 0.0]]
    """
    diff = means[:, None, :] - means[None, :, :]
    return np.sqrt((diff**2).sum(axis=-1))


def distance_scale(d: np.ndarray, rule: str = "max") -> float:
    """The normalisation divisor applied to D before eq 3.

    ``max``: the largest distance (normalised D in [0, 1]); ``median``: the median off-diagonal
    distance; ``none``: 1 (D in PC units, i.e. mm).
    """
    off = d[~np.eye(len(d), dtype=bool)]
    off = off[np.isfinite(off)]
    if rule == "none" or off.size == 0:
        return 1.0
    if rule == "max":
        return float(off.max())
    if rule == "median":
        return float(np.median(off))
    raise ValueError(f"unknown distance scale rule {rule!r}")


def similarity_matrix(d: np.ndarray, nu: float = 10.0, scale: float = 1.0) -> np.ndarray:
    """Eq 3: ``S_ik = exp(-nu D_ik / scale)``; values in (0, 1], 1 on the diagonal.

    Examples
    --------
    >>> np.round(similarity_matrix(np.array([[0.0, 0.1], [0.1, 0.0]]), nu=10), 4).tolist()
    [[1.0, 0.3679], [0.3679, 1.0]]
    """
    s = np.exp(-nu * np.asarray(d) / scale)
    return np.where(np.isfinite(s), s, 0.0)


@dataclass(frozen=True)
class SimilarRow:
    """One row of the paper's Table 1: a phone and its most similar phones."""

    phone: str
    neighbours: tuple[tuple[str, float], ...]


def top_similar(s: np.ndarray, phones: Sequence[str], k: int = 3,
                exclude: Sequence[str] = ("sil",)) -> list[SimilarRow]:
    """The ``k`` visually most similar phones of every phone (the paper's Table 1)."""
    keep = [i for i, p in enumerate(phones) if p not in exclude]
    rows = []
    for i in keep:
        cand = [j for j in keep if j != i]
        order = sorted(cand, key=lambda j: -s[i, j])[:k]
        rows.append(SimilarRow(phones[i], tuple((phones[j], float(s[i, j])) for j in order)))
    return rows


def format_table1(rows: Sequence[SimilarRow]) -> str:
    """Table 1 as plain text: ``Phoneme  Closest  2nd  3rd`` with similarity values."""
    k = max((len(r.neighbours) for r in rows), default=3)
    heads = ["Closest", "2nd", "3rd"] + [f"{i}th" for i in range(4, k + 1)]
    lines = ["Phoneme  " + "  ".join(f"{h:<10}" for h in heads[:k])]
    for r in rows:
        cells = "  ".join(f"{p:<4} {v:4.2f} " for p, v in r.neighbours)
        lines.append(f"{r.phone:<8} {cells}")
    return "\n".join(lines)


def context_weights(context: int, xi: float) -> np.ndarray:
    """The weights of eq 4 for columns ``[l_C .. l_1, c, r_1 .. r_C]``: ``xi^-i`` and 1 at c."""
    i = np.abs(np.arange(-context, context + 1)).astype(float)
    return xi ** (-i)


def context_similarity(query: np.ndarray, codebook: np.ndarray, s: np.ndarray, xi: float = 20.0,
                       context: int | None = None) -> np.ndarray:
    """Eq 4: ``n_j = S_cj + sum_i xi^-i S_l_ij + sum_i xi^-i S_r_ij`` for every codebook context.

    ``query`` is ``(Q, 2C+1)`` (or ``(2C+1,)``) phone ids, ``codebook`` ``(L, 2C+1)``; the result is
    ``(Q, L)`` (or ``(L,)``). ``context`` may be smaller than the stored C to use fewer neighbours.

    Examples
    --------
    >>> s = np.array([[1.0, 0.5], [0.5, 1.0]])
    >>> round(float(context_similarity(np.array([0, 0, 1]), np.array([[1, 0, 1]]), s, xi=10)[0]), 6)
    1.15
    """
    query = np.asarray(query)
    single = query.ndim == 1
    q = np.atleast_2d(query)
    full = (q.shape[1] - 1) // 2
    c = full if context is None else min(context, full)
    cols = np.arange(full - c, full + c + 1)
    w = context_weights(c, xi)
    n = np.zeros((q.shape[0], codebook.shape[0]))
    for col, weight in zip(cols, w, strict=True):
        n += weight * s[q[:, col][:, None], codebook[None, :, col]]
    return n[0] if single else n


def top_contexts(n: np.ndarray, count: int) -> np.ndarray:
    """Indices of the ``count`` largest ``n_j`` per row, best first (ties: lower index first)."""
    n = np.atleast_2d(n)
    count = min(count, n.shape[1])
    order = np.argsort(-n, axis=1, kind="stable")
    return order[:, :count]


def top_context_phones(query: np.ndarray, codebook: np.ndarray, s: np.ndarray, xi: float,
                       context: int | None, count: int, index: ContextIndex | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Eq 4 then :func:`top_contexts`, without scoring every codebook context for every query:
    the fast kernel of the pair (the reference).

    The context terms of eq 4 add at most ``B = 2 sum_i xi^-i`` (similarities are <= 1), so a
    codebook context whose centre similarity is below ``S_max - B`` (``S_max`` the query centre's
    best centre similarity in the codebook) can never outrank one whose centre reaches ``S_max``.
    Each query is scored only against the contexts that can win (all of them when fewer than
    ``count`` reach ``S_max``), every query at once: the pairs side by side in one flat array, each
    term ``xi^-i S`` looked up in a table of the weighted similarities and the terms added in
    :func:`context_similarity`'s order, so the scores are its scores to the bit; then the
    ``count``-th best score of each query (a partition) and a sort of the few scores reaching it.
    The result, including the lower-index-first tie order, is that of the full computation
    (tested). With a context (``context >= 1``) the contexts that can win are found by groups
    of the same centre and first neighbours (:mod:`facetraj_engine.method.context_index`): their
    number stops growing with the corpus, where the contexts of a centre phone grow with it.
    ``index``: the :class:`~facetraj_engine.method.context_index.ContextIndex` of ``codebook``
    over the phones of ``s`` when the caller keeps it (a model's, :attr:`Model.context_index`),
    else made here.

    Returns ``(top, scores)``, both ``(Q, count)``.

    >>> s = np.array([[1.0, 0.5], [0.5, 1.0]])
    >>> top, n = top_context_phones(np.array([[0, 0, 1]]), np.array([[1, 0, 1], [0, 0, 0]]), s,
    ...                             10.0, 1, 1)
    >>> top.tolist(), n.round(6).tolist()        # both score 1.15: the lower index first
    ([[0]], [[1.15]])
    """
    q = np.atleast_2d(np.asarray(query))
    n_q, n_cb, n_ph = q.shape[0], codebook.shape[0], s.shape[0]
    full = (q.shape[1] - 1) // 2
    c = full if context is None else min(context, full)
    bound = 2.0 * sum(xi ** (-i) for i in range(1, c + 1))
    count = min(count, n_cb)
    cols = np.arange(full - c, full + c + 1)
    tables = context_weights(c, xi)[:, None, None] * s                       # (2c+1) x n x n
    if n_q > 0 and c >= 1:                        # the contexts that can win, by groups
        rest = 2.0 * sum(xi ** (-i) for i in range(2, c + 1))
        index = ContextIndex.of(codebook, n_ph) if index is None else index
        rows, cand = index.candidates(q, s, xi ** -1.0, bound, rest, count)
        return _best(q, codebook, rows, cand, tables, cols, count)
    # the contexts that can win, per distinct query centre u: cand_all[u_start[u]:][:u_size[u]]
    centres, inverse = np.unique(q[:, full], return_inverse=True)
    sim = s[centres][:, codebook[:, full]]                                  # (U, L)
    best = sim.max(axis=1, keepdims=True)
    keep = sim >= best - bound - 1e-12
    keep[np.count_nonzero(sim >= best, axis=1) < count] = True
    u_size = np.count_nonzero(keep, axis=1)
    u_start = np.cumsum(u_size) - u_size
    cand_all = np.nonzero(keep)[1]
    sizes = u_size[inverse]
    rows = np.repeat(np.arange(n_q), sizes)
    place = np.arange(sizes.sum()) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    cand = cand_all[np.repeat(u_start[inverse], sizes) + place]
    return _best(q, codebook, rows, cand, tables, cols, count)


def _best(q: np.ndarray, codebook: np.ndarray, rows: np.ndarray, cand: np.ndarray,
          tables: np.ndarray, cols: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` best of each query among the (query ``rows[p]``, context ``cand[p]``) pairs
    (by query, each query's in increasing context order): eq 4's terms ``xi^-i S`` looked up in
    ``tables`` and added column by column, as :func:`context_similarity` adds them (its scores
    to the bit), then the ``count``-th best score of each query (a partition) and a sort of the
    few scores reaching it (ties: lower index first)."""
    n_q, n_ph = q.shape[0], tables.shape[1]
    sizes = np.bincount(rows, minlength=n_q)
    starts = np.cumsum(sizes) - sizes
    place = np.arange(len(rows)) - np.repeat(starts, sizes)                 # within its query
    flat = tables.ravel()
    at = np.take(q.T[cols] * n_ph + (np.arange(len(cols)) * n_ph * n_ph)[:, None], rows, axis=1)
    at += np.take(codebook.T[cols], cand, axis=1)
    terms = flat.take(at)
    n = terms[0].copy()
    for term in terms[1:]:
        n += term
    width = int(sizes.max())
    grid = np.full((n_q, width), -np.inf)
    grid.ravel()[rows * width + place] = n
    kth = np.partition(grid, width - count, axis=1)[:, width - count]
    r, k = np.nonzero(grid >= kth[:, None])                                # ties included
    order = np.lexsort((k, -grid[r, k], r))                # by query, best first, lower index first
    r, k = r[order], k[order]
    k = k[np.searchsorted(r, np.arange(n_q))[:, None] + np.arange(count)]
    return cand[starts[:, None] + k], np.take_along_axis(grid, k, axis=1)
