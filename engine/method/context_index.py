"""Eq 4's codebook contexts grouped by their centre phone and first neighbours, so that the N
most similar contexts of an input phone are found by scoring groups, then the few contexts that
can still win (paper section 2.3, eq 4).

Eq 4, ``n_j = S_cj + sum_i xi^-i (S_l_ij + S_r_ij)``, is ``p_j``, its centre and first
neighbours' terms, plus the outer terms, which add at most ``B2 = 2 sum_{i>=2} xi^-i``
(similarities are in [0, 1]). Every context of a group (one centre, one left and one right
neighbour) has the same ``p``. The ``count``-th largest ``p`` over the contexts of an input's
candidate groups is ``tau``; a context whose ``p + B2`` stays below ``tau`` is beaten by
``count`` others and cannot be among the best. Only the contexts of the groups reaching ``tau``
are scored in full. The number of groups grows with the distinct triphones of a corpus, not with
its length: the search's cost per input phone stops growing with the corpus (eq 4 over every
context of the centre phone grows with it, and with it the evaluation's time per utterance).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: what the bounds leave to rounding: far above the error of a sum of seven similarities
MARGIN = 1e-9


@dataclass(frozen=True)
class ContextIndex:
    """The codebook's contexts ``(L, 2C+1)``: the distinct ones (a sentence read twice repeats
    its contexts), grouped by ``(c, l_1, r_1)``, the groups sorted by centre phone.

    Attributes
    ----------
    centre, left, right : ``(G,)`` each group's phone ids.
    group_start, group_size : ``(G,)`` each group's distinct contexts:
        ``distinct[group_start:group_start + group_size]``; ``group_tokens`` ``(G,)`` their
        codebook contexts in all.
    distinct : ``(D,)`` the distinct contexts, by group.
    start, size : ``(D,)`` each distinct context's codebook contexts: ``tokens[start:start +
        size]``, in increasing order.
    tokens : ``(L,)`` the codebook contexts' indices, by distinct context.
    centre_start, centre_groups : ``(P,)`` the groups of centre phone ``u``:
        ``centre_start[u]`` to ``centre_start[u] + centre_groups[u]``.
    centre_tokens : ``(P,)`` the codebook contexts of each centre phone.
    """

    centre: np.ndarray
    left: np.ndarray
    right: np.ndarray
    group_start: np.ndarray
    group_size: np.ndarray
    group_tokens: np.ndarray
    distinct: np.ndarray
    start: np.ndarray
    size: np.ndarray
    tokens: np.ndarray
    centre_start: np.ndarray
    centre_groups: np.ndarray
    centre_tokens: np.ndarray

    @classmethod
    def of(cls, codebook: np.ndarray, n_phones: int) -> ContextIndex:
        """The index of codebook contexts ``(L, 2C+1)`` (``C >= 1``) over ``n_phones`` phones.

        >>> ix = ContextIndex.of(np.array([[0, 1, 2], [1, 0, 2], [0, 1, 2]]), 3)
        >>> ix.centre.tolist(), ix.group_tokens.tolist(), ix.size.tolist(), ix.tokens.tolist()
        ([0, 1], [1, 2], [2, 1], [0, 2, 1])
        """
        codebook = np.asarray(codebook, dtype=np.int64)
        full = (codebook.shape[1] - 1) // 2
        rows, inverse, size = unique_rows(codebook)
        tokens = np.argsort(inverse, kind="stable")
        keys = rows[:, [full, full - 1, full + 1]]
        groups, of_group, _ = unique_rows(keys)
        distinct = np.argsort(of_group, kind="stable")
        group_size = np.bincount(of_group, minlength=len(groups))
        centre = groups[:, 0]
        centre_groups = np.bincount(centre, minlength=n_phones)
        return cls(centre, groups[:, 1], groups[:, 2], np.cumsum(group_size) - group_size,
                   group_size, np.bincount(of_group, weights=size).astype(np.int64), distinct,
                   np.cumsum(size) - size, size, tokens,
                   np.cumsum(centre_groups) - centre_groups, centre_groups,
                   np.bincount(codebook[:, full], minlength=n_phones))

    @property
    def tokens_per_group(self) -> float:
        """Codebook contexts per group, on average."""
        return len(self.tokens) / max(len(self.centre), 1)

    def candidates(self, query: np.ndarray, s: np.ndarray, w1: float, bound: float,
                   rest: float, count: int) -> tuple[np.ndarray, np.ndarray]:
        """``(rows, contexts)``: the (query, codebook context) pairs among which each query's
        ``count`` best by eq 4 are (sorted by query, then context index). ``w1`` is ``xi^-1``,
        ``bound`` what the neighbours' terms add at most, ``rest`` what the terms past the
        first neighbours add at most. Of a context repeated in the codebook, only its first
        ``count`` copies can be among the best (the others score the same, with higher
        indices)."""
        rows, grp, sizes = self._candidate_groups(query, s, bound, count)
        full = (query.shape[1] - 1) // 2
        n = s.shape[0]
        flat = s.ravel()
        p = flat.take(np.repeat(query[:, full] * n, sizes) + self.centre.take(grp))
        p += w1 * (flat.take(np.repeat(query[:, full - 1] * n, sizes) + self.left.take(grp)) +
                   flat.take(np.repeat(query[:, full + 1] * n, sizes) + self.right.take(grp)))
        keep = p + rest + MARGIN >= np.repeat(_tau(sizes, p, self.group_tokens.take(grp), count),
                                              sizes)
        grp = grp[keep]
        rows, dist = _expand(rows[keep], self.group_start.take(grp), self.group_size.take(grp))
        dist = self.distinct.take(dist)
        rows, tok = _expand(rows, self.start.take(dist), np.minimum(self.size.take(dist), count))
        contexts = self.tokens.take(tok)
        order = np.argsort(rows * len(self.tokens) + contexts)
        return rows.take(order), contexts.take(order)

    def _candidate_groups(self, query: np.ndarray, s: np.ndarray, bound: float, count: int
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(rows, groups, sizes)``: for every query, the groups of the centre phones whose
        similarity to its centre is within ``bound`` of the best one (every centre when fewer
        than ``count`` contexts reach the best), by query; ``sizes`` the groups of each."""
        full = (query.shape[1] - 1) // 2
        centres, inverse = np.unique(query[:, full], return_inverse=True)
        inverse = inverse.ravel()
        present = np.flatnonzero(self.centre_tokens)
        sim = s[centres][:, present]                                        # (U, P')
        best = sim.max(axis=1, keepdims=True)
        near = sim >= best - bound - 1e-12
        reach = np.where(sim >= best, self.centre_tokens[present], 0).sum(axis=1)
        near[reach < count] = True
        uu, vv = np.nonzero(near)
        _, flat = _expand(uu, self.centre_start[present[vv]], self.centre_groups[present[vv]])
        u_size = np.bincount(uu, weights=self.centre_groups[present[vv]],
                             minlength=len(centres)).astype(np.int64)
        u_start = np.cumsum(u_size) - u_size
        rows, at = _expand(np.arange(len(query)), u_start[inverse], u_size[inverse])
        return rows, flat.take(at), u_size[inverse]


def _expand(owner: np.ndarray, start: np.ndarray, size: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Ranges ``start[k]:start[k] + size[k]`` laid end to end: ``(their owner, the indices)``.

    >>> _expand(np.array([7, 8]), np.array([10, 0]), np.array([2, 1]))
    (array([7, 7, 8]), array([10, 11,  0]))
    """
    size = np.asarray(size, dtype=np.int64)
    offsets = np.arange(size.sum()) - np.repeat(np.cumsum(size) - size, size)
    return np.repeat(owner, size), np.repeat(start, size) + offsets


def unique_rows(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``numpy.unique(a, axis=0, return_inverse=True, return_counts=True)`` of phone ids ``(n, k)``
    (the rows in lexicographic order, each row's place among them ``(n,)``, their counts), each
    row taken as one integer of ``k`` digits in base ``max + 1`` when it fits in 63 bits (a
    sort of integers, not of rows).

    >>> rows, inverse, counts = unique_rows(np.array([[1, 0], [0, 5], [1, 0]]))
    >>> rows.tolist(), inverse.tolist(), counts.tolist()
    ([[0, 5], [1, 0]], [1, 0, 1], [1, 2])
    """
    a = np.asarray(a, dtype=np.int64)
    base = int(a.max(initial=0)) + 1
    if a.size == 0 or a.min() < 0 or a.shape[1] * np.log2(base) >= 62:
        rows, inverse, counts = np.unique(a, axis=0, return_inverse=True, return_counts=True)
        return rows, inverse.ravel(), counts
    key = np.zeros(len(a), dtype=np.int64)
    for column in a.T:
        key *= base
        key += column
    _, first, inverse, counts = np.unique(key, return_index=True, return_inverse=True,
                                          return_counts=True)
    return a[first], inverse.ravel(), counts


def _tau(sizes: np.ndarray, p: np.ndarray, tokens: np.ndarray, count: int) -> np.ndarray:
    """Per query (its ``sizes[q]`` candidate groups, in order), a value that ``count`` of its
    candidate contexts reach or pass in ``p``: the larger of the ``count``-th largest group ``p``
    and the largest ``p`` of a group of ``count`` contexts or more (``tokens``: each group's;
    ``-inf`` when neither exists)."""
    n_queries = len(sizes)
    starts = np.cumsum(sizes) - sizes
    width = int(sizes.max())
    grid = np.full((n_queries, width), -np.inf)
    grid.ravel()[np.repeat(np.arange(n_queries) * width - starts, sizes) + np.arange(len(p))] = p
    by_groups = np.partition(grid, width - count, axis=1)[:, width - count] if count <= width \
        else np.full(n_queries, -np.inf)
    big = np.where(tokens >= count, p, -np.inf)
    some = sizes > 0
    tau = by_groups
    tau[some] = np.maximum(tau[some], np.maximum.reduceat(big, starts[some]))
    return tau
