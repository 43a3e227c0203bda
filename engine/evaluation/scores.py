"""Evaluation (paper section 3): speech-only frames by median-filtered energy, and the correlation
between original and synthesized trajectories (Table 2, Figure 5).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import ClassVar

import numpy as np

from ..config import EvalConfig, SynthConfig
from ..data import Utterance
from ..fanout import Skips, fan_out
from ..io.corpus import Corpus
from ..method.model import Model
from ..method.modes import choose_mode
from ..method.pipeline import Synthesis, resmooth, synthesize
from ..method.speech import speech_mask
from ..threads import limit_frame_threads, one_blas_thread, usable_cores
from .closed_lips import (
    CLOSED_TOL_MM,
    ClosureAgreement,
    TalkerClosed,
    TalkerLips,
    agreements,
    talker_closed,
    talker_lips,
)
from .correlation import pearson
from .sensors import SensorTable, pooled, sensor_scores

log = logging.getLogger(__name__)

METRICS = ("whole_face", "lower_lip", "upper_lip")


def moving_coordinates(model: Model, fraction: float = 0.1) -> np.ndarray:
    """Flat indices (into ``M * 3``) of the coordinates that move: training std >= ``fraction`` of
    the largest coordinate std. These make up the "whole face" average."""
    std = model.coord_std
    return np.flatnonzero(std >= fraction * std.max())


def trajectory_correlations(original: np.ndarray, synthesized: np.ndarray, mask: np.ndarray,
                            model: Model, config: EvalConfig | None = None) -> dict[str, float]:
    """Correlations on the frames in ``mask``: whole face (mean over moving coordinates), lower
    lip y and upper lip y. ``original`` and ``synthesized`` are ``(T, M, 3)`` head-normalised."""
    config = config or EvalConfig()
    ok = mask & np.isfinite(original).all(axis=(1, 2)) & np.isfinite(synthesized).all(axis=(1, 2))
    width = int(np.prod(original.shape[1:]))    # explicit: no frame at all may be left
    o = original[ok].reshape(int(ok.sum()), width)
    s = synthesized[ok].reshape(int(ok.sum()), width)
    coords = moving_coordinates(model, config.moving_fraction)
    per = np.array([pearson(o[:, c], s[:, c]) for c in coords])
    y = 1
    return {
        "whole_face": float(np.nanmean(per)) if np.isfinite(per).any() else float("nan"),
        "lower_lip": pearson(o[:, model.lower_lip * 3 + y], s[:, model.lower_lip * 3 + y]),
        "upper_lip": pearson(o[:, model.upper_lip * 3 + y], s[:, model.upper_lip * 3 + y]),
    }


@dataclass
class ConditionScores:
    """The three correlations of section 3 (whole face, lower lip, upper lip) under one condition:
    split, synthesis mode, smoothing and N. One utterance's scores (:class:`UtteranceScore`) and a
    mean over utterances (a Table 2 row) share these fields."""

    split: str
    mode: str
    smoothing: str
    n_context_phones: int
    whole_face: float
    lower_lip: float
    upper_lip: float


@dataclass(kw_only=True)
class UtteranceScore(ConditionScores):
    """Correlations of one utterance under one condition, on its ``speech_frames`` frames; and on
    the same frames the synthesized closures against the talker's own lips
    (:mod:`facetraj_engine.evaluation.closed_lips`: frames closed in the original, in the synthesis,
    in both; counted once the talker's closed value is known, :func:`evaluate`); ``sensors``:
    every sensor coordinate's r and RMSE (:func:`~facetraj_engine.evaluation.sensors.sensor_scores`,
    set by the evaluation; not a field, so not in a score's JSON: :meth:`EvalResult.sensor_table`
    pools them)."""

    utterance: str
    speech_frames: int
    closed_frames: int = 0
    synthesized_closed_frames: int = 0
    both_closed_frames: int = 0
    sensors: ClassVar[tuple] = ()

    @property
    def closures(self) -> ClosureAgreement:
        return ClosureAgreement(self.closed_frames, self.synthesized_closed_frames,
                                self.both_closed_frames)

    def set_closures(self, agreement: ClosureAgreement) -> None:
        self.closed_frames, self.synthesized_closed_frames, self.both_closed_frames = \
            agreement.talker, agreement.synthesized, agreement.both


def _nanmean(values: Sequence[float]) -> float:
    """Mean of the finite values; NaN (without numpy's warning) when there are none, e.g. an
    utterance whose markers have no complete frame."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    return float(v.mean()) if v.size else float("nan")


@dataclass
class EvalResult:
    """Per-utterance scores and their averages per condition, and the talker's closed lip
    aperture the closures were judged by (``None``: not measured)."""

    scores: list[UtteranceScore] = field(default_factory=list)
    talker: TalkerClosed | None = None

    def mean(self, split: str, smoothing: str, mode: str = "phonetic",
             n: int | None = None) -> dict[str, float]:
        """Mean correlation over utterances of one condition (the paper averages utterances), and
        the closures' precision and recall against the talker's lips, pooled over its frames."""
        rows = [r for r in self.scores if r.split == split and r.smoothing == smoothing
                and r.mode == mode and (n is None or r.n_context_phones == n)]
        pooled = ClosureAgreement.pooled([r.closures for r in rows])
        return {**{m: _nanmean([getattr(r, m) for r in rows]) for m in METRICS},
                "closure_precision": pooled.precision, "closure_recall": pooled.recall}

    def sensor_table(self, split: str, smoothing: str, mode: str = "phonetic",
                     n: int | None = None) -> SensorTable:
        """Per-sensor r and RMSE (mm) of one condition over its utterances
        (:func:`~facetraj_engine.evaluation.sensors.pooled`)."""
        return pooled(r.sensors for r in self.scores if r.split == split and r.smoothing == smoothing
                      and r.mode == mode and (n is None or r.n_context_phones == n))

    def conditions(self) -> list[tuple[str, str, str, int]]:
        seen: dict[tuple[str, str, str, int], None] = {}
        for r in self.scores:
            seen[(r.split, r.mode, r.smoothing, r.n_context_phones)] = None
        return list(seen)

    def table(self) -> list[dict]:
        """One row per condition with the three mean correlations (Table 2 layout)."""
        return [{"split": sp, "mode": mo, "smoothing": sm, "n_context_phones": n,
                 **self.mean(sp, sm, mo, n)} for sp, mo, sm, n in self.conditions()]

    def to_json(self) -> dict:
        # the utterance first, as it reads
        return {"table": self.table(),
                **({"talker_closed": self.talker.to_json()} if self.talker is not None else {}),
                "utterances": [{"utterance": r.utterance, **asdict(r),
                                "closure_precision": r.closures.precision,
                                "closure_recall": r.closures.recall} for r in self.scores],
                "sensors": [{"split": sp, "mode": mo, "smoothing": sm, "n_context_phones": n,
                             **self.sensor_table(sp, sm, mo, n).to_json()}
                            for sp, mo, sm, n in self.conditions()]}


def evaluate_utterance(model: Model, utt: Utterance, split: str = "test",
                       config: SynthConfig | None = None,
                       smoothings: Sequence[str] = ("triangular", "spline"),
                       eval_config: EvalConfig | None = None,
                       synthesis: Synthesis | None = None, original: np.ndarray | None = None,
                       speech: np.ndarray | None = None,
                       lsf: np.ndarray | None = None,
                       lips: TalkerLips | None = None) -> list[UtteranceScore]:
    """Synthesize one utterance and score each smoothing against its original markers.

    With ``eval_config.by_labels`` the mode follows the utterance's labels as in every command;
    otherwise ``config`` is used as it is. Robust synthesis weighs each label by the utterance's
    ``confidence``.

    ``original`` (head-normalised markers), ``speech`` (the speech-frame mask) and ``lsf`` (the
    input LSFs, :meth:`Model.input_lsf`) may be passed when already computed, e.g. when one
    utterance is scored under several configs. ``lips``: the utterance's
    :class:`~facetraj_engine.evaluation.closed_lips.TalkerLips`, given each smoothing's face.
    """
    config = config or SynthConfig()
    if eval_config is not None and eval_config.by_labels:
        config = choose_mode(config, utt.phones, utt.provenance, tuned=model.tuned,
                             keep=eval_config.keep).config
    if utt.markers is None:
        raise ValueError(f"{utt.name}: no original markers to compare with")
    if original is None:
        original = model.normalise_markers(utt.markers)
    res = synthesis or synthesize(model, utt.audio, utt.sample_rate, utt.phones, config,
                                  n_frames=utt.n_frames, source=utt.name, lsf=lsf,
                                  confidence=utt.confidence, provenance=utt.provenance,
                                  checked=utt.checked)
    mask = speech if speech is not None else speech_mask(utt.audio, utt.sample_rate, res.times,
                                                         eval_config)
    out = []
    for sm in smoothings:
        markers = resmooth(model, res, sm)
        if lips is not None:
            lips.add(markers)
        c = trajectory_correlations(original, markers, mask, model, eval_config)
        out.append(UtteranceScore(split=split, mode=config.mode, smoothing=sm,
                                  n_context_phones=config.n_context_phones, **c,
                                  utterance=utt.name, speech_frames=int(mask.sum())))
        out[-1].sensors = tuple(sensor_scores(original, markers, mask, model))
    return out


def _score_utterance(model: Model, corpus: Corpus, split: str, utt_id: str,
                     configs: Sequence[SynthConfig], smoothings: Sequence[str],
                     eval_config: EvalConfig | None) -> tuple[list[UtteranceScore], TalkerLips]:
    """Every config's scores of one corpus utterance (its audio, markers and LSFs read once),
    and its lips (:class:`~facetraj_engine.evaluation.closed_lips.TalkerLips`, a face per score)."""
    utt = corpus.utterance(utt_id)
    original = model.normalise_markers(utt.markers)
    times = utt.frame_times()
    speech = speech_mask(utt.audio, utt.sample_rate, times, eval_config)
    lsf = model.input_lsf(utt.audio, utt.sample_rate,                 # synthesize()'s frames
                          np.arange(utt.n_frames) / model.marker_rate)
    lips = talker_lips(original, times, utt.phones, speech, model.upper_lip, model.lower_lip)
    out: list[UtteranceScore] = []
    for cfg in configs:
        out.extend(evaluate_utterance(model, utt, split, cfg, smoothings, eval_config,
                                      original=original, speech=speech, lsf=lsf, lips=lips))
    return out, lips


def judged_by_the_talker(done: Sequence[tuple[list[UtteranceScore], TalkerLips]]) -> EvalResult:
    """The utterances' scores with their closures counted against the talker's closed value,
    found over all of them (:func:`~facetraj_engine.evaluation.closed_lips.talker_closed`)."""
    parts = [lips for _, lips in done]
    talker = talker_closed(parts)
    for (scores, _), counts in zip(done, agreements(parts, talker), strict=True):
        for score, agreement in zip(scores, counts, strict=True):
            score.set_closures(agreement)
    return EvalResult([s for scores, _ in done for s in scores], talker)


def default_workers() -> int:
    """Worker processes for :func:`evaluate` by default: the cores this process may use."""
    return usable_cores()


def evaluate(model: Model, corpus: Corpus, splits: Iterable[str] = ("train", "test"),
             configs: Sequence[SynthConfig] | None = None,
             smoothings: Sequence[str] = ("triangular", "spline"),
             eval_config: EvalConfig | None = None,
             progress: Callable[[float, str], None] | None = None,
             workers: int = 1, skip: Skips | None = None) -> EvalResult:
    """Score every utterance of ``splits`` under each synthesis config (Table 2 and more), and
    judge its synthesized closures by the talker's own lips
    (:mod:`facetraj_engine.evaluation.closed_lips`, the closed value found over these utterances).

    With ``workers > 1`` the utterances are scored in that many processes
    (:func:`facetraj_engine.fanout.fan_out`: forked, so the model is shared, not copied through pickle);
    each utterance is independent, and the scores come back in corpus order, equal to the serial
    run's. BLAS runs on one thread either way (:mod:`facetraj_engine.threads`): the processes share the
    cores, and the serial run computes the same sums in the same order; and each utterance is
    synthesized on one frame thread (:func:`facetraj_engine.threads.limit_frame_threads`), in the serial
    run too, so that the scores do not depend on ``workers`` even at rounding level.

    An utterance with a bad file stops the evaluation with that file's error, whatever
    ``workers``; with ``skip`` it is left out and recorded there (``--skip-bad``).
    """
    splits = list(splits)
    configs = list(configs or [SynthConfig()])
    split_of = {u: sp for sp in splits for u in getattr(corpus.info, sp)}

    def score(utt_id: str) -> tuple[list[UtteranceScore], TalkerLips]:
        with limit_frame_threads(1):        # also in a worker, which may run in a new context
            return _score_utterance(model, corpus, split_of[utt_id], utt_id, configs,
                                    list(smoothings), eval_config)

    with one_blas_thread(), limit_frame_threads(1):
        done = fan_out(score, list(split_of), workers, skip=skip, progress=progress,
                       describe=lambda u: f"{split_of[u]}: {u}")
        return judged_by_the_talker([result for _, result in done])


def table2(model: Model, corpus: Corpus, acoustic: bool = True,
           eval_config: EvalConfig | None = None,
           progress: Callable[[float, str], None] | None = None, workers: int = 1,
           skip: Skips | None = None) -> EvalResult:
    """The paper's Table 2 (train/test x triangular/spline, N = 3), plus acoustic-only rows
    (the paper's whole-codebook search, ``acoustic_prefilter=None``)."""
    configs = [SynthConfig(mode="phonetic", closure=False)]          # the paper's, as it is
    if acoustic:
        configs.append(SynthConfig(mode="acoustic", acoustic_prefilter=None, closure=False))
    return evaluate(model, corpus, ("train", "test"), configs, ("triangular", "spline"),
                    eval_config, progress, workers, skip)


def sweep_n(model: Model, corpus: Corpus, ns: Sequence[int] = tuple(range(1, 11)),
            splits: Sequence[str] = ("train", "test"), eval_config: EvalConfig | None = None,
            progress: Callable[[float, str], None] | None = None, workers: int = 1,
            skip: Skips | None = None) -> EvalResult:
    """Correlation against N (the paper's Figure 5), triangular smoothing."""
    configs = [SynthConfig(n_context_phones=n, closure=False) for n in ns]
    if eval_config is not None and eval_config.by_labels:       # the sweep sets N, not the tuning
        eval_config = replace(eval_config, keep=(*eval_config.keep, "n_context_phones"))
    return evaluate(model, corpus, splits, configs, ("triangular",), eval_config, progress,
                    workers, skip)


def format_table2(result: EvalResult) -> str:
    """Table 2 as text: one line per condition with whole face, lower lip, upper lip, and the
    closures' precision and recall against the talker's lips (the closed value said below)."""
    lines = [f"{'Test condition':<34} {'Whole Face':>10} {'Lower Lip':>10} {'Upper Lip':>10} "
             f"{'Closed P':>9} {'Closed R':>9}"]
    for row in result.table():
        name = f"{row['split'].title()} ({row['smoothing']}, {row['mode']}, N={row['n_context_phones']})"
        lines.append(f"{name:<34} {row['whole_face']:>10.4f} {row['lower_lip']:>10.4f} "
                     f"{row['upper_lip']:>10.4f} {row['closure_precision']:>9.3f} "
                     f"{row['closure_recall']:>9.3f}")
    if result.talker is not None:
        lines.append(f"Closed P, R: the share of the synthesized frames closed within "
                     f"{CLOSED_TOL_MM:g} mm that are closed in the original, and the reverse; "
                     f"{result.talker.describe()}")
    return "\n".join(lines)

