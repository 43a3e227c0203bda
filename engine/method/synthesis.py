"""Codebook weighting and PC synthesis (paper section 2.3, eqs 5-8), vectorised over frames."""

from __future__ import annotations

import functools
from dataclasses import dataclass, fields

import numpy as np


def perceptual_weights(w: np.ndarray) -> np.ndarray:
    """Eq 5 (first line): ``h_k = 1 / min(|w_k - w_(k-1)|, |w_k - w_(k+1)|)``, ``w_0 = 0``,
    ``w_(P+1) = pi``. Closely spaced LSFs (formants) get large weights (Laroia et al. 1991).

    ``w`` is ``(..., P)`` LSF in radians.

    Examples
    --------
    >>> np.round(perceptual_weights(np.array([0.5, 0.6, 2.0])), 4).tolist()
    [10.0, 10.0, 0.876]
    """
    w = np.asarray(w, dtype=np.float64)
    lead = w.shape[:-1]
    padded = np.concatenate([np.zeros((*lead, 1)), w, np.full((*lead, 1), np.pi)], axis=-1)
    gaps = np.diff(padded, axis=-1)
    nearest = np.minimum(gaps[..., :-1], gaps[..., 1:])
    return 1.0 / np.maximum(nearest, 1e-6)


def lsf_distances(w: np.ndarray, codewords: np.ndarray, h: np.ndarray | None = None) -> np.ndarray:
    """Eq 5 (second line): ``d_i = sum_k h_k |w_k - L_ik|``.

    ``w`` is ``(..., P)``, ``codewords`` ``(..., I, P)`` broadcastable against ``w[..., None, :]``;
    the result is ``(..., I)``.

    Examples
    --------
    >>> w = np.array([0.5, 0.6, 2.0])
    >>> L = np.array([[0.5, 0.6, 2.0], [0.6, 0.6, 2.0]])
    >>> np.round(lsf_distances(w, L), 4).tolist()
    [0.0, 1.0]
    """
    w = np.asarray(w, dtype=np.float64)
    if h is None:
        h = perceptual_weights(w)
    return np.einsum("...ik,...k->...i", np.abs(w[..., None, :] - codewords), h)


def codebook_weights(d: np.ndarray, gamma: float | np.ndarray) -> np.ndarray:
    """Eq 6: ``v_i = exp(-gamma d_i) / sum_l exp(-gamma d_l)``, a numerically stable softmax.

    Examples
    --------
    >>> v = codebook_weights(np.array([0.0, np.log(3.0)]), 1.0)
    >>> np.round(v, 4).tolist()
    [0.75, 0.25]
    """
    z = -np.asarray(gamma)[..., None] * np.asarray(d)
    z = z - z.max(axis=-1, keepdims=True)
    e = np.exp(z)
    return e / e.sum(axis=-1, keepdims=True)


def grid_weights(d: np.ndarray, gammas: np.ndarray) -> np.ndarray:
    """Eq 6 for every gamma of a search grid at once: distances ``(..., I)`` to weights
    ``(..., G, I)``, the fast kernel of :func:`weight_frames` (reference: :func:`codebook_weights`).

    On an evenly spaced grid ``gamma_j = gamma_0 + j delta``, ``exp(-gamma_j x)`` (``x = d - min d``,
    the softmax's stabilising shift) is ``exp(-gamma_0 x) exp(-delta x)^j``: two exponentials per
    codeword instead of G, the powers by repeated products (relative error below ``j`` ulps). Any
    other grid falls back to the reference. Tested equal to it to 1e-13.

    >>> d = np.array([0.0, 1.0, 2.5])
    >>> g = gamma_grid(0.2, 2.0, 10)
    >>> bool(np.allclose(grid_weights(d, g), codebook_weights(d[None, :], g), rtol=1e-13, atol=0))
    True
    """
    d = np.asarray(d, dtype=np.float64)
    gammas = np.asarray(gammas, dtype=np.float64)
    step = _even_step(tuple(gammas.tolist()))
    if step is None:
        return codebook_weights(d[..., None, :], gammas)
    x = d - d.min(axis=-1, keepdims=True)
    e = np.empty((*d.shape[:-1], len(gammas), d.shape[-1]))
    e[..., 0, :] = np.exp(-gammas[0] * x)
    ratio = np.exp(-step * x)
    for j in range(1, len(gammas)):
        np.multiply(e[..., j - 1, :], ratio, out=e[..., j, :])
    e /= e.sum(axis=-1, keepdims=True)
    return e


@functools.lru_cache(maxsize=64)
def _even_step(gammas: tuple[float, ...]) -> float | None:
    """The step of an evenly spaced grid of three gammas or more (:func:`grid_weights`' fast
    kernel), else ``None``; judged once per grid (``numpy.allclose`` costs 0.1 ms a call).

    >>> _even_step((0.2, 0.4, 0.6)), _even_step((0.2, 0.4, 0.7)), _even_step((0.2, 0.4))
    (np.float64(0.2), None, None)
    """
    steps = np.diff(np.array(gammas))
    if len(gammas) < 3 or not np.allclose(steps, steps[0], rtol=1e-12, atol=0.0):
        return None
    return steps[0]


def approximate_lsf(v: np.ndarray, codewords: np.ndarray) -> np.ndarray:
    """Eq 7: ``w-hat_k = sum_i v_i L_ik``, the LSF vector rebuilt from the weighted codewords."""
    return np.einsum("...i,...ik->...k", v, codewords)


@functools.lru_cache(maxsize=64)
def gamma_grid(lo: float = 0.2, hi: float = 2.0, steps: int = 10) -> np.ndarray:
    """The incremental search grid for gamma (eq 7's criterion): ``steps`` values in [lo, hi]
    (made once per grid, read-only).

    >>> gamma_grid(0.2, 2.0, 10)[[0, 1, -1]].round(2).tolist(), gamma_grid().flags.writeable
    ([0.2, 0.4, 2.0], False)
    """
    grid = np.linspace(lo, hi, steps)
    grid.flags.writeable = False
    return grid


@dataclass
class FrameWeights:
    """Per-frame result of eqs 5-8.

    Attributes
    ----------
    pcs : ``(T, K)`` the synthesized PC vectors p-hat(t) (eq 8, unsmoothed).
    gamma : ``(T,)`` the gamma chosen per frame.
    weights : ``(T, I)`` the weights v_i of the candidate codewords.
    candidates : ``(T, I)`` codebook indices of the candidates.
    lsf_hat : ``(T, P)`` the approximated LSF w-hat (eq 7).
    error : ``(T,)`` the perceptually weighted distance between w and w-hat.
    """

    pcs: np.ndarray
    gamma: np.ndarray
    weights: np.ndarray
    candidates: np.ndarray
    lsf_hat: np.ndarray
    error: np.ndarray

    @classmethod
    def concatenate(cls, parts: list[FrameWeights]) -> FrameWeights:
        """The frames of ``parts`` one after another (spans of frames weighted apart).
        Candidates that every frame shares (a broadcast row: the whole codebook) stay one row."""
        if len(parts) == 1:
            return parts[0]
        joined = {f.name: np.concatenate([getattr(p, f.name) for p in parts])
                  for f in fields(cls) if f.name != "candidates"}
        cands = [p.candidates for p in parts]
        if all(c.strides[0] == 0 and np.array_equal(c[0], cands[0][0]) for c in cands):
            n = sum(len(c) for c in cands)
            return cls(**joined, candidates=np.broadcast_to(cands[0][0], (n, cands[0].shape[1])))
        return cls(**joined, candidates=np.concatenate(cands))


    @classmethod
    def merged(cls, mask: np.ndarray, inside: FrameWeights, outside: FrameWeights) -> FrameWeights:
        """The frames of ``inside`` where ``mask`` is true and of ``outside`` elsewhere, in frame
        order (two searches of one input's frames); the narrower candidate rows are padded with
        their first candidate at weight 0.

        >>> def frames(n, i, v):
        ...     return FrameWeights(np.full((n, 2), v), np.full(n, v), np.full((n, i), v),
        ...                         np.full((n, i), int(v)), np.full((n, 3), v), np.full(n, v))
        >>> both = FrameWeights.merged(np.array([False, True, False]), frames(1, 2, 1.0),
        ...                            frames(2, 3, 0.5))
        >>> both.weights.tolist(), both.candidates[1].tolist()
        ([[0.5, 0.5, 0.5], [1.0, 1.0, 0.0], [0.5, 0.5, 0.5]], [1, 1, 1])
        """
        mask = np.asarray(mask, bool)
        width = max(inside.candidates.shape[1], outside.candidates.shape[1])
        out = {}
        for f in fields(cls):
            a, b = getattr(inside, f.name), getattr(outside, f.name)
            if f.name in ("weights", "candidates"):
                a, b = (np.pad(x, ((0, 0), (0, width - x.shape[1])),
                               mode="constant" if f.name == "weights" else "edge") for x in (a, b))
            joined = np.empty((len(mask), *a.shape[1:]), dtype=np.result_type(a, b))
            joined[mask], joined[~mask] = a, b
            out[f.name] = joined
        return cls(**out)


def weight_frames(w: np.ndarray, candidates: np.ndarray, cb_lsf: np.ndarray, cb_pcs: np.ndarray,
                  gammas: np.ndarray, chunk: int = 1024) -> FrameWeights:
    """Eqs 5-8 for every frame: distances to its candidate codewords, gamma searched on
    ``gammas`` to minimise ``sum_k h_k |w_k - w-hat_k|``, and ``p-hat = sum_i v_i F_i``.

    ``w`` is ``(T, P)`` input LSFs, ``candidates`` ``(T, I)`` codebook indices per frame,
    ``cb_lsf`` ``(5L, P)`` the codebook LSFs L_i and ``cb_pcs`` ``(5L, K)`` its PC vectors F_i.
    Work is chunked over frames: about 300,000 values per array, which stay in cache, when each
    frame gathers its own candidates; about 4 million when every frame has the same candidates
    (acoustic-only full search), whose codebook is not gathered per frame and eqs 7-8 are plain
    matrix products. Codewords are gathered with ``np.take``.
    """
    n_frames = w.shape[0]
    n_cand = candidates.shape[1]
    shared = n_frames > 0 and candidates.strides[0] == 0          # a broadcast row: same for all
    gammas = np.asarray(gammas, dtype=np.float64)
    budget = 4e6 if shared else 3e5          # values per chunk array: gathered ones stay in cache
    chunk = max(1, min(chunk, int(budget // max(1, n_cand * max(w.shape[1], len(gammas))))))
    pcs = np.empty((n_frames, cb_pcs.shape[1]))
    gam = np.empty(n_frames)
    weights = np.empty((n_frames, n_cand))
    lsf_hat = np.empty_like(w, dtype=np.float64)
    err = np.empty(n_frames)
    if shared:
        lsf_all = cb_lsf[candidates[0]]
        pcs_all = cb_pcs[candidates[0]]
    for a in range(0, n_frames, chunk):
        b = min(a + chunk, n_frames)
        wc = w[a:b]
        h = perceptual_weights(wc)                               # (t, P)   eq 5
        cand_lsf = lsf_all[None] if shared else np.take(cb_lsf, candidates[a:b], axis=0)  # (t|1, I, P)
        d = cand_lsf - wc[:, None, :]
        d = np.matmul(np.abs(d, out=d), h[:, :, None])[..., 0]  # (t, I) eq 5
        v = grid_weights(d, gammas)                              # (t, G, I) eq 6
        what = np.matmul(v, cand_lsf)                            # (t, G, P) eq 7
        e = np.matmul(np.abs(what - wc[:, None, :]), h[:, :, None])[..., 0]
        best = e.argmin(axis=1)
        rows = np.arange(b - a)
        vb = v[rows, best]
        gam[a:b] = gammas[best]
        weights[a:b] = vb
        lsf_hat[a:b] = what[rows, best]
        err[a:b] = e[rows, best]
        if shared:
            pcs[a:b] = vb @ pcs_all                              # eq 8
        else:
            pcs[a:b] = np.matmul(vb[:, None, :], np.take(cb_pcs, candidates[a:b], axis=0))[:, 0]
    return FrameWeights(pcs, gam, weights, np.asarray(candidates), lsf_hat, err)


def nearest_codewords(w: np.ndarray, cb_lsf: np.ndarray, count: int | None,
                      chunk: int | None = None, shortlist: int = 4) -> np.ndarray:
    """Acoustic-only candidates: all ``5L`` codewords, or the ``count`` nearest by eq 5's distance.

    The nearest are found in two steps: a shortlist of ``shortlist * count`` codewords by the
    perceptually weighted *squared* distance ``sum_k h_k (w_k - L_ik)^2``, which expands into one
    matrix product ``[-2 h w, h] . [L_i, L_i^2]`` (BLAS, float32), then eq 5's weighted absolute
    distance on the shortlist only, keeping ``count``.

    Returns ``(T, I)`` codebook indices.
    """
    n_frames, n_cb = w.shape[0], cb_lsf.shape[0]
    if count is None or count >= n_cb:
        return np.broadcast_to(np.arange(n_cb), (n_frames, n_cb))
    m = min(n_cb, max(count, shortlist * count))
    chunk = chunk or max(1, min(256, int(4e6 // n_cb)))          # about 4 million distances per chunk
    out = np.empty((n_frames, count), dtype=np.int64)
    feats = np.concatenate([cb_lsf, cb_lsf**2], axis=1).astype(np.float32).T   # (2P, 5L)
    for a in range(0, n_frames, chunk):
        b = min(a + chunk, n_frames)
        wc = w[a:b]
        h = perceptual_weights(wc)
        q = np.concatenate([-2.0 * h * wc, h], axis=1).astype(np.float32)      # (t, 2P)
        d2 = q @ feats                                                          # (t, 5L)
        short = np.argpartition(d2, m - 1, axis=1)[:, :m] if m < n_cb else \
            np.broadcast_to(np.arange(n_cb), (b - a, n_cb))
        d = np.matmul(np.abs(wc[:, None, :] - cb_lsf[short]), h[:, :, None])[..., 0]   # eq 5
        keep = np.argpartition(d, count - 1, axis=1)[:, :count]
        out[a:b] = np.take_along_axis(short, keep, axis=1)
    return out
