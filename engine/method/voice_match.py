"""How well an input voice matches the training voice, from the audio alone (issue 25).

The codebook's acoustics are one talker's. For an input frame, eq 5's distance to the nearest
codeword says how well the codebook knows that sound; over a recording's speech frames, its
median says how well it knows the voice. The training voice's own figure (each training
utterance measured with its own codewords left out, else every frame finds itself) is stored in
the model as the reference ``D0``; the *voice match* is 1 up to ``1.5 D0`` and 0 from ``3 D0``,
linear in log distance between. Measured: the training voice's held-out sentences are at
0.86-1.27 ``D0``, six real CMU ARCTIC sentences by two other talkers at 3.5-4.8 ``D0``.

Synthesis trusts recognized labels more where the voice matches less (the recognizer was trained
on many real voices; the codebook on one): :func:`facetraj_engine.method.closure.closure_strengths`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..config import SynthConfig
from .lsf_index import LsfIndex
from .quantiles import median
from .synthesis import lsf_distances, perceptual_weights

#: The voice match is 1 up to ``MATCH_FULL`` times the training voice's distance, 0 from
#: ``MATCH_NONE`` times it.
MATCH_FULL, MATCH_NONE = 1.5, 3.0
#: Speech frames a recording's figure is computed on, at most (evenly spaced).
MAX_FRAMES = 400
#: The LSF index's cells probed for a frame's nearest codeword.
PROBE = 8
#: Speech frames heard before a voice is measured (0.5 s of speech at 60 Hz): a stream's running
#: match counts from then (:mod:`facetraj_engine.streaming.voice`), and so does the detector's
#: use of the match offline (:func:`match_from`), so that both treat the first half second alike.
MIN_FRAMES = 30
#: The voice match assumed until the voice has been measured (a person at a microphone is not the
#: training voice, which is synthetic).
PRIOR_MATCH = 0.0


def match_from(speech: np.ndarray, min_frames: int = MIN_FRAMES) -> int:
    """The first frame that may use the voice match, as a stream measures it: the frame after the
    ``min_frames``-th speech frame (``speech``: per frame; ``len(speech)``: none does).

    >>> match_from(np.array([0, 1, 1, 0, 1, 0, 0], bool), 3)
    5
    >>> match_from(np.array([0, 1, 0], bool), 3)
    3
    """
    heard = np.flatnonzero(np.asarray(speech, dtype=bool))
    return int(heard[min_frames - 1]) + 1 if heard.size >= min_frames else len(speech)


def frame_matches(match: float, count: int, first: int) -> np.ndarray:
    """Per frame, the voice match a frame may use: ``match`` from frame ``first`` on, before it
    :data:`PRIOR_MATCH` (NaN: unknown, the prior throughout).

    >>> frame_matches(1.0, 5, 3).tolist(), frame_matches(float("nan"), 2, 0).tolist()
    ([0.0, 0.0, 0.0, 1.0, 1.0], [0.0, 0.0])
    """
    m = float(match) if np.isfinite(match) else PRIOR_MATCH
    return np.where(np.arange(count) >= first, m, PRIOR_MATCH)


def nearest_distances(w: np.ndarray, cb_lsf: np.ndarray, exclude: np.ndarray | None = None,
                      chunk: int = 128, block: int = 512) -> np.ndarray:
    """Per frame of ``w`` ``(T, P)``, eq 5's distance to the nearest codeword (exact search;
    ``exclude`` ``(5L,)`` bool: codewords left out), ``chunk`` frames against ``block`` codewords
    at a time: the differences held at once stay a few MB whatever the codebook's size.

    >>> L = np.array([[0.5, 1.0, 2.0], [0.6, 1.0, 2.0]])
    >>> nearest_distances(np.array([[0.6, 1.0, 2.0]]), L).tolist()
    [0.0]
    >>> nearest_distances(np.array([[0.6, 1.0, 2.0]]), L, np.array([False, True])).round(3).tolist()
    [0.25]
    """
    w = np.asarray(w, dtype=np.float64)
    h = perceptual_weights(w)
    codewords = cb_lsf if exclude is None else cb_lsf[~np.asarray(exclude, bool)]
    if len(codewords) == 0:
        return np.full(len(w), np.nan)
    out = np.full(len(w), np.inf)
    for a in range(0, len(w), chunk):
        for b in range(0, len(codewords), block):
            near = lsf_distances(w[a:a + chunk], codewords[None, b:b + block], h[a:a + chunk])
            np.minimum(out[a:a + chunk], near.min(axis=1), out=out[a:a + chunk])
    return out


def voice_distance(w: np.ndarray, speech: np.ndarray, cb_lsf: np.ndarray,
                   index: LsfIndex | None = None, exclude: np.ndarray | None = None,
                   max_frames: int = MAX_FRAMES, nearest: np.ndarray | None = None) -> float:
    """The median, over (at most ``max_frames`` evenly spaced) speech frames, of eq 5's distance
    to the nearest codeword; through the model's LSF ``index`` when given (:data:`PROBE` cells
    probed; ``nearest``: every frame's nearest codeword found so already, by the acoustic
    search), else exact. NaN without speech frames."""
    frames = np.flatnonzero(np.asarray(speech, bool))
    if frames.size == 0:
        return float("nan")
    frames = frames[np.linspace(0, frames.size - 1, min(frames.size, max_frames)).astype(int)]
    w = np.asarray(w, dtype=np.float64)[frames]
    if index is None:
        d = nearest_distances(w, cb_lsf, exclude)
        return float(np.median(d)) if np.isfinite(d).all() else float("nan")
    return median(indexed_distances(w, cb_lsf, index, None if nearest is None else nearest[frames]))


def indexed_distances(w: np.ndarray, cb_lsf: np.ndarray, index: LsfIndex,
                      near: np.ndarray | None = None) -> np.ndarray:
    """Per frame of ``w`` ``(T, P)``, eq 5's distance to the nearest codeword found through the
    model's LSF ``index`` (:data:`PROBE` cells probed; ``near``: those codewords, when found
    already): what :func:`voice_distance` takes the median of."""
    if near is None:
        near = index.nearest(np.asarray(w, dtype=np.float64), cb_lsf, 1, PROBE)[:, 0]
    return lsf_distances(w, cb_lsf[near][:, None, :])[:, 0]


def training_voice_distance(lsf: Sequence[np.ndarray], speech: Sequence[np.ndarray],
                            codeword_utterance: np.ndarray, cb_lsf: np.ndarray,
                            workers: int = 1) -> float:
    """``D0``: the median over training utterances of :func:`voice_distance`, each with its own
    codewords left out (``codeword_utterance`` ``(5L,)``: the index, in ``lsf``'s order, of the
    utterance each codeword comes from), in ``workers`` processes."""
    from ..fanout import fan_out  # training's: not for a synthesis's start

    def one(k: int) -> float:
        return voice_distance(lsf[k], speech[k], cb_lsf, exclude=codeword_utterance == k)

    d = [x for _, x in fan_out(one, range(len(lsf)), workers)]
    d = [x for x in d if np.isfinite(x)]
    return float(np.median(d)) if d else float("nan")


def voice_match(distance: float, reference: float) -> float:
    """The voice-match figure in [0, 1]: 1 up to ``MATCH_FULL`` times the training voice's
    ``reference`` distance, 0 from ``MATCH_NONE`` times it, linear in log distance between
    (NaN when either is unknown).

    >>> voice_match(2.5, 2.5), voice_match(7.5, 2.5), round(voice_match(2.5 * 4.5 ** 0.5, 2.5), 3)
    (1.0, 0.0, 0.5)
    """
    if not (np.isfinite(distance) and np.isfinite(reference) and reference > 0):
        return float("nan")
    x = np.log(max(distance, 1e-12) / (MATCH_FULL * reference)) / np.log(MATCH_NONE / MATCH_FULL)
    return float(np.clip(1.0 - x, 0.0, 1.0))


def label_weight_scale(ratio: float, by_voice: bool = True) -> float:
    """The factor of the robust mode's label weight for a voice at distance ratio ``ratio``
    (``D / D0``): the ratio, at least 1 (eq 5's distances grow on a voice the codebook does not
    know, and the labels must keep their weight against them); 1 when the ratio is unknown or
    ``by_voice`` is off (``SynthConfig.label_weight_by_voice``).

    >>> label_weight_scale(4.2), label_weight_scale(0.8), label_weight_scale(float("nan"))
    (4.2, 1.0, 1.0)
    """
    return max(1.0, float(ratio)) if by_voice and np.isfinite(ratio) else 1.0


def trust_by_voice(confidence: np.ndarray, ratio: float, by_voice: bool = True) -> np.ndarray:
    """Labels weighed by voice (issue 25): ``c' = 1 - (1 - c) m``, ``m`` the voice match of the
    distance ``ratio``. On the training voice (``m = 1``) a label counts as much as its maker
    trusted it; on a voice the codebook does not know (``m = 0``) the acoustic distances are the
    untrustworthy part and the labels count fully (the recognizer and the aligner were trained on
    many voices, the codebook on one; their scores drop on such a voice for every phone). The
    confidence as it is when the ratio is unknown or ``by_voice`` is off.

    >>> trust_by_voice(np.array([0.2, 1.0]), 1.0).round(9).tolist()
    [0.2, 1.0]
    >>> trust_by_voice(np.array([0.2]), 5.0).tolist(), trust_by_voice(np.array([0.2]), 5.0, False).tolist()
    ([1.0], [0.2])
    """
    c = np.asarray(confidence, dtype=np.float64)
    if not by_voice or not np.isfinite(ratio):
        return c.copy()
    return 1.0 - (1.0 - c) * voice_match(ratio, 1.0)


#: What the voice match means, for the log and the app's tooltip.
MATCH_RANGE = (f"1 = the training voice's (D/D0 up to {MATCH_FULL:g}), 0 = a voice the codebook "
               f"does not know (D/D0 {MATCH_NONE:g} or more)")


def explain_match(ratio: float, config: SynthConfig, kind: str | None) -> str:
    """The voice match of a synthesis at distance ratio ``ratio`` (``D / D0``) in words: what its
    range means, and what it changed in this run (``config``: its settings; ``kind``: how its
    labels were made, ``None`` without labels) -- the robust mode's label confidences and label
    weight (:func:`trust_by_voice`, :func:`label_weight_scale`), the closure step's trust in
    recognized /p b m/ (:func:`facetraj_engine.method.closure.closure_strengths`).

    >>> explain_match(4.2, SynthConfig(mode="robust"), "aligned")  # doctest: +NORMALIZE_WHITESPACE
    "voice match 0.00 (D/D0 4.20; 1 = the training voice's (D/D0 up to 1.5), 0 = a voice the
    codebook does not know (D/D0 3 or more)); here: label confidences raised to 1 (by 1 - match),
    the label weight x4.20, so the labels count over acoustics the codebook does not know"
    >>> print(explain_match(1.0, SynthConfig(), "hand-checked").split("; here: ")[1])
    changed nothing (the phonetic mode trusts its labels; the lips close at every labelled /p b m/)
    """
    m = voice_match(ratio, 1.0)
    if not np.isfinite(m):
        return ("voice match unknown (no speech measured, or a model file without the training "
                "voice's distance D0): nothing weighed by it")
    changed = []
    if config.mode == "robust" and config.label_weight_by_voice:
        raised = "raised to 1 (by 1 - match)" if m == 0 else \
            f"raised towards 1 (by 1 - match = {1 - m:.2f})" if m < 1 else "as their maker gave them"
        changed.append(f"label confidences {raised}, the label weight "
                       f"x{label_weight_scale(ratio):.2f}")
        if m < 1:
            changed[-1] += ", so the labels count over acoustics the codebook does not know"
    if config.closure and kind == "recognized":
        changed.append(f"recognized /p b m/ closed with strength {1 - m:.2f} (1 - match)")
    if not changed:
        why = {"phonetic": "the phonetic mode trusts its labels",
               "acoustic": "no labels to weigh"}.get(config.mode, "weighing by voice is off")
        closing = ("the lips close at every labelled /p b m/" if config.closure and kind
                   else "no closure step" if not config.closure else "no /p b m/ labels")
        changed.append(f"changed nothing ({why}; {closing})")
    return f"voice match {m:.2f} (D/D0 {ratio:.2f}; {MATCH_RANGE}); here: " + "; ".join(changed)
