"""Label-robust codeword selection (beyond the paper, issue 16): the ``robust`` synthesis mode.

The paper's phonetic mode (eq 4) searches only the codewords of the N context-phones most similar
to the input phone: exact when the labels are right, harmful when they are wrong. The robust mode
keeps eqs 5-8 but changes what they see:

* **candidates** -- the eq 4 codewords *and* the K acoustically nearest codewords together
  (:func:`candidate_union`);
* **target cost** -- eq 5's distance with acoustic context (:func:`context_distances`: the LSFs of
  the frames ``t + o`` against the codeword's LSFs at the same offsets), plus a penalty on the
  codewords eq 4 did not choose, scaled by the label's confidence (:func:`label_penalty`): with
  hand-checked labels (confidence 1) the phonetic restriction counts fully, with a label the
  recognizer doubts it hardly counts;
* **speaker mean normalisation** of the input LSFs (:func:`mean_normalise`).

Eqs 6-8 then weight the candidates by ``exp(-gamma * cost)`` exactly as the paper does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .synthesis import FrameWeights, codebook_weights, perceptual_weights


def mean_normalise(w: np.ndarray, target_mean: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """Speaker mean normalisation: ``w'(t) = w(t) - mean(w) + mu``, the input LSFs moved so that
    their mean (over ``mask`` frames, e.g. speech) is the training speaker's mean ``mu``.

    Examples
    --------
    >>> w = np.array([[0.4, 1.0], [0.6, 1.2]])
    >>> mean_normalise(w, np.array([0.5, 1.0])).round(3).tolist()
    [[0.4, 0.9], [0.6, 1.1]]
    """
    w = np.asarray(w, dtype=np.float64)
    rows = w if mask is None or not np.any(mask) else w[np.asarray(mask, bool)]
    return w - rows.mean(axis=0) + np.asarray(target_mean, dtype=np.float64)


def context_frames(w: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The LSF vectors of frames ``t + o`` for each offset ``o`` (frames), clamped at the ends:
    ``(T, O, P)``.

    Examples
    --------
    >>> w = np.arange(3.0)[:, None]
    >>> context_frames(w, np.array([-1, 1]))[..., 0].tolist()
    [[0.0, 1.0], [0.0, 2.0], [1.0, 2.0]]
    """
    t = np.arange(w.shape[0])[:, None] + np.asarray(offsets, dtype=np.int64)[None, :]
    return w[np.clip(t, 0, w.shape[0] - 1)]


def context_distances(w: np.ndarray, w_ctx: np.ndarray | None, cand_lsf: np.ndarray,
                      cand_ctx: np.ndarray | None, context_weight: float) -> np.ndarray:
    """Eq 5 with acoustic context: ``d_i = sum_k h_k |w_k - L_ik|
    + rho / O * sum_o sum_k h_ok |w_ok - L_iok|``, where ``w_o`` is the input frame at offset
    ``o``, ``L_io`` codeword i's LSF vector at the same offset (stored at training), ``h_o`` eq 5's
    perceptual weights of ``w_o`` and ``rho`` = ``context_weight``. Without context (``w_ctx`` or
    ``cand_ctx`` ``None``, or ``rho = 0``) this is eq 5.

    Shapes: ``w`` ``(T, P)``, ``w_ctx`` ``(T, O, P)``, ``cand_lsf`` ``(T, I, P)``, ``cand_ctx``
    ``(T, I, O, P)``; result ``(T, I)``.

    Examples
    --------
    One frame, one codeword, P = 2, one context offset; eq 5 gives 1.0 at the centre
    (``h = [10, 10/0.9 ...]``), the context term adds ``0.5 * 1.0``:

    >>> w = np.array([[0.5, 0.6]])
    >>> L = np.array([[[0.6, 0.6]]])
    >>> wc = np.array([[[0.5, 0.6]]])
    >>> Lc = np.array([[[[0.6, 0.6]]]])
    >>> context_distances(w, None, L, None, 0.5).round(4).tolist()
    [[1.0]]
    >>> context_distances(w, wc, L, Lc, 0.5).round(4).tolist()
    [[1.5]]
    """
    h = perceptual_weights(w)                                               # (T, P)
    d = np.einsum("tik,tk->ti", np.abs(w[:, None, :] - cand_lsf), h)
    if w_ctx is None or cand_ctx is None or context_weight == 0 or w_ctx.shape[1] == 0:
        return d
    hc = perceptual_weights(w_ctx)                                          # (T, O, P)
    dc = np.einsum("tiok,tok->ti", np.abs(w_ctx[:, None] - cand_ctx), hc)
    return d + context_weight / w_ctx.shape[1] * dc


def candidate_union(phonetic: np.ndarray, acoustic: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frame, the eq 4 candidates followed by the acoustic ones.

    Returns ``(candidates, from_labels, valid)``, each ``(T, I + J)``: codebook indices, whether
    each codeword is among eq 4's, and whether the entry counts (an acoustic candidate eq 4 already
    holds is a repeat and does not count twice).

    Examples
    --------
    >>> c, f, v = candidate_union(np.array([[3, 4]]), np.array([[4, 7]]))
    >>> c.tolist(), f.tolist(), v.tolist()
    ([[3, 4, 4, 7]], [[True, True, True, False]], [[True, True, False, True]])
    """
    phonetic = np.asarray(phonetic)
    acoustic = np.asarray(acoustic)
    dup = (acoustic[:, :, None] == phonetic[:, None, :]).any(axis=2)        # (T, J)
    cand = np.concatenate([phonetic, acoustic], axis=1)
    from_labels = np.concatenate([np.ones(phonetic.shape, bool), dup], axis=1)
    valid = np.concatenate([np.ones(phonetic.shape, bool), ~dup], axis=1)
    return cand, from_labels, valid


def label_penalty(from_labels: np.ndarray, confidence: np.ndarray, kappa: float) -> np.ndarray:
    """The label term of the target cost: ``kappa * c(t)`` for a codeword eq 4 did not choose,
    0 for one it did, where ``c(t)`` in [0, 1] is the confidence of frame t's phone label
    (1 for hand-checked labels, the aligner's or recognizer's confidence otherwise).

    Examples
    --------
    >>> label_penalty(np.array([[True, False]]), np.array([0.5]), 4.0).tolist()
    [[0.0, 2.0]]
    """
    return np.where(from_labels, 0.0, kappa * np.asarray(confidence, dtype=np.float64)[:, None])


@dataclass
class RobustFrames(FrameWeights):
    """:class:`~facetraj_engine.method.synthesis.FrameWeights` of the robust mode, with why each candidate got its
    weight: ``acoustic_cost`` (eq 5 with context), ``label_cost`` (:func:`label_penalty`),
    ``from_labels`` (chosen by eq 4) and ``confidence`` ``(T,)`` (the frame's label confidence).
    Entries that do not count (repeats) have infinite cost and weight 0."""

    acoustic_cost: np.ndarray | None = None
    label_cost: np.ndarray | None = None
    from_labels: np.ndarray | None = None
    confidence: np.ndarray | None = None


def weight_costs(w: np.ndarray, candidates: np.ndarray, cost: np.ndarray, cb_lsf: np.ndarray,
                 cb_pcs: np.ndarray, gammas: np.ndarray) -> FrameWeights:
    """Eqs 6-8 over a given target cost instead of eq 5's distance: ``v_i = softmax(-gamma
    cost_i)``, gamma searched on ``gammas`` to minimise ``sum_k h_k |w_k - w-hat_k|`` (eq 7's
    criterion), ``p-hat = sum_i v_i F_i``. With ``cost`` = eq 5's distances this is
    :func:`facetraj_engine.method.synthesis.weight_frames` (the test checks it).
    """
    h = perceptual_weights(w)
    cand_lsf = cb_lsf[candidates]                                           # (T, I, P)
    v = codebook_weights(cost[:, None, :], gammas[None, :])                 # (T, G, I)  eq 6
    what = np.matmul(v, cand_lsf)                                           # (T, G, P)  eq 7
    e = np.matmul(np.abs(what - w[:, None, :]), h[:, :, None])[..., 0]
    best = e.argmin(axis=1)
    rows = np.arange(w.shape[0])
    vb = v[rows, best]
    pcs = np.matmul(vb[:, None, :], cb_pcs[candidates])[:, 0]              # eq 8
    return FrameWeights(pcs, gammas[best], vb, candidates, what[rows, best], e[rows, best])


def robust_frames(w: np.ndarray, phonetic: np.ndarray, acoustic: np.ndarray,
                  confidence: np.ndarray, cb_lsf: np.ndarray, cb_pcs: np.ndarray,
                  gammas: np.ndarray, kappa: float, cb_ctx: np.ndarray | None = None,
                  offsets: np.ndarray | None = None, context_weight: float = 0.0,
                  chunk: int = 128, w_ctx: np.ndarray | None = None) -> RobustFrames:
    """The robust mode per frame: candidate union, target cost = :func:`context_distances` +
    :func:`label_penalty`, then eqs 6-8 (:func:`weight_costs`). ``cb_ctx`` ``(5L, O, P)`` holds
    the codewords' LSFs at ``offsets`` frames (``None``: no context). ``w_ctx`` ``(T, O, P)``:
    the input frames at those offsets when ``w`` is part of a longer input (a stream), else
    :func:`context_frames` of ``w``. Chunked over frames."""
    cand, from_labels, valid = candidate_union(phonetic, acoustic)
    use_ctx = cb_ctx is not None and offsets is not None and len(offsets) and context_weight > 0
    w_ctx_all = (context_frames(w, offsets) if w_ctx is None else w_ctx) if use_ctx else None
    gammas = np.asarray(gammas, dtype=np.float64)
    parts = []
    acost = np.empty(cand.shape)
    lcost = label_penalty(from_labels, confidence, kappa)
    for a in range(0, w.shape[0], chunk):
        b = min(a + chunk, w.shape[0])
        c = cand[a:b]
        d = context_distances(w[a:b], w_ctx_all[a:b] if use_ctx else None, cb_lsf[c],
                              cb_ctx[c] if use_ctx else None, context_weight)
        d = np.where(valid[a:b], d, np.inf)
        acost[a:b] = d
        parts.append(weight_costs(w[a:b], c, d + lcost[a:b], cb_lsf, cb_pcs, gammas))
    fw = [np.concatenate([getattr(p, f) for p in parts]) for f in
          ("pcs", "gamma", "weights", "candidates", "lsf_hat", "error")]
    return RobustFrames(*fw, acoustic_cost=acost, label_cost=lcost, from_labels=from_labels,
                        confidence=np.asarray(confidence, dtype=np.float64))
