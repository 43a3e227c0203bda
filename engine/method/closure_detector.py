"""Where the lips close, from the sound alone: the bilabial-closure detector (beyond the paper,
issue 40), for the closure step (:mod:`facetraj_engine.method.closure`) of a synthesis without
phone labels.

A bilabial closure is silence or a low murmur inside speech, and the formants fall into it and
rise out of it. Per marker frame t, from the 25 ms analysis frames of the input LSFs (paper
2.1: 16 kHz, pre-emphasis, Hamming window centred on the frame):

1. the energy dip ``e_rel(t) = max(e(t) - max_{t-B <= s <= t} e(s), floor)`` (dB; ``e`` the
   frame's mean square, ``B`` = 20 frames, 333 ms; the floor -30 dB): level-free
   (:func:`relative_energy`);
2. the voicing gate ``g(t) = clip((e_rel(t) - lo) / (hi - lo), 0, 1)``, -20 / -15 dB: 0 in a
   closure, 1 in a vowel (:func:`voicing_gate`);
3. the formants' place: the ``n_lsf`` = 8 lowest LSFs (up to about 3.5 kHz: F1-F3) as log
   frequencies minus their running mean over the voiced frames so far, ``m(t) = (n0 mu0 +
   sum_{s <= t} g(s) log w(s)) / (n0 + sum_{s <= t} g(s))`` (``mu0`` the training voice's mean,
   worth ``n0`` = 20 frames), times the gate: ``u(t) = g(t) (log w(t) - m(t))``
   (:func:`running_mean`); a voice whose formants are all higher by one factor has the same
   ``u``;
4. ``x(t)``: ``[e_rel, u]`` at frames t-3 .. t+3 (+-50 ms: into and out of the closure; the
   first and last frames repeated beyond the ends; :func:`stacked`): 63 numbers;
5. ``p_a(t) = 1 / (1 + exp(-(b + beta . (x(t) - mean) / scale)))``: a logistic regression
   with an L2 penalty (:func:`fit_logistic`), fitted at training on the training utterances'
   frames, 1 inside a /p b m/ label (:func:`train_detector`);
6. the acoustic search's own opinion, where the codebook knows the voice: a second logistic
   regression ``p_s(t)`` of ``x(t)`` and, at the same 7 frames, the share of eq 7's weight on
   /p b m/ codewords and the unsmoothed aperture of eq 8 minus the closed one
   (:mod:`facetraj_engine.method.closure_search`; fitted on the training utterances searched
   with their own codewords left out, as a new recording of the training voice is), mixed in by
   the input's voice match ``m`` (:mod:`facetraj_engine.method.voice_match`): ``p(t) = (1 - m)
   p_a(t) + m p_s(t)`` -- the codebook's sounds are the training voice's, and on another voice
   its opinion misleads (measured: the second voice's vowels fall on /p b m/ codewords);
7. the closures: runs of at least ``min_frames`` = 2 frames with ``p >= threshold``
   (``SynthConfig.closure_threshold``; :func:`closure_runs`).

Every step looks at most 3 frames ahead (step 4), which live mode's triangular smoothing has
waited for already: the detector adds no lookahead to a stream
(:mod:`facetraj_engine.streaming.detector`, equal to this frame for frame at one voice match).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from ..config import TrainConfig
from ..data import PhoneSegment
from ..level import unit_exponent
from .closure import BILABIALS
from .lsf import analysis_frames, lsf_at, resample_audio

#: Added to a frame's mean square before its logarithm (digital silence is -300 dB: far below
#: any energy dip's floor, so the energies of a signal and of the same signal scaled differ by
#: one constant and their dips are equal).
ENERGY_FLOOR = 1e-30


@dataclass(frozen=True)
class DetectorSpec:
    """How the detector's features are made (stored with it in the model file).

    Attributes
    ----------
    back : frames the energy dip looks back for the loudest frame (``B``).
    floor_db : the lowest energy dip (dB).
    gate_db : the dips (dB) at which the voicing gate is 0 and 1.
    n_lsf : the lowest LSFs used.
    prior_frames : how many voiced frames the training voice's mean LSFs count for (``n0``).
    offsets : the frames around t whose values make ``x(t)``.
    min_frames : the shortest closure (frames).
    """

    back: int = 20
    floor_db: float = -30.0
    gate_db: tuple[float, float] = (-20.0, -15.0)
    n_lsf: int = 8
    prior_frames: float = 20.0
    offsets: tuple[int, ...] = (-3, -2, -1, 0, 1, 2, 3)
    min_frames: int = 2

    @property
    def n_features(self) -> int:
        return len(self.offsets) * (1 + self.n_lsf)

    @property
    def ahead(self) -> int:
        """Frames after t that ``x(t)`` needs."""
        return max(0, *self.offsets)

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, obj: dict) -> DetectorSpec:
        kw = {f.name: obj[f.name] for f in fields(cls) if f.name in obj}
        for key in ("gate_db", "offsets"):
            if key in kw:
                kw[key] = tuple(kw[key])
        return cls(**kw)


@dataclass(frozen=True)
class Logistic:
    """A fitted logistic regression: the features' training ``mean`` and ``scale`` ``(F,)``,
    the ``weights`` ``(F,)`` of the standardised features and the ``bias``."""

    mean: np.ndarray
    scale: np.ndarray
    weights: np.ndarray
    bias: float

    def probability(self, x: np.ndarray) -> np.ndarray:
        z = (np.asarray(x, dtype=np.float64) - self.mean) / self.scale @ self.weights + self.bias
        return sigmoid(z)

    @classmethod
    def fit(cls, x: np.ndarray, y: np.ndarray, ridge: float) -> Logistic:
        """Standardise the features of ``x`` ``(T, F)``, then :func:`fit_logistic`."""
        mean = x.mean(axis=0)
        scale = x.std(axis=0)
        scale = np.where(scale > 1e-9, scale, 1.0)
        beta, b = fit_logistic((x - mean) / scale, y, ridge)
        return cls(mean, scale, beta, b)

    def arrays(self, prefix: str) -> dict[str, np.ndarray]:
        return {f"{prefix}_mean": self.mean, f"{prefix}_scale": self.scale,
                f"{prefix}_weights": self.weights}

    @classmethod
    def from_file(cls, arrays: dict[str, np.ndarray], prefix: str, bias: float) -> Logistic:
        return cls(arrays[f"{prefix}_mean"], arrays[f"{prefix}_scale"], arrays[f"{prefix}_weights"],
                   float(bias))


@dataclass(frozen=True)
class ClosureDetector:
    """A trained detector: its ``spec``, the training voice's mean log LSFs ``lsf_mean``
    ``(n_lsf,)``, the acoustic regression (step 5) and the one with the search's opinion (step 6;
    ``None``: none)."""

    spec: DetectorSpec
    lsf_mean: np.ndarray
    acoustic: Logistic
    search: Logistic | None = None

    def probability(self, x: np.ndarray, x_search: np.ndarray | None = None,
                    match: float | np.ndarray = 0.0) -> np.ndarray:
        """``p(t)`` (steps 5-6) of feature rows ``x`` ``(T, F)``, the search's stacked rows
        ``x_search`` ``(T, 2 len(offsets))`` (``None``: not known) and the voice ``match``, one
        for every row or one per row (NaN: unknown, 0)."""
        p = self.acoustic.probability(x)
        m = np.broadcast_to(np.nan_to_num(np.asarray(match, dtype=np.float64), nan=0.0), p.shape)
        if self.search is None or x_search is None or not (m > 0.0).any():
            return p
        return (1.0 - m) * p + m * self.search.probability(np.concatenate([x, x_search], axis=1))

    def frame_probability(self, lsf: np.ndarray, energy_db: np.ndarray,
                          search: np.ndarray | None = None,
                          match: float | np.ndarray = 0.0) -> np.ndarray:
        """``p(t)`` of every frame of an input from its LSFs ``(T, P)``, frame energies ``(T,)``
        (dB), and the search's rows ``(T, 2)`` (:mod:`facetraj_engine.method.closure_search`)."""
        x = detector_features(lsf, energy_db, self.spec, self.lsf_mean)
        xs = stacked(search, self.spec.offsets) if search is not None else None
        return self.probability(x, xs, match)

    def meta(self) -> dict:
        """What the model file's metadata keeps of it (the arrays go beside it)."""
        out = {"spec": self.spec.to_json(), "bias": self.acoustic.bias}
        if self.search is not None:
            out["search_bias"] = self.search.bias
        return out

    def arrays(self) -> dict[str, np.ndarray]:
        out = {"cd_lsf_mean": self.lsf_mean, **self.acoustic.arrays("cd")}
        return out if self.search is None else {**out, **self.search.arrays("cs")}

    @classmethod
    def from_file(cls, meta: dict, arrays: dict[str, np.ndarray]) -> ClosureDetector:
        search = Logistic.from_file(arrays, "cs", meta["search_bias"]) \
            if "search_bias" in meta else None
        return cls(DetectorSpec.from_json(meta["spec"]), arrays["cd_lsf_mean"],
                   Logistic.from_file(arrays, "cd", meta["bias"]), search)


# --------------------------------------------------------------------------- the features
def sigmoid(z: np.ndarray) -> np.ndarray:
    """``1 / (1 + exp(-z))`` without overflow.

    >>> sigmoid(np.array([-1000.0, 0.0, 1000.0])).tolist()
    [0.0, 0.5, 1.0]
    """
    z = np.asarray(z, dtype=np.float64)
    e = np.exp(-np.abs(z))
    return np.where(z >= 0, 1.0 / (1.0 + e), e / (1.0 + e))


def frame_energy_db(frames: np.ndarray) -> np.ndarray:
    """Each windowed frame's mean square in dB (``(T, n)`` -> ``(T,)``).

    >>> frame_energy_db(np.array([[1.0, -1.0], [0.1, 0.1]])).round(6).tolist()
    [0.0, -20.0]
    """
    f = np.asarray(frames, dtype=np.float64)
    return 10.0 * np.log10(np.mean(f * f, axis=-1) + ENERGY_FLOOR)


def relative_energy(e: np.ndarray, back: int = 20, floor_db: float = -30.0,
                    before: np.ndarray | None = None) -> np.ndarray:
    """Step 1: each frame's energy minus the largest of it and the ``back`` frames before it,
    at least ``floor_db`` (``before``: the energies of the frames before ``e``, when it is the
    continuation of a stream).

    >>> relative_energy(np.array([0.0, -10.0, -50.0, -20.0]), back=2).tolist()
    [0.0, -10.0, -30.0, -10.0]
    """
    e = np.asarray(e, dtype=np.float64)
    prev = np.zeros(0) if before is None else np.asarray(before, dtype=np.float64)[-back:]
    pad = np.concatenate([np.full(back - len(prev), -np.inf), prev, e])
    peak = np.lib.stride_tricks.sliding_window_view(pad, back + 1).max(axis=1)
    return np.maximum(e - peak, floor_db)


def voicing_gate(e_rel: np.ndarray, gate_db: tuple[float, float] = (-20.0, -15.0)) -> np.ndarray:
    """Step 2: 0 at dips of ``gate_db[0]`` and below, 1 from ``gate_db[1]``, linear between.

    >>> voicing_gate(np.array([-30.0, -17.5, -5.0])).tolist()
    [0.0, 0.5, 1.0]
    """
    lo, hi = gate_db
    return np.clip((np.asarray(e_rel, dtype=np.float64) - lo) / (hi - lo), 0.0, 1.0)


def running_mean(x: np.ndarray, w: np.ndarray, prior: np.ndarray, prior_weight: float,
                 sums: tuple[np.ndarray, float] | None = None
                 ) -> tuple[np.ndarray, tuple[np.ndarray, float]]:
    """Step 3's ``m(t)``: the mean of the rows of ``x`` ``(T, D)`` up to each, weighted by ``w``
    ``(T,)``, with ``prior`` ``(D,)`` worth ``prior_weight``; and the weighted sums after the
    last row (``sums``: those before the first, when ``x`` continues a stream).

    >>> m, s = running_mean(np.array([[2.0], [4.0]]), np.array([1.0, 0.0]), np.array([0.0]), 1.0)
    >>> m.tolist(), (s[0].tolist(), s[1])
    ([[1.0], [1.0]], ([2.0], 1.0))
    """
    x = np.asarray(x, dtype=np.float64)
    w = np.asarray(w, dtype=np.float64)
    sx0, sw0 = sums if sums is not None else (np.zeros(x.shape[1]), 0.0)
    sx = sx0 + np.cumsum(w[:, None] * x, axis=0)
    sw = sw0 + np.cumsum(w)
    means = (prior[None, :] * prior_weight + sx) / (prior_weight + sw)[:, None]
    return means, ((sx[-1], float(sw[-1])) if len(x) else (sx0, sw0))


def stacked(rows: np.ndarray, offsets: Sequence[int], first: int = 0,
            count: int | None = None) -> np.ndarray:
    """Step 4: for frames ``first .. first + count - 1``, the rows at each of ``offsets`` from
    it side by side, the first and last rows repeated beyond the ends.

    >>> stacked(np.array([[1.0], [2.0], [3.0]]), (-1, 0, 1)).tolist()
    [[1.0, 1.0, 2.0], [1.0, 2.0, 3.0], [2.0, 3.0, 3.0]]
    """
    rows = np.asarray(rows, dtype=np.float64)
    count = len(rows) - first if count is None else count
    idx = np.arange(first, first + count)
    return np.concatenate([rows[np.clip(idx + o, 0, len(rows) - 1)] for o in offsets], axis=1) \
        if len(rows) else np.zeros((0, len(offsets) * rows.shape[-1]))


def frame_rows(lsf: np.ndarray, energy_db: np.ndarray, spec: DetectorSpec, lsf_mean: np.ndarray,
               before: np.ndarray | None = None, sums: tuple[np.ndarray, float] | None = None
               ) -> tuple[np.ndarray, tuple[np.ndarray, float]]:
    """Steps 1-3: ``[e_rel, u]`` of each frame ``(T, 1 + n_lsf)``, and the running mean's sums
    (``before``, ``sums``: a stream's earlier energies and sums)."""
    e_rel = relative_energy(energy_db, spec.back, spec.floor_db, before)
    g = voicing_gate(e_rel, spec.gate_db)
    logw = np.log(np.asarray(lsf, dtype=np.float64)[:, :spec.n_lsf])
    m, sums = running_mean(logw, g, lsf_mean, spec.prior_frames, sums)
    return np.column_stack([e_rel, g[:, None] * (logw - m)]), sums


def detector_features(lsf: np.ndarray, energy_db: np.ndarray, spec: DetectorSpec,
                      lsf_mean: np.ndarray) -> np.ndarray:
    """``x(t)`` (steps 1-4) of every frame of one input, ``(T, F)``."""
    rows, _ = frame_rows(lsf, energy_db, spec, lsf_mean)
    return stacked(rows, spec.offsets)


def input_energy_db(config: TrainConfig, audio: np.ndarray, sample_rate: int,
                    times: np.ndarray) -> np.ndarray:
    """The energy (dB) of the analysis frames of the input LSFs at ``times`` (resampled to
    ``config.audio_rate``, pre-emphasized, windowed as :func:`~facetraj_engine.method.lsf.lsf_at`
    frames them; only differences of energy are used, so the signal is first brought to a peak
    in [0.5, 1) by a power of two, :func:`facetraj_engine.level.unit_exponent`: exact, and no
    sample squared overflows at any gain)."""
    x = resample_audio(np.asarray(audio, dtype=np.float64), sample_rate, config.audio_rate)
    x = np.ldexp(x, unit_exponent(x))
    return frame_energy_db(analysis_frames(x, config.audio_rate, np.asarray(times, dtype=np.float64),
                                           config.window_s, config.preemphasis))


# --------------------------------------------------------------------------- training
def fit_logistic(x: np.ndarray, y: np.ndarray, ridge: float = 100.0, iterations: int = 50
                 ) -> tuple[np.ndarray, float]:
    """Logistic regression by Newton's method (iteratively reweighted least squares) with the
    penalty ``ridge/2 |beta|^2`` on the weights (not the bias): ``(beta, b)`` maximising
    ``sum_t y_t log p_t + (1 - y_t) log(1 - p_t) - ridge/2 |beta|^2``, ``p_t = sigmoid(b +
    x_t . beta)``. Without the penalty, one 0/1 feature gives the log odds of each group: 1 in
    4 where ``x = 0`` (``b = log 1/3``), 3 in 4 where ``x = 1`` (``b + beta = log 3``):

    >>> beta, b = fit_logistic(np.repeat([[0.0], [1.0]], 4, axis=0), np.array([1, 0, 0, 0, 1, 1, 1, 0]), 0.0)
    >>> round(float(beta[0]), 4), round(b, 4), round(2 * float(np.log(3)), 4)
    (2.1972, -1.0986, 2.1972)
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    z = np.column_stack([x, np.ones(len(x))])
    penalty = np.full(z.shape[1], float(ridge))
    penalty[-1] = 0.0
    theta = np.zeros(z.shape[1])
    for _ in range(iterations):
        p = sigmoid(z @ theta)
        grad = z.T @ (y - p) - penalty * theta
        hess = (z * (p * (1 - p))[:, None]).T @ z + np.diag(penalty) + 1e-9 * np.eye(z.shape[1])
        step = np.linalg.solve(hess, grad)
        theta += step
        if np.abs(step).max() < 1e-8:
            break
    return theta[:-1], float(theta[-1])


def bilabial_frames(phones: Sequence[PhoneSegment], times: np.ndarray) -> np.ndarray:
    """Whether each of ``times`` lies inside a /p b m/ of ``phones``.

    >>> bilabial_frames([PhoneSegment(0, .1, "aa"), PhoneSegment(.1, .2, "m")],
    ...                 np.array([0.05, 0.15, 0.25])).tolist()
    [False, True, False]
    """
    t = np.asarray(times, dtype=np.float64)
    inside = np.zeros(len(t), dtype=bool)
    for s in phones:
        if s.label in BILABIALS:
            inside |= (t >= s.start) & (t < s.end)
    return inside


def voiced_mean(lsf: Sequence[np.ndarray], energy_db: Sequence[np.ndarray],
                spec: DetectorSpec) -> np.ndarray:
    """``mu0``: the mean log LSFs of the voiced frames (weighted by the gate) of utterances."""
    total, weight = np.zeros(spec.n_lsf), 0.0
    for w, e in zip(lsf, energy_db, strict=True):
        g = voicing_gate(relative_energy(e, spec.back, spec.floor_db), spec.gate_db)
        total += g @ np.log(np.asarray(w, dtype=np.float64)[:, :spec.n_lsf])
        weight += float(g.sum())
    return total / weight if weight > 0 else np.log(np.asarray(lsf[0])[:, :spec.n_lsf]).mean(axis=0)


def train_detector(lsf: Sequence[np.ndarray], energy_db: Sequence[np.ndarray],
                   targets: Sequence[np.ndarray], spec: DetectorSpec | None = None,
                   ridge: float = 100.0, search: Sequence[np.ndarray] | None = None
                   ) -> ClosureDetector | None:
    """The detector of utterances' frames: their LSFs ``(T, P)``, energies ``(T,)`` (dB),
    targets ``(T,)`` (inside a /p b m/) and (``search``) the search's rows ``(T, 2)`` of each,
    searched without its own codewords; ``None`` when no frame is one (or every one is). A model
    of fewer than ``spec.n_lsf`` LSFs (an LPC order under 8) places the formants with the LSFs it
    has."""
    spec = spec or DetectorSpec()
    width = min((np.shape(w)[1] for w in lsf), default=spec.n_lsf)
    if width < spec.n_lsf:
        spec = replace(spec, n_lsf=int(width))
    y = np.concatenate([np.asarray(t, dtype=bool) for t in targets])
    if not y.any() or y.all():
        return None
    mu0 = voiced_mean(lsf, energy_db, spec)
    x = np.concatenate([detector_features(w, e, spec, mu0) for w, e in zip(lsf, energy_db,
                                                                          strict=True)])
    with_search = None
    if search is not None:
        xs = np.concatenate([stacked(r, spec.offsets) for r in search])
        with_search = Logistic.fit(np.concatenate([x, xs], axis=1), y, ridge)
    return ClosureDetector(spec, mu0, Logistic.fit(x, y, ridge), with_search)


def utterance_inputs(config: TrainConfig, audio: np.ndarray, sample_rate: int,
                     times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """An utterance's LSFs and frame energies at ``times``, analysed as the model analyses its
    inputs."""
    w = lsf_at(audio, sample_rate, times, config.lpc_order, config.window_s, config.audio_rate,
               config.preemphasis)
    return w, input_energy_db(config, audio, sample_rate, times)


def input_probability(detector: ClosureDetector, config: TrainConfig, audio: np.ndarray,
                      sample_rate: int, times: np.ndarray, lsf: np.ndarray | None = None,
                      search: np.ndarray | None = None, match: float | np.ndarray = 0.0,
                      energy_db: np.ndarray | None = None) -> np.ndarray:
    """``p(t)`` of an input's frames at ``times`` (``lsf``: its input LSFs there, unwarped, when
    already computed; ``search``, ``match``: the search's rows and the voice match, one or one
    per frame, step 6; ``energy_db``: the frame energies of those LSFs' analysis frames, when
    computed with them)."""
    w = lsf if lsf is not None else lsf_at(audio, sample_rate, times, config.lpc_order,
                                           config.window_s, config.audio_rate, config.preemphasis)
    if energy_db is None:
        energy_db = input_energy_db(config, audio, sample_rate, times)
    return detector.frame_probability(w, energy_db, search, match)


# --------------------------------------------------------------------------- the closures
def closure_runs(p: np.ndarray, times: np.ndarray, threshold: float, min_frames: int = 2,
                 open_end: bool = False) -> np.ndarray:
    """Step 6: ``(J, 2)`` ``[start, end)`` seconds of the runs of at least ``min_frames`` frames
    with ``p >= threshold`` (``times`` equally spaced; ``open_end``: a run reaching the last
    frame has not ended, its end is ``inf``).

    >>> closure_runs(np.array([0.9, 0.1, 0.8, 0.7, 0.1, 0.6, 0.6]), np.arange(7) / 10, 0.5).tolist()
    [[0.2, 0.4], [0.5, 0.7]]
    """
    hit = np.concatenate([[False], np.asarray(p) >= threshold, [False]])
    edges = np.flatnonzero(np.diff(hit.astype(np.int8)))
    starts, stops = edges[::2], edges[1::2]
    keep = stops - starts >= min_frames
    if not len(times) or not keep.any():
        return np.zeros((0, 2))
    step = times[1] - times[0] if len(times) > 1 else 1.0
    t = np.asarray(times, dtype=np.float64)
    out = np.column_stack([t[starts[keep]], t[stops[keep] - 1] + step])
    if open_end and stops[keep][-1] == len(t):
        out[-1, 1] = np.inf
    return np.round(out, 12)


def causal_closures(runs: np.ndarray, rate: float, min_frames: int = 2) -> np.ndarray:
    """The closures the lips make of ``runs`` ``(J, 2)`` of at least ``min_frames`` frames
    (:func:`closure_runs`): from each run's ``min_frames``-th frame, the first at which a stream
    knows the run is one (it shows a frame once the frame's own probability is known, not the
    next one's), to its last frame; the bounds half a frame from the frames' times, so that which
    frames are inside does not hang on rounding (an unended run stays unended).

    >>> causal_closures(np.array([[0.2, 0.4], [0.5, np.inf]]), 10.0).tolist()
    [[0.25, 0.35], [0.55, inf]]
    """
    runs = np.asarray(runs, dtype=np.float64).reshape(-1, 2)
    half = 0.5 / rate
    return np.round(np.column_stack([runs[:, 0] + (min_frames - 1) / rate - half,
                                     runs[:, 1] - half]), 12)


def beside(runs: np.ndarray, intervals: np.ndarray) -> np.ndarray:
    """The closures of ``runs`` ``(J, 2)`` that overlap none of ``intervals`` ``(I, 2)`` (where
    the detector and the labels disagree: a closure with no labelled /p b m/).

    >>> beside(np.array([[0.1, 0.2], [0.5, 0.6]]), np.array([[0.15, 0.3]])).tolist()
    [[0.5, 0.6]]
    """
    runs = np.asarray(runs, dtype=np.float64).reshape(-1, 2)
    iv = np.asarray(intervals, dtype=np.float64).reshape(-1, 2)
    overlaps = (runs[:, None, 0] < iv[None, :, 1]) & (runs[:, None, 1] > iv[None, :, 0])
    return runs[~overlaps.any(axis=1)]
