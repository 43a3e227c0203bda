"""Cross-validated synthesis settings (issue 16): gamma's range, N, the robust mode's label
weight and acoustic candidate count, and the smoothing width (any other SynthConfig field, e.g.
xi or the context weight, can be put in the grid), chosen on the *training* split only (never the test
split) and stored in the model (:attr:`engine.method.model.Model.tuned`).

K folds of the training utterances: a model trained on K-1 folds synthesizes the held-out fold
under every candidate setting; the setting with the best mean correlation (whole face, lower lip
and upper lip averaged, triangular smoothing, speech frames: as Table 2) over all held-out
utterances wins. The smoothing width is scored on the same syntheses (only re-smoothed).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from ..config import SynthConfig, TrainConfig
from ..errors import InputError
from ..io.corpus import Corpus
from ..method.pipeline import synthesize
from ..method.smoothing import smooth
from ..method.training import train
from .scores import speech_mask, trajectory_correlations

log = logging.getLogger(__name__)

#: The settings searched (robust mode): one dict of SynthConfig fields per candidate.
DEFAULT_GRID: tuple[dict, ...] = tuple(
    {"n_context_phones": n, "label_weight": k, "robust_candidates": c, "gamma_max": g}
    for n in (3, 6) for k in (4.0, 16.0) for c in (16, 32) for g in (2.0, 5.0))
#: Triangular smoothing widths searched (seconds).
DEFAULT_WIDTHS = (0.067, 0.1, 0.133)
@dataclass
class Tuning:
    """The result of :func:`cross_validate`: the chosen ``settings`` (SynthConfig fields), and
    every candidate's mean held-out ``scores`` (``settings`` + ``score``)."""

    settings: dict
    scores: list[dict] = field(default_factory=list)
    folds: int = 2
    utterances: int = 0

    def to_json(self) -> dict:
        return {"settings": self.settings, "scores": self.scores, "folds": self.folds,
                "utterances": self.utterances, "split": "train"}


def fold_ids(ids: Sequence[str], folds: int) -> list[list[str]]:
    """Utterance ids dealt into ``folds`` interleaved folds.

    >>> fold_ids(["a", "b", "c", "d", "e"], 2)
    [['a', 'c', 'e'], ['b', 'd']]
    """
    return [list(ids[k::folds]) for k in range(folds)]


def cross_validate(corpus: Corpus, train_config: TrainConfig | None = None,
                   confidences: Mapping[str, np.ndarray] | None = None,
                   grid: Sequence[Mapping] = DEFAULT_GRID, widths: Sequence[float] = DEFAULT_WIDTHS,
                   folds: int = 2, max_per_fold: int | None = 12,
                   progress: Callable[[float, str], None] | None = None) -> Tuning:
    """Choose the robust mode's settings by ``folds``-fold cross-validation on ``corpus``'s
    training split (see the module docstring). ``confidences`` maps utterance id -> per-phone
    label confidence (automatic labels); ``max_per_fold`` held-out utterances are scored per fold
    (evenly spread) to bound the time."""
    ids = list(corpus.info.train)
    if not 2 <= folds <= len(ids):
        raise InputError(corpus.root, f"{folds}-fold cross-validation needs 2 to {len(ids)} folds "
                                      f"(one per training utterance at most)")
    parts = fold_ids(ids, folds)
    totals = np.zeros((len(grid), len(widths)))
    counts = np.zeros((len(grid), len(widths)))
    n_scored = 0
    for f, held in enumerate(parts):
        rest = [u for u in ids if u not in set(held)]
        sub = replace(corpus, info=replace(corpus.info, train=rest, test=[]))
        if progress:
            progress(f / folds, f"fold {f + 1}/{folds}: training")
        model = train(sub, config=train_config)
        if max_per_fold is not None and len(held) > max_per_fold:
            held = [held[int(i)] for i in np.linspace(0, len(held) - 1, max_per_fold)]
        for j, utt_id in enumerate(held):
            if progress:
                progress((f + (j + 1) / (len(held) + 1)) / folds, f"fold {f + 1}: {utt_id}")
            utt = corpus.utterance(utt_id)
            original = model.normalise_markers(utt.markers)
            mask = speech_mask(utt.audio, utt.sample_rate, utt.frame_times())
            lsf = model.input_lsf(utt.audio, utt.sample_rate,
                                  np.arange(utt.n_frames) / model.marker_rate)
            conf = None if confidences is None else confidences.get(utt_id)
            n_scored += 1
            for g, settings in enumerate(grid):
                cfg = SynthConfig(mode="robust", smoothing="none", closure=False, **settings)
                res = synthesize(model, utt.audio, utt.sample_rate, utt.phones, cfg,
                                 n_frames=utt.n_frames, source=utt.name, lsf=lsf, confidence=conf)
                for k, width in enumerate(widths):
                    pcs = smooth(res.raw_pcs, model.marker_rate, "triangular", width)
                    c = trajectory_correlations(original, model.to_markers(pcs), mask, model)
                    score = np.nanmean(list(c.values()))
                    if np.isfinite(score):
                        totals[g, k] += score
                        counts[g, k] += 1
    mean = totals / np.maximum(counts, 1)
    g, k = np.unravel_index(np.argmax(mean), mean.shape)
    settings = {**dict(grid[g]), "triangle_s": float(widths[k])}
    scores = [{**dict(grid[a]), "triangle_s": float(widths[b]), "score": float(mean[a, b])}
              for a in range(len(grid)) for b in range(len(widths))]
    log.info("cross-validated robust settings: %s (mean held-out correlation %.4f)", settings,
             mean[g, k])
    if progress:
        progress(1.0, "cross-validation done")
    return Tuning(settings, scores, folds, n_scored)
