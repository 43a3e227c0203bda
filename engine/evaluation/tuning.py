"""Cross-validated synthesis settings (issues 16, 24): the robust mode's N, label weight,
acoustic candidates and gamma's range, and the smoothing width, chosen on the *training* split
only (never the test split) and stored in the model (:attr:`facetraj_engine.method.model.Model.tuned`).

K folds of the training utterances: a model trained on K-1 folds synthesizes (up to
``max_per_fold`` utterances of) the held-out fold; a setting's score is the mean correlation
(whole face, lower lip and upper lip averaged, triangular smoothing, speech frames: as Table 2)
over all held-out utterances, at the best of the smoothing widths (scored on the same
syntheses, only re-smoothed). The settings are searched one at a time along ordered ladders of
values (:func:`coordinate_search`), from the defaults, each moved to its best neighbour and the
search widened past an edge until the best value has a worse one on either side (or is the
ladder's last): so a chosen value sits inside what was searched, and its curve -- the score of
every value tried with the others at their chosen values -- is kept with the choice.
"""

from __future__ import annotations

import logging
import time
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

#: The settings searched, each an ordered ladder of values (robust mode).
LADDERS: dict[str, tuple] = {
    "n_context_phones": (1, 2, 3, 4, 6, 8, 12, 16, 24, 32),
    "label_weight": (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0),
    "robust_candidates": (8, 16, 32, 64, 128),
    "gamma_max": (0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 12.0),
    "chain_beta": (0.0, 0.03, 0.1, 0.2, 0.4, 0.8),
}
#: Values that are their setting's own limit, with nothing beyond them to search: one
#: context-phone, no chain. A choice there is not "at the end of its range".
LIMITS: dict[str, object] = {"n_context_phones": 1, "chain_beta": 0.0}
#: Where the search starts: the defaults of SynthConfig.
START = {k: getattr(SynthConfig(), k) for k in LADDERS}
#: Triangular smoothing widths scored on every synthesis (seconds).
WIDTHS = (0.033, 0.05, 0.067, 0.083, 0.1, 0.133, 0.167, 0.2)


@dataclass
class Tuning:
    """The result of :func:`cross_validate`: the chosen ``settings`` (SynthConfig fields), each
    searched setting's ``curves`` (``[value, score]`` with the others at their chosen values),
    the settings left at the end of their ladder (``at_end``), and every setting scored."""

    settings: dict
    scores: list[dict] = field(default_factory=list)
    folds: int = 2
    utterances: int = 0
    curves: dict = field(default_factory=dict)
    at_end: list[str] = field(default_factory=list)
    seconds: float = 0.0

    def to_json(self) -> dict:
        return {"settings": self.settings, "scores": self.scores, "folds": self.folds,
                "utterances": self.utterances, "split": "train", "curves": self.curves,
                "at_end": self.at_end, "seconds": round(self.seconds, 1)}


def coordinate_search(score: Callable[[dict], float], ladders: Mapping[str, Sequence],
                      start: Mapping, rounds: int = 3, limits: Mapping[str, object] = LIMITS
                      ) -> tuple[dict, dict, list[str]]:
    """The settings maximising ``score`` one at a time along their ``ladders``, from ``start``:
    each moves to its best neighbour, the window widened past an edge until the best value has a
    worse one on either side or is the ladder's last; until a round changes nothing. Returns the
    settings, each one's curve (``[[value, score], ...]`` at the final settings) and the settings
    left at the end of their ladder (other than at their own ``limits``). ``score`` is called once
    per distinct settings.

    >>> best, curves, ends = coordinate_search(lambda s: -(s["a"] - 3) ** 2 - (s["b"] - 1) ** 2,
    ...                                        {"a": (0, 1, 2, 3, 4, 5), "b": (1, 2, 3)}, {"a": 1, "b": 2})
    >>> best, ends, [v for v, _ in curves["a"]]
    ({'a': 3, 'b': 1}, ['b'], [2, 3, 4])
    """
    memo: dict[tuple, float] = {}

    def scored(settings: dict) -> float:
        key = tuple(sorted(settings.items()))
        if key not in memo:
            memo[key] = float(score(dict(settings)))
        return memo[key]

    current = dict(start)
    for _ in range(rounds):
        changed = False
        for name, ladder in ladders.items():
            best = _line_search(lambda v, name=name: scored({**current, name: v}), list(ladder),
                                ladder.index(current[name]))
            changed |= best != current[name]
            current[name] = best
        if not changed:
            break
    curves = {name: [[v, memo[k]] for v in ladder
                     if (k := tuple(sorted({**current, name: v}.items()))) in memo]
              for name, ladder in ladders.items()}
    ends = [name for name, ladder in ladders.items()
            if current[name] in (ladder[0], ladder[-1]) and current[name] != limits.get(name)]
    return current, curves, ends


def _line_search(f: Callable[[object], float], ladder: list, i: int) -> object:
    """The best value of ``ladder`` near index ``i``, widening past an edge while it improves."""
    lo, hi = max(i - 1, 0), min(i + 1, len(ladder) - 1)
    values = {j: f(ladder[j]) for j in range(lo, hi + 1)}
    while True:
        best = max(values, key=lambda j: (values[j], -abs(j - i)))
        if best == lo and lo > 0:
            lo -= 1
            values[lo] = f(ladder[lo])
        elif best == hi and hi < len(ladder) - 1:
            hi += 1
            values[hi] = f(ladder[hi])
        else:
            return ladder[best]


def fold_ids(ids: Sequence[str], folds: int) -> list[list[str]]:
    """Utterance ids dealt into ``folds`` interleaved folds.

    >>> fold_ids(["a", "b", "c", "d", "e"], 2)
    [['a', 'c', 'e'], ['b', 'd']]
    """
    return [list(ids[k::folds]) for k in range(folds)]


@dataclass
class _Held:
    """A held-out utterance of a fold, with what every setting's synthesis reuses."""

    model: object
    utt: object
    original: np.ndarray
    mask: np.ndarray
    lsf: np.ndarray


def _fold_data(corpus: Corpus, train_config: TrainConfig | None, folds: int,
               max_per_fold: int | None, progress: Callable[[float, str], None]) -> list[_Held]:
    ids = list(corpus.info.train)
    held_all = []
    for f, held in enumerate(fold_ids(ids, folds)):
        rest = [u for u in ids if u not in set(held)]
        sub = replace(corpus, info=replace(corpus.info, train=rest, test=[]))
        progress(0.3 * f / folds, f"fold {f + 1}/{folds}: training")
        model = train(sub, config=train_config)
        if max_per_fold is not None and len(held) > max_per_fold:
            held = [held[int(i)] for i in np.linspace(0, len(held) - 1, max_per_fold)]
        for utt_id in held:
            utt = corpus.utterance(utt_id)
            held_all.append(_Held(model, utt, model.normalise_markers(utt.markers),
                                  speech_mask(utt.audio, utt.sample_rate, utt.frame_times()),
                                  model.input_lsf(utt.audio, utt.sample_rate,
                                                  np.arange(utt.n_frames) / model.marker_rate)))
    return held_all


def _width_scores(held: list[_Held], settings: Mapping, widths: Sequence[float]) -> np.ndarray:
    """The mean held-out correlation of ``settings`` at each smoothing width."""
    totals, counts = np.zeros(len(widths)), np.zeros(len(widths))
    for h in held:
        cfg = SynthConfig(mode="robust", smoothing="none", closure=False, **settings)
        res = synthesize(h.model, h.utt.audio, h.utt.sample_rate, h.utt.phones, cfg,
                         n_frames=h.utt.n_frames, source=h.utt.name, lsf=h.lsf,
                         confidence=h.utt.confidence, provenance=h.utt.provenance)
        for k, width in enumerate(widths):
            pcs = smooth(res.raw_pcs, h.model.marker_rate, "triangular", width)
            c = trajectory_correlations(h.original, h.model.to_markers(pcs), h.mask, h.model)
            score = np.nanmean(list(c.values()))
            if np.isfinite(score):
                totals[k] += score
                counts[k] += 1
    return np.where(counts > 0, totals / np.maximum(counts, 1), -np.inf)


def cross_validate(corpus: Corpus, train_config: TrainConfig | None = None,
                   ladders: Mapping[str, Sequence] = LADDERS, start: Mapping | None = None,
                   widths: Sequence[float] = WIDTHS, folds: int = 2, max_per_fold: int | None = 12,
                   progress: Callable[[float, str], None] | None = None) -> Tuning:
    """Choose the robust mode's settings by ``folds``-fold cross-validation on ``corpus``'s
    training split (see the module docstring): :func:`coordinate_search` over ``ladders`` from
    ``start`` (default :data:`START`), the smoothing width the best of ``widths`` for each
    setting. The utterances' labels are weighed by their own confidence; ``max_per_fold``
    held-out utterances are scored per fold (evenly spread) to bound the time."""
    ids = list(corpus.info.train)
    if not 2 <= folds <= len(ids):
        raise InputError(corpus.root, f"{folds}-fold cross-validation needs 2 to {len(ids)} folds "
                                      f"(one per training utterance at most)")
    progress = progress or (lambda f, m: None)
    t0 = time.monotonic()
    held = _fold_data(corpus, train_config, folds, max_per_fold, progress)
    tried: list[dict] = []
    expected = 3 * len(ladders) + 2            # a typical search: about three values a setting

    def score(settings: dict) -> float:
        progress(min(0.3 + 0.7 * len(tried) / expected, 0.99),
                 "setting " + ", ".join(f"{k}={v:g}" for k, v in settings.items()))
        per_width = _width_scores(held, settings, widths)
        k = int(np.argmax(per_width))
        tried.append({**settings, "triangle_s": float(widths[k]), "score": float(per_width[k])})
        return float(per_width[k])

    best, curves, ends = coordinate_search(score, ladders, START if start is None else start)
    chosen = next(s for s in tried if all(s[k] == v for k, v in best.items()))
    settings = {k: v for k, v in chosen.items() if k != "score"}
    log.info("cross-validated robust settings: %s (mean held-out correlation %.4f, %d settings "
             "scored)%s", settings, chosen["score"], len(tried),
             f"; at the end of their range: {', '.join(ends)}" if ends else "")
    progress(1.0, "cross-validation done")
    return Tuning(settings, tried, folds, len(held), curves, ends, time.monotonic() - t0)
