"""Eq 4's search by groups of contexts (facetraj_engine.method.context_index, issue 41): the same best
contexts and the same scores, to the bit and in the same tie order, as scoring every codebook
context; the contexts scored per input phone do not grow when the corpus repeats itself."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.method.context_index import ContextIndex
from facetraj_engine.method.similarity import context_similarity, top_context_phones, top_contexts


def _queries(model, n: int, seed: int) -> np.ndarray:
    """Contexts of the codebook, some with a neighbour changed, and contexts of random phones."""
    rng = np.random.default_rng(seed)
    cb = model.codebook.contexts
    real = cb[rng.choice(len(cb), n)]
    changed = real.copy()
    changed[np.arange(n), rng.integers(0, cb.shape[1], n)] = rng.integers(0, len(model.phones), n)
    return np.concatenate([real, changed, rng.integers(0, len(model.phones), (n, cb.shape[1]))])


@pytest.mark.parametrize(("context", "count"), [(3, 3), (3, 1), (2, 16), (1, 5), (0, 3)])
def test_the_best_contexts_are_those_of_every_context_scored(default_model, context, count):
    s = default_model.similarity()
    cb = default_model.codebook.contexts
    q = _queries(default_model, 150, context)
    top, n = top_context_phones(q, cb, s, 20.0, context, count)
    full = context_similarity(q, cb, s, 20.0, context)
    want = top_contexts(full, count)
    np.testing.assert_array_equal(top, want)
    np.testing.assert_array_equal(n, np.take_along_axis(full, want, axis=1))


def test_a_corpus_repeated_gives_its_first_copies_and_scores_no_more(default_model):
    """Every context four times over (a corpus read four times): the best are the first copies
    (ties: lower index first), as scoring every context gives; and the contexts scored per
    input phone stop growing with the repeats (of each distinct context, at most its first
    ``count`` copies), a fraction of those of its centre phone."""
    s = default_model.similarity()
    once = default_model.codebook.contexts
    four = np.tile(once, (4, 1))
    q = _queries(default_model, 100, 7)
    top, n = top_context_phones(q, four, s, 20.0, 3, 3)
    full = context_similarity(q, four, s, 20.0, 3)
    want = top_contexts(full, 3)
    np.testing.assert_array_equal(top, want)
    np.testing.assert_array_equal(n, np.take_along_axis(full, want, axis=1))
    bound, rest = 2 * (20.0 ** -1 + 20.0 ** -2 + 20.0 ** -3), 2 * (20.0 ** -2 + 20.0 ** -3)
    scored = [len(ContextIndex.of(cb, len(s)).candidates(q, s, 1 / 20.0, bound, rest, 3)[0])
              for cb in (once, four, np.tile(once, (16, 1)))]
    assert scored[2] == scored[1] <= 3 * scored[0]
    by_centre = sum(int((once[:, 3] == c).sum()) for c in q[:, 3])     # every context of its centre
    assert scored[0] < by_centre / 4


@pytest.mark.parametrize("seed", range(8))
def test_unique_rows_are_numpys(seed):
    """Rows as base-(max+1) integers (issue 48): numpy's unique rows, places and counts, for
    few and many phones, short and long contexts, and rows too long for 63 bits (numpy's)."""
    from facetraj_engine.method.context_index import unique_rows

    rng = np.random.default_rng(seed)
    n, k = int(rng.integers(1, 3000)), int(rng.choice([1, 3, 7, 13, 31]))
    a = rng.integers(0, int(rng.choice([2, 40, 300, 5000])), (n, k))
    a = np.concatenate([a, a[rng.integers(0, n, n // 3)]])          # repeated rows
    want = np.unique(a, axis=0, return_inverse=True, return_counts=True)
    got = unique_rows(a)
    for x, y in zip(got, want, strict=True):
        np.testing.assert_array_equal(x, y.reshape(x.shape))
    assert got[1].shape == (len(a),)
