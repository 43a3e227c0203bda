"""Two simple baselines to put the paper's method in perspective (issue 7), scored exactly like
Table 2 (:func:`~facetraj_engine.evaluation.scores.trajectory_correlations` on
:func:`~facetraj_engine.evaluation.scores.speech_mask` frames, the same smoothing).

* **Viseme lookup**: every frame gets the mean PC vector of its phone (the eq 1 idea applied
  directly, no acoustics, no context): what the phone labels alone explain.
* **Linear (ridge) regression**: PCs from the LSF vectors of frames t-5 .. t+5 stacked (the
  paper's own features, ~180 ms of context, no labels), by ridge regression; the regularisation
  is chosen on held-out *training* utterances, never on the test split.

Both work on the 60 Hz marker frames: LSFs from :func:`facetraj_engine.method.lsf.lsf_at` with the model's
analysis settings, PCs from the model's normalisation and PCA. Both are fitted from sufficient
statistics given one training utterance at a time (:class:`BaselineGather`: the phones' sums, the
moments of ``[features, PCs]``), so that a corpus is streamed through them. numpy only.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from ..config import EvalConfig
from ..data import Utterance
from ..fanout import fan_out
from ..io.corpus import Corpus
from ..labels.phoneset import normalise_label
from ..method.closure_detector import stacked
from ..method.context import segment_index
from ..method.model import Model
from ..method.moments import Moments
from ..method.smoothing import smooth
from ..threads import one_blas_thread
from .scores import UtteranceScore, speech_mask, trajectory_correlations
from .sensors import sensor_scores

log = logging.getLogger(__name__)

#: frames of LSF context on each side for the ridge baseline (+-5 frames at 60 Hz = +-83 ms)
RIDGE_CONTEXT = 5
#: ridge penalties tried (on standardised features, relative to the number of frames)
RIDGE_LAMBDAS = (1e-4, 1e-3, 1e-2, 1e-1, 1.0)


# ---------------------------------------------------------------------- per-frame data
@dataclass
class FrameData:
    """Per marker frame features and targets of one utterance.

    Attributes
    ----------
    name : utterance id.
    lsf : ``(T, P)`` LSF vectors centred on the frames (the model's analysis settings).
    pcs : ``(T, K)`` PC coefficients of the head-normalised markers (NaN where markers are missing).
    phone : ``(T,)`` model phone id of each frame, -1 for a phone the model does not know.
    original : ``(T, M, 3)`` head-normalised markers (the reference for scoring).
    speech : ``(T,)`` speech frames (energy + 112 ms median filter, as in section 3).
    """

    name: str
    lsf: np.ndarray
    pcs: np.ndarray
    phone: np.ndarray
    original: np.ndarray
    speech: np.ndarray


def frame_phone_ids(model: Model, utt: Utterance, times: np.ndarray) -> np.ndarray:
    """Model phone id at each time (-1 for labels the model does not know)."""
    if not utt.phones:
        return np.full(len(times), -1, dtype=np.int64)
    pid = {p: i for i, p in enumerate(model.phones)}
    ids = np.array([pid.get(normalise_label(s.label), -1) for s in utt.phones], dtype=np.int64)
    return ids[segment_index(utt.phones, times)]


def frame_data(model: Model, utt: Utterance, eval_config: EvalConfig | None = None,
               keep_original: bool = True) -> FrameData:
    """Features, targets and the speech mask of one utterance with markers (without
    ``keep_original``, its ``original`` markers are left empty: fitting does not need them)."""
    if utt.markers is None:
        raise ValueError(f"{utt.name}: no markers")
    times = utt.frame_times()
    lsf = model.input_lsf(utt.audio, utt.sample_rate, times)
    original = model.normalise_markers(utt.markers)
    pcs = model.to_pcs(original)
    return FrameData(utt.name, lsf, pcs, frame_phone_ids(model, utt, times),
                     original if keep_original else np.zeros((0, *original.shape[1:])),
                     speech_mask(utt.audio, utt.sample_rate, times, eval_config))


# ---------------------------------------------------------------------- viseme lookup
@dataclass
class VisemeLookup:
    """Mean PC vector per phone; ``fallback`` (the overall mean) for unknown or unseen phones.

    Attributes
    ----------
    table : ``(n_phones, K)`` mean PC vector of every phone (NaN rows for unseen phones).
    fallback : ``(K,)`` mean PC vector over all frames.
    """

    table: np.ndarray
    fallback: np.ndarray

    def predict(self, phone: np.ndarray) -> np.ndarray:
        """``(T, K)`` PCs: the table row of each frame's phone id."""
        phone = np.asarray(phone, dtype=np.int64)
        out = np.tile(self.fallback, (len(phone), 1))
        known = (phone >= 0) & (phone < len(self.table))
        rows = self.table[phone[known]]
        good = np.isfinite(rows).all(axis=1)
        idx = np.flatnonzero(known)[good]
        out[idx] = rows[good]
        return out


class VisemeGather:
    """:func:`fit_viseme` an utterance's frames at a time (in order): each phone's sum and count,
    and the running sum of every finite row, added row after row as of all frames at once (the
    same bits)."""

    def __init__(self, n_phones: int):
        self.n_phones = n_phones
        self.sums: np.ndarray | None = None
        self.counts = np.zeros(n_phones)
        self.total: np.ndarray | None = None
        self.n = 0

    def add(self, pcs: np.ndarray, phone: np.ndarray) -> None:
        pcs = np.asarray(pcs, dtype=np.float64)
        phone = np.asarray(phone, dtype=np.int64)
        if self.sums is None:
            self.sums, self.total = np.zeros((self.n_phones, pcs.shape[1])), np.zeros(pcs.shape[1])
        ok = np.isfinite(pcs).all(axis=1)
        self.total = np.add.reduce(np.concatenate([self.total[None], pcs[ok]]), axis=0)
        self.n += int(ok.sum())
        sel = ok & (phone >= 0)
        np.add.at(self.sums, phone[sel], pcs[sel])
        self.counts += np.bincount(phone[sel], minlength=self.n_phones)

    def lookup(self) -> VisemeLookup:
        with np.errstate(invalid="ignore", divide="ignore"):
            return VisemeLookup(self.sums / self.counts[:, None], self.total / self.n)


def fit_viseme(pcs: np.ndarray, phone: np.ndarray, n_phones: int) -> VisemeLookup:
    """Mean of the finite PC rows of each phone id (eq 1 over frames); ids < 0 only count in the
    fallback mean.

    Examples
    --------
    >>> v = fit_viseme(np.array([[1.0], [3.0], [10.0]]), np.array([0, 0, 1]), 3)
    >>> v.table.ravel().tolist()[:2], v.predict(np.array([1, 2, -1])).ravel().tolist()
    ([2.0, 10.0], [10.0, 4.666666666666667, 4.666666666666667])
    """
    gather = VisemeGather(n_phones)
    gather.add(pcs, phone)
    return gather.lookup()


# ---------------------------------------------------------------------- ridge regression
def stack_context(x: np.ndarray, k: int = RIDGE_CONTEXT) -> np.ndarray:
    """Stack the rows ``t-k .. t+k`` of ``x`` (``(T, P)``) into ``(T, (2k+1) P)``, edges repeated
    (:func:`facetraj_engine.method.closure_detector.stacked` at offsets ``-k .. k``); no rows
    are refused.

    Examples
    --------
    >>> stack_context(np.array([[1.0], [2.0], [3.0]]), 1).tolist()
    [[1.0, 1.0, 2.0], [1.0, 2.0, 3.0], [2.0, 3.0, 3.0]]
    """
    x = np.asarray(x, dtype=np.float64)
    if not len(x):
        raise ValueError("cannot stack the context of no rows")
    return stacked(x, range(-k, k + 1))


@dataclass
class RidgeRegression:
    """``y = y_mean + ((x - x_mean) / x_scale) @ coef``.

    Attributes
    ----------
    x_mean, x_scale : ``(D,)`` feature standardisation.
    y_mean : ``(K,)`` target mean (the intercept, not penalised).
    coef : ``(D, K)`` coefficients on standardised features.
    lam : the penalty used.
    """

    x_mean: np.ndarray
    x_scale: np.ndarray
    y_mean: np.ndarray
    coef: np.ndarray
    lam: float

    def predict(self, x: np.ndarray) -> np.ndarray:
        return self.y_mean + ((np.asarray(x) - self.x_mean) / self.x_scale) @ self.coef


def fit_ridge(x: np.ndarray, y: np.ndarray, lam: float) -> RidgeRegression:
    """Ridge regression on standardised features: ``coef = (Xs'Xs + lam I)^-1 Xs'(y - mean y)``.

    Features with zero variance get scale 1 (and so coefficient 0).

    Examples
    --------
    >>> x = np.array([[0.0], [1.0], [2.0]]); y = np.array([[0.0], [2.0], [4.0]])
    >>> fit_ridge(x, y, 0.0).predict(x).round(6).ravel().tolist()
    [0.0, 2.0, 4.0]
    >>> fit_ridge(x, y, 3.0).predict(x).round(6).ravel().tolist()    # Xs'Xs = 3: slope halved
    [1.0, 2.0, 3.0]
    """
    x = np.asarray(x, dtype=np.float64)
    return ridge_of(Moments.of(np.hstack([x, np.asarray(y, dtype=np.float64)])), x.shape[1], lam)


def ridge_of(moments: Moments, n_features: int, lam: float) -> RidgeRegression:
    """:func:`fit_ridge` from the moments of the rows ``[x, y]`` (``x`` their first
    ``n_features`` columns): ``Xs'Xs`` and ``Xs'(y - mean y)`` are their scatter's blocks over the
    features' standard deviations, so that the frames need not be held; ``lam = 0``: the
    minimum-norm least-squares solution."""
    p = n_features
    sxx, sxy = moments.scatter[:p, :p], moments.scatter[:p, p:]
    x_scale = moments.std()[:p]
    x_scale = np.where(x_scale > 0, x_scale, 1.0)
    gram = sxx / np.outer(x_scale, x_scale)
    gram[np.diag_indices_from(gram)] += lam
    rhs = sxy / x_scale[:, None]
    coef = np.linalg.solve(gram, rhs) if lam > 0 else np.linalg.lstsq(gram, rhs, rcond=None)[0]
    return RidgeRegression(moments.mean[:p], x_scale, moments.mean[p:], coef, float(lam))


def _design(fd: FrameData, k: int) -> tuple[np.ndarray, np.ndarray]:
    """One utterance's stacked features and targets, on its frames with complete markers."""
    ok = np.isfinite(fd.pcs).all(axis=1)
    return stack_context(fd.lsf, k)[ok], fd.pcs[ok]


class RidgeGather:
    """:func:`fit_ridge_baseline` an utterance at a time, in order, ``n_utterances`` in all: the
    moments of the fitting part (the first ones), then, as the held-out ones arrive (the fitting
    part complete by then), each penalty's squared error on them; the refit on all from the
    moments merged."""

    def __init__(self, n_utterances: int, k: int = RIDGE_CONTEXT,
                 lambdas: Sequence[float] = RIDGE_LAMBDAS, holdout: float = 0.2):
        self.k, self.lambdas = k, list(lambdas)
        n_hold = int(round(holdout * n_utterances)) if n_utterances >= 5 else 0
        self.n_fit = n_utterances - n_hold if n_hold and len(self.lambdas) > 1 else n_utterances
        self.fit: Moments | None = None
        self.held: Moments | None = None
        self.trials: list[RidgeRegression] = []
        self.errors = np.zeros(len(self.lambdas))
        self.values = 0
        self.seen = 0
        self.n_features = 0

    def add(self, fd: FrameData) -> None:
        x, y = _design(fd, self.k)
        m = Moments.of(np.hstack([x, y]))
        self.seen, self.n_features = self.seen + 1, x.shape[1]
        if self.seen <= self.n_fit:
            self.fit = m if self.fit is None else self.fit.merged(m)
            return
        if not self.trials:
            self.trials = [ridge_of(self.fit, x.shape[1], lam * self.fit.n) for lam in self.lambdas]
        self.errors += [float(((r.predict(x) - y) ** 2).sum()) for r in self.trials]
        self.values += y.size
        self.held = m if self.held is None else self.held.merged(m)

    def ridge(self) -> RidgeRegression:
        best = self.lambdas[0]
        if self.trials:
            mse = self.errors / max(self.values, 1)
            best = self.lambdas[int(np.argmin(mse))]
            log.info("ridge baseline: validation MSE %s -> lambda %g",
                     ", ".join(f"{e:.4g}" for e in mse), best)
        every = self.fit if self.held is None else self.fit.merged(self.held)
        return ridge_of(every, self.n_features, best * every.n)


def fit_ridge_baseline(frames: Iterable[FrameData], k: int = RIDGE_CONTEXT,
                       lambdas: Sequence[float] = RIDGE_LAMBDAS,
                       holdout: float = 0.2) -> RidgeRegression:
    """The ridge baseline on training utterances.

    The penalty ``lam * n_frames`` is chosen among ``lambdas`` by the PC-space squared error on
    the last ``holdout`` share of the training utterances (fitted on the rest), then the model is
    refitted on all of them.
    """
    frames = list(frames)
    gather = RidgeGather(len(frames), k, lambdas, holdout)
    for fd in frames:
        gather.add(fd)
    return gather.ridge()


# ---------------------------------------------------------------------- scoring
@dataclass
class Baselines:
    """The two fitted baselines."""

    viseme: VisemeLookup
    ridge: RidgeRegression
    context: int = RIDGE_CONTEXT

    def predict(self, name: str, fd: FrameData) -> np.ndarray:
        """Unsmoothed PCs ``(T, K)`` of baseline ``name`` (``viseme`` or ``ridge``)."""
        if name == "viseme":
            return self.viseme.predict(fd.phone)
        if name == "ridge":
            return self.ridge.predict(stack_context(fd.lsf, self.context))
        raise ValueError(f"unknown baseline {name!r} (viseme or ridge)")


class BaselineGather:
    """Both baselines fitted from ``n_utterances`` training utterances' frames given one at a
    time, in order, and let go (:class:`VisemeGather`, :class:`RidgeGather`)."""

    def __init__(self, model: Model, n_utterances: int):
        self.viseme = VisemeGather(len(model.phones))
        self.ridge = RidgeGather(n_utterances)

    def add(self, fd: FrameData) -> None:
        self.viseme.add(fd.pcs, fd.phone)
        self.ridge.add(fd)

    def baselines(self) -> Baselines:
        return Baselines(self.viseme.lookup(), self.ridge.ridge())


def fit_baselines(model: Model, train_frames: Iterable[FrameData],
                  n_utterances: int | None = None) -> Baselines:
    """Fit the viseme lookup and the ridge regression on the training frames (a sequence, or an
    iterable of ``n_utterances``: each utterance's frames let go once added)."""
    if n_utterances is None:
        train_frames = list(train_frames)
        n_utterances = len(train_frames)
    gather = BaselineGather(model, n_utterances)
    for fd in train_frames:
        gather.add(fd)
    return gather.baselines()


def score_baseline(model: Model, fd: FrameData, pcs: np.ndarray, split: str, name: str,
                   smoothing: str = "triangular", eval_config: EvalConfig | None = None,
                   triangle_s: float = 0.1, knot_s: float = 0.1) -> UtteranceScore:
    """Smooth predicted PCs like the synthesis, rebuild markers and score them as in Table 2.

    The score's ``mode`` is the baseline ``name`` and its ``n_context_phones`` 0.
    """
    markers = model.to_markers(smooth(pcs, model.marker_rate, smoothing, triangle_s, knot_s))
    c = trajectory_correlations(fd.original, markers, fd.speech, model, eval_config)
    score = UtteranceScore(split=split, mode=name, smoothing=smoothing, n_context_phones=0, **c,
                           utterance=fd.name, speech_frames=int(fd.speech.sum()))
    score.sensors = tuple(sensor_scores(fd.original, markers, fd.speech, model))
    return score


def evaluate_baselines(model: Model, baselines: Baselines,
                       frames: dict[str, Sequence[FrameData]],
                       smoothings: Sequence[str] = ("triangular", "spline"),
                       names: Sequence[str] = ("viseme", "ridge"),
                       eval_config: EvalConfig | None = None,
                       progress: Callable[[float, str], None] | None = None) -> list[UtteranceScore]:
    """Scores of every baseline x smoothing on every utterance of ``frames`` (split -> frames)."""
    out = []
    for split, fds in frames.items():
        for fd in fds:
            out.extend(score_baselines(model, baselines, fd, split, smoothings, names, eval_config))
    if progress:
        progress(1.0, "baselines done")
    return out


def score_baselines(model: Model, baselines: Baselines, fd: FrameData, split: str,
                    smoothings: Sequence[str] = ("triangular", "spline"),
                    names: Sequence[str] = ("viseme", "ridge"),
                    eval_config: EvalConfig | None = None) -> list[UtteranceScore]:
    """One utterance's scores of every baseline x smoothing."""
    out = []
    for name in names:
        pcs = baselines.predict(name, fd)
        out.extend(score_baseline(model, fd, pcs, split, name, sm, eval_config)
                   for sm in smoothings)
    return out


def fit_and_score(model: Model, corpus: Corpus, splits: Sequence[str] = ("train", "test"),
                  progress: Callable[[float, str], None] | None = None, workers: int = 1
                  ) -> tuple[Baselines, list[UtteranceScore]]:
    """Fit the two baselines on ``corpus``'s training split and score them on ``splits``: the
    corpus streamed twice (fitted from the training utterances' frames an utterance at a time,
    then each utterance scored), in ``workers`` processes, BLAS on one thread as in the
    evaluation. ``progress`` from 0 to 1."""
    progress = progress or (lambda f, m: None)
    train_ids = list(corpus.info.train)
    ids = [(sp, u) for sp in splits for u in getattr(corpus.info, sp)]

    def fitting(utt_id: str) -> FrameData:
        return frame_data(model, corpus.utterance(utt_id), keep_original=False)

    def scoring(pair: tuple[str, str]) -> list[UtteranceScore]:
        return score_baselines(model, base, frame_data(model, corpus.utterance(pair[1])), pair[0])

    gather = BaselineGather(model, len(train_ids))
    scores: list[UtteranceScore] = []
    with one_blas_thread():
        for _, fd in fan_out(fitting, train_ids, workers, describe=lambda u: f"baselines: {u}",
                             progress=lambda f, m: progress(0.35 * f, m)):
            gather.add(fd)
        base = gather.baselines()
        for _, utt_scores in fan_out(scoring, ids, workers, describe=lambda pair: f"baselines: {pair[1]}",
                                     progress=lambda f, m: progress(0.35 + 0.65 * f, m)):
            scores.extend(utt_scores)
    return base, scores
