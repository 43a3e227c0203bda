"""Two simple baselines to put the paper's method in perspective (issue 7), scored exactly like
Table 2 (:func:`~facetraj_engine.evaluation.scores.trajectory_correlations` on
:func:`~facetraj_engine.evaluation.scores.speech_mask` frames, the same smoothing).

* **Viseme lookup**: every frame gets the mean PC vector of its phone (the eq 1 idea applied
  directly, no acoustics, no context): what the phone labels alone explain.
* **Linear (ridge) regression**: PCs from the LSF vectors of frames t-5 .. t+5 stacked (the
  paper's own features, ~180 ms of context, no labels), by ridge regression; the regularisation
  is chosen on held-out *training* utterances, never on the test split.

Both work on the 60 Hz marker frames: LSFs from :func:`facetraj_engine.method.lsf.lsf_at` with the model's
analysis settings, PCs from the model's normalisation and PCA. numpy only.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..config import EvalConfig
from ..data import Utterance
from ..labels.phoneset import normalise_label
from ..method.context import segment_index
from ..method.model import Model
from ..method.smoothing import smooth
from .scores import UtteranceScore, speech_mask, trajectory_correlations

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


def frame_data(model: Model, utt: Utterance, eval_config: EvalConfig | None = None) -> FrameData:
    """Features, targets and the speech mask of one utterance with markers."""
    if utt.markers is None:
        raise ValueError(f"{utt.name}: no markers")
    times = utt.frame_times()
    lsf = model.input_lsf(utt.audio, utt.sample_rate, times)
    original = model.normalise_markers(utt.markers)
    pcs = model.to_pcs(original)
    return FrameData(utt.name, lsf, pcs, frame_phone_ids(model, utt, times), original,
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


def fit_viseme(pcs: np.ndarray, phone: np.ndarray, n_phones: int) -> VisemeLookup:
    """Mean of the finite PC rows of each phone id (eq 1 over frames); ids < 0 only count in the
    fallback mean.

    Examples
    --------
    >>> v = fit_viseme(np.array([[1.0], [3.0], [10.0]]), np.array([0, 0, 1]), 3)
    >>> v.table.ravel().tolist()[:2], v.predict(np.array([1, 2, -1])).ravel().tolist()
    ([2.0, 10.0], [10.0, 4.666666666666667, 4.666666666666667])
    """
    pcs = np.asarray(pcs, dtype=np.float64)
    phone = np.asarray(phone, dtype=np.int64)
    ok = np.isfinite(pcs).all(axis=1)
    fallback = pcs[ok].mean(axis=0)
    sel = ok & (phone >= 0)
    sums = np.zeros((n_phones, pcs.shape[1]))
    np.add.at(sums, phone[sel], pcs[sel])
    counts = np.bincount(phone[sel], minlength=n_phones).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        table = sums / counts[:, None]
    return VisemeLookup(table, fallback)


# ---------------------------------------------------------------------- ridge regression
def stack_context(x: np.ndarray, k: int = RIDGE_CONTEXT) -> np.ndarray:
    """Stack the rows ``t-k .. t+k`` of ``x`` (``(T, P)``) into ``(T, (2k+1) P)``, edges repeated.

    Examples
    --------
    >>> stack_context(np.array([[1.0], [2.0], [3.0]]), 1).tolist()
    [[1.0, 1.0, 2.0], [1.0, 2.0, 3.0], [2.0, 3.0, 3.0]]
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    idx = np.clip(np.arange(n)[:, None] + np.arange(-k, k + 1)[None, :], 0, n - 1)
    return x[idx].reshape(n, -1)


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
    y = np.asarray(y, dtype=np.float64)
    x_mean = x.mean(axis=0)
    x_scale = x.std(axis=0)
    x_scale = np.where(x_scale > 0, x_scale, 1.0)
    xs = (x - x_mean) / x_scale
    y_mean = y.mean(axis=0)
    gram = xs.T @ xs
    gram[np.diag_indices_from(gram)] += lam
    if lam > 0:
        coef = np.linalg.solve(gram, xs.T @ (y - y_mean))
    else:  # least squares, minimum norm (constant features get 0)
        coef = np.linalg.lstsq(xs, y - y_mean, rcond=None)[0]
    return RidgeRegression(x_mean, x_scale, y_mean, coef, float(lam))


def _design(frames: Sequence[FrameData], k: int) -> tuple[np.ndarray, np.ndarray]:
    xs, ys = [], []
    for fd in frames:
        ok = np.isfinite(fd.pcs).all(axis=1)
        xs.append(stack_context(fd.lsf, k)[ok])
        ys.append(fd.pcs[ok])
    return np.concatenate(xs), np.concatenate(ys)


def fit_ridge_baseline(frames: Sequence[FrameData], k: int = RIDGE_CONTEXT,
                       lambdas: Sequence[float] = RIDGE_LAMBDAS,
                       holdout: float = 0.2) -> RidgeRegression:
    """The ridge baseline on training utterances.

    The penalty ``lam * n_frames`` is chosen among ``lambdas`` by the PC-space squared error on
    the last ``holdout`` share of the training utterances (fitted on the rest), then the model is
    refitted on all of them.
    """
    frames = list(frames)
    n_hold = int(round(holdout * len(frames))) if len(frames) >= 5 else 0
    best = lambdas[0]
    if n_hold and len(lambdas) > 1:
        x_fit, y_fit = _design(frames[:-n_hold], k)
        x_val, y_val = _design(frames[-n_hold:], k)
        errors = []
        for lam in lambdas:
            r = fit_ridge(x_fit, y_fit, lam * len(x_fit))
            errors.append(float(((r.predict(x_val) - y_val) ** 2).mean()))
        best = lambdas[int(np.argmin(errors))]
        log.info("ridge baseline: validation MSE %s -> lambda %g",
                 ", ".join(f"{e:.4g}" for e in errors), best)
    x, y = _design(frames, k)
    return fit_ridge(x, y, best * len(x))


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


def fit_baselines(model: Model, train_frames: Sequence[FrameData]) -> Baselines:
    """Fit the viseme lookup and the ridge regression on the training frames."""
    pcs = np.concatenate([fd.pcs for fd in train_frames])
    phone = np.concatenate([fd.phone for fd in train_frames])
    return Baselines(fit_viseme(pcs, phone, len(model.phones)), fit_ridge_baseline(train_frames))


def score_baseline(model: Model, fd: FrameData, pcs: np.ndarray, split: str, name: str,
                   smoothing: str = "triangular", eval_config: EvalConfig | None = None,
                   triangle_s: float = 0.1, knot_s: float = 0.1) -> UtteranceScore:
    """Smooth predicted PCs like the synthesis, rebuild markers and score them as in Table 2.

    The score's ``mode`` is the baseline ``name`` and its ``n_context_phones`` 0.
    """
    markers = model.to_markers(smooth(pcs, model.marker_rate, smoothing, triangle_s, knot_s))
    c = trajectory_correlations(fd.original, markers, fd.speech, model, eval_config)
    return UtteranceScore(split=split, mode=name, smoothing=smoothing, n_context_phones=0, **c,
                          utterance=fd.name, speech_frames=int(fd.speech.sum()))


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
            for name in names:
                pcs = baselines.predict(name, fd)
                out.extend(score_baseline(model, fd, pcs, split, name, sm, eval_config)
                           for sm in smoothings)
    if progress:
        progress(1.0, "baselines done")
    return out
