"""The acoustic search's own opinion on where the lips close (issue 40): per frame of an
acoustic-only search (paper 2.3, eqs 5-8), the share of eq 7's weight on codewords of /p b m/
context-phones and the aperture of eq 8's unsmoothed face minus the training talker's closed
aperture. The bilabial-closure detector (:mod:`facetraj_engine.method.closure_detector`, step 6)
weighs them by the voice match: they are the training voice's sounds.

At training the training utterances are searched with their own codewords left out
(:func:`left_out_rows`), as a new recording of the training voice is searched: with them, every
frame finds itself.
"""

from __future__ import annotations

import numpy as np

from ..config import SynthConfig
from .closure import BILABIALS, aperture_functional
from .model import Model
from .search import acoustic_candidates, gammas
from .synthesis import FrameWeights, perceptual_weights, weight_frames


def bilabial_codewords(model: Model) -> np.ndarray:
    """``(5L,)`` whether each codeword belongs to a context-phone whose centre is /p b m/."""
    is_bilabial = np.isin(np.asarray(model.phones), BILABIALS)
    return is_bilabial[model.codebook.codeword_phone()]


def bilabial_share(weights: np.ndarray, candidates: np.ndarray, bilabial: np.ndarray) -> np.ndarray:
    """Per frame, the share of the weights ``(T, I)`` on the candidates ``(T, I)`` that are
    ``bilabial`` codewords.

    >>> bilabial_share(np.array([[0.25, 0.75]]), np.array([[0, 2]]), np.array([True, True, False])).tolist()
    [0.25]
    """
    w = np.asarray(weights, dtype=np.float64)
    total = w.sum(axis=1)
    return (w * bilabial[candidates]).sum(axis=1) / np.where(total > 0, total, 1.0)


def search_rows(model: Model, frames: FrameWeights, bilabial: np.ndarray | None = None
                ) -> np.ndarray:
    """``(T, 2)``: per frame of an acoustic-only search, the share of its weight on /p b m/
    codewords and its unsmoothed aperture minus the closed one (mm)."""
    bilabial = bilabial_codewords(model) if bilabial is None else bilabial
    a0, g = aperture_functional(model.pca, model.upper_lip, model.lower_lip)
    closed = model.closure.closed if model.closure is not None else 0.0
    return np.column_stack([bilabial_share(frames.weights, frames.candidates, bilabial),
                            a0 + np.asarray(frames.pcs) @ g - closed])


def left_out_rows(model: Model, w: np.ndarray, utterance: int, config: SynthConfig | None = None,
                  spare: int = 2) -> np.ndarray:
    """:func:`search_rows` of training utterance ``utterance``'s input LSFs ``w`` searched
    acoustic-only (the index's ``spare`` times as many nearest codewords, those of the utterance
    itself left out, the nearest ``acoustic_prefilter`` of the rest by eq 5)."""
    config = config or SynthConfig(mode="acoustic")
    cb = model.codebook
    n = len(cb.lsf)
    count = min(config.acoustic_prefilter or n, n)
    wide = acoustic_candidates(model, w, config.with_(acoustic_prefilter=min(spare * count, n)))
    h = perceptual_weights(w)
    d = np.matmul(np.abs(cb.lsf[wide] - w[:, None, :]), h[:, :, None])[..., 0]     # eq 5
    own = cb.token_utt[wide // cb.n_per_phone] == utterance
    d[own] = np.inf
    count = min(count, d.shape[1])
    keep = np.argpartition(d, count - 1, axis=1)[:, :count]
    candidates = np.take_along_axis(wide, keep, axis=1)
    return search_rows(model, weight_frames(w, candidates, cb.lsf, cb.pcs, gammas(config)))
