"""Lips that close, and a face that rests in pauses (beyond the paper, issues 25, 40 and 46).

The paper's eqs 5-8 average codewords, and its 100 ms triangular window averages frames: both
shave the extremes off, and the most visible extreme of speech is a bilabial closure (the paper's
phonetic mode with exact labels closes only about half of /p b m/ within 1 mm; unsmoothed, all of
them). This step, after eq 8 and the smoothing, leaves the paper's equations alone and:

1. **closes the lips** where the labels say /p b m/: the PCs move along the *closing direction*
   ``d`` (learnt at training: the regression of the PCs on the lip aperture, so the jaw and the
   lips move together as the talker's do) until the aperture's minimum inside the segment reaches
   the talker's closed aperture; the move is flat over the segment with raised-cosine tapers of
   ``closure_taper_s`` outside it, scaled by how much the label is trusted
   (:func:`closure_strengths`). The closures the bilabial-closure detector finds without phones
   are closed as a stream can close them (*causal* intervals, :func:`closure_moves`): from their
   first frame, each frame by the smallest aperture of the closure so far, tapered after their end
   only -- so that ``facetraj live --acoustic-only`` and ``synth --mode acoustic`` make the same
   face (issue 46);
2. **rests the face** in pauses (by energy, as the evaluation finds speech frames): a silence is
   a pause once it is longer than a stop closure's (``rest_pause_s``), and the PCs blend towards
   the training talker's median face, reading only each frame, those before it and the
   ``rest_lookahead_s`` after it (:func:`rest_weights`: what a stream knows when it shows a
   frame, so offline and live rest alike). Outside the recording is silence: the silence it
   starts with is rested from its first frame, and the one it ends in as any pause that goes
   on; no speech frame is rested.

The lip aperture (upper-lip centre y minus lower-lip centre y) is linear in the PCs,
``a(p) = a0 + p . g`` (:func:`aperture_functional`), so every move is exact.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..data import PhoneSegment
from ..labels.phoneset import SILENCE, normalise_label
from .moments import Moments
from .pca import PCA

#: The phones whose lips close.
BILABIALS = ("p", "b", "m")


@dataclass(frozen=True)
class ClosureStats:
    """What the step needs of the training talker (stored in the model).

    Attributes
    ----------
    closed : the closed lip aperture (mm): the median, over the training /p b m/, of the
        aperture's minimum inside the segment.
    direction : ``(K,)`` the closing direction in PC space, ``g . direction = 1`` (one mm).
    rest : ``(K,)`` the rest face: the median PCs of the training pauses over 150 ms.
    """

    closed: float
    direction: np.ndarray
    rest: np.ndarray


@dataclass(frozen=True)
class ClosurePlan:
    """Where the step acts on one input: ``intervals`` ``(J, 2)`` seconds of /p b m/ and their
    ``strengths`` ``(J,)`` in [0, 1]; ``silent`` ``(F,)`` whether each frame from frame
    ``silent_from`` on is decided silent (frames after the last decided one count as speech), and
    ``leading``: no frame before ``silent_from`` is speech (the input began in silence);
    ``end``: the input's frame count once it is known to have ended (offline; a stream at its
    last frames), from which on frames count as silent (``None``: not known);
    ``causal`` ``(J,)`` which intervals are closed as a stream closes them (the detector's,
    :func:`closure_moves`; ``None``: none); ``probability``: per frame, the bilabial-closure
    detector's (:mod:`facetraj_engine.method.closure_detector`) when it ran."""

    intervals: np.ndarray
    strengths: np.ndarray
    silent: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    probability: np.ndarray | None = None
    causal: np.ndarray | None = None
    silent_from: int = 0
    leading: bool = True
    end: int | None = None

    @property
    def is_causal(self) -> np.ndarray:
        """``(J,)`` which intervals are causal."""
        return np.zeros(len(self.intervals), dtype=bool) if self.causal is None else \
            np.asarray(self.causal, dtype=bool)


# --------------------------------------------------------------------------- the aperture
def aperture_functional(pca: PCA, upper: int, lower: int) -> tuple[float, np.ndarray]:
    """``(a0, g)`` with the lip aperture of PC vector ``p`` equal to ``a0 + p . g`` (the markers
    are ``mean + p . components``; the aperture is upper-lip y minus lower-lip y).

    >>> pca = PCA(np.array([0, 5.0, 0, 0, 1.0, 0]), np.array([[0, 1.0, 0, 0, -1.0, 0]]),
    ...           np.ones(1), 1.0)
    >>> a0, g = aperture_functional(pca, 0, 1)
    >>> float(a0), g.tolist()
    (4.0, [2.0])
    """
    u, lo = 3 * upper + 1, 3 * lower + 1
    return float(pca.mean[u] - pca.mean[lo]), np.asarray(pca.components[:, u] - pca.components[:, lo],
                                                         dtype=np.float64)


def _joint_moments(p: np.ndarray, a: np.ndarray) -> Moments:
    """The moments of the rows ``[p, a]`` where both are finite."""
    ok = np.isfinite(p).all(axis=1) & np.isfinite(a)
    return Moments.of(np.column_stack([p[ok], a[ok]]))


def _direction(joint: Moments) -> np.ndarray:
    """The closing direction ``d = cov(p, a) / var(a)`` from the moments of ``[p, a]``: the
    regression of the PCs on the aperture over the training frames, how the whole face moves, on
    average, per mm of aperture (when ``a = a0 + p . g`` exactly, ``g . d = 1``).

    >>> p = np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 4.0]])
    >>> _direction(_joint_moments(p, 3.0 + p @ np.array([1.0, 0.0]))).tolist()
    [1.0, 2.0]
    """
    return joint.scatter[:-1, -1] / joint.scatter[-1, -1]


@dataclass
class ClosurePart:
    """One training utterance's share of :class:`ClosureStats`: the aperture's minimum in each
    /p b m/, its PC rows in pauses over ``pause_s`` (finite ones), the moments of ``[p, a]`` over
    its frames; and for the fallbacks of a corpus without pauses or without /p b m/, its PCs and
    apertures (only when it has none itself)."""

    minima: list[float]
    rest: np.ndarray
    joint: Moments
    pcs: np.ndarray | None = None
    apertures: np.ndarray | None = None


def closure_part(pcs: np.ndarray, segs: Sequence[PhoneSegment], rate: float, a0: float,
                 g: np.ndarray, pause_s: float = 0.15) -> ClosurePart:
    """The :class:`ClosurePart` of one utterance's PCs ``(T, K)`` (NaN where a marker was unseen)
    and its phone labels."""
    p = np.asarray(pcs, dtype=np.float64)
    a = a0 + p @ g
    t = np.arange(len(p)) / rate
    minima, rest = [], []
    for s in segs:
        idx = np.flatnonzero((t >= s.start) & (t < s.end))
        if idx.size == 0 or not np.isfinite(a[idx]).any():
            continue
        if s.label in BILABIALS:
            minima.append(float(np.nanmin(a[idx])))
        elif s.label == "sil" and s.end - s.start > pause_s:
            rest.append(p[idx])
    rows = np.concatenate(rest) if rest else np.zeros((0, p.shape[1]))
    return ClosurePart(minima, rows[np.isfinite(rows).all(axis=1)], _joint_moments(p, a),
                       None if rest else p, None if minima else a)


class ClosureGather:
    """:class:`ClosureStats` gathered one utterance's :class:`ClosurePart` at a time (in order):
    the minima and pause rows kept (their medians need them all), the regression from merged
    moments; every utterance's PCs and apertures only while no pause (no /p b m/) has been seen,
    for the fallbacks."""

    def __init__(self, n_pcs: int):
        self.minima: list[float] = []
        self.rest: list[np.ndarray] = []
        self.joint = Moments.empty(n_pcs + 1)
        self.all_pcs: list[np.ndarray] = []
        self.all_apertures: list[np.ndarray] = []

    def add(self, part: ClosurePart) -> None:
        self.minima += part.minima
        if part.minima:
            self.all_apertures = []
        elif not self.minima:
            self.all_apertures.append(part.apertures)
        if len(part.rest):
            self.rest.append(part.rest)
            self.all_pcs = []
        elif not self.rest:
            self.all_pcs.append(part.pcs)
        self.joint = self.joint.merged(part.joint)

    def stats(self) -> ClosureStats:
        """The statistics of every utterance added: the median aperture minimum over /p b m/
        (else the aperture's 10th percentile), the closing direction (:func:`_direction`), the
        median face of long pauses (else of every frame)."""
        rows = np.concatenate(self.rest) if self.rest else np.concatenate(self.all_pcs)
        rows = rows[np.isfinite(rows).all(axis=1)]
        closed = (float(np.median(self.minima)) if self.minima else
                  float(np.nanpercentile(np.concatenate(self.all_apertures), 10)))
        return ClosureStats(closed, _direction(self.joint), np.median(rows, axis=0))


# --------------------------------------------------------------------------- where and how much
def closure_intervals(phones: Sequence[PhoneSegment], strengths: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """``(intervals (J, 2), strengths (J,))`` of the /p b m/ among ``phones`` with a strength
    above 0 (``strengths``: one per phone).

    >>> segs = [PhoneSegment(0, .1, "sil"), PhoneSegment(.1, .2, "b"), PhoneSegment(.2, .3, "m")]
    >>> iv, s = closure_intervals(segs, np.array([1.0, 0.5, 0.0]))
    >>> iv.tolist(), s.tolist()
    ([[0.1, 0.2]], [0.5])
    """
    keep = [k for k, s in enumerate(phones) if s.label in BILABIALS and strengths[k] > 0]
    iv = np.array([(phones[k].start, phones[k].end) for k in keep], dtype=np.float64)
    return iv.reshape(-1, 2), np.asarray(strengths, dtype=np.float64)[keep]


def closure_strengths(n_phones: int, kind: str, voice_match: float) -> np.ndarray:
    """Per phone, how much the step trusts a /p b m/ label: 1 when its identity comes from a
    person or a transcript (``hand-checked``, ``aligned``); for ``recognized`` labels ``1 -
    voice_match``: the recognizer (trained on many real voices) is trusted as far as the voice is
    not the training voice, whose own sounds the codebook already matches (measured: its /p b m/
    are 40 % right on the synthetic training voice, 85 % on real voices).

    >>> closure_strengths(2, "aligned", 0.9).tolist(), closure_strengths(2, "recognized", 0.25).tolist()
    ([1.0, 1.0], [0.75, 0.75])
    """
    return np.full(n_phones, 1.0 if kind != "recognized" else 1.0 - float(voice_match))


def bump(times: np.ndarray, start: float, end: float, taper_s: float, inside: bool = False,
         lead: bool = True) -> np.ndarray:
    """A flat-topped weight: 1 on ``[start, end]``, raised-cosine tapers of ``taper_s`` outside
    the interval (``inside``: the tapers inside it, 0 outside; ``lead=False``: no taper before
    it, 0 there).

    >>> bump(np.arange(7) / 10, 0.3, 0.4, 0.2).round(3).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0, 0.5, 0.0]
    >>> bump(np.arange(7) / 10, 0.1, 0.5, 0.2, inside=True).round(3).tolist()
    [0.0, 0.0, 0.5, 1.0, 0.5, 0.0, 0.0]
    >>> bump(np.arange(7) / 10, 0.3, 0.4, 0.2, lead=False).round(3).tolist()
    [0.0, 0.0, 0.0, 1.0, 1.0, 0.5, 0.0]
    """
    t = np.asarray(times, dtype=np.float64)
    if inside:
        half = min(taper_s, 0.5 * (end - start))
        start, end, taper_s = start + half, end - half, half
    if taper_s <= 0:
        return ((t >= start) & (t <= end)).astype(np.float64)
    dist = np.maximum(np.maximum(start - t, t - end), 0.0)
    w = np.where(dist >= taper_s, 0.0, 0.5 * (1 + np.cos(np.pi * np.minimum(dist / taper_s, 1.0))))
    return w if lead else np.where(t < start, 0.0, w)


def ramp(x: np.ndarray) -> np.ndarray:
    """A raised-cosine rise from 0 at ``x <= 0`` to 1 at ``x >= 1``.

    >>> ramp(np.array([-1.0, 0.0, 0.5, 1.0, 2.0])).round(3).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0]
    """
    return 0.5 * (1 - np.cos(np.pi * np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)))


# --------------------------------------------------------------------------- the step
def close_lips(pcs: np.ndarray, times: np.ndarray, plan: ClosurePlan, stats: ClosureStats,
               a0: float, g: np.ndarray, taper_s: float) -> np.ndarray:
    """Step 1: for each interval j, the aperture's minimum over its frames ``m_j`` and the move
    ``c_j = s_j min(0, closed - m_j)`` (mm, at most 0); the PCs move by ``c(t) d``, ``c(t)`` the
    most negative ``c_j bump_j(t)``. With strength 1 the minimum inside each interval reaches the
    closed aperture exactly; frames away from every interval are unchanged. Causal intervals
    (the detector's) move as :func:`closure_moves` moves a stream's frames. ``times``: the
    frames' times, ascending.

    >>> st = ClosureStats(1.0, np.array([1.0]), np.array([0.0]))
    >>> plan = ClosurePlan(np.array([[0.2, 0.3]]), np.array([1.0]))
    >>> t = np.arange(6) / 10
    >>> close_lips(np.full((6, 1), 3.0), t, plan, st, 0.0, np.array([1.0]), 0.1)[:, 0].tolist()
    [3.0, 3.0, 1.0, 1.0, 3.0, 3.0]
    """
    pcs = np.asarray(pcs, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    a = a0 + pcs @ g
    c = np.zeros(len(pcs))
    causal = plan.is_causal
    for (t0, t1), s in zip(plan.intervals[~causal], plan.strengths[~causal], strict=True):
        lo, hi = np.searchsorted(times, (t0, t1))        # the frames in [t0, t1)
        if lo == hi:                                     # shorter than a frame: its nearest one
            lo = int(np.argmin(np.abs(times - 0.5 * (t0 + t1))))
            hi = lo + 1
        move = s * min(0.0, stats.closed - float(a[lo:hi].min()))
        if move < 0:
            near = _support(times, t0, t1, taper_s)
            c[near] = np.minimum(c[near], move * bump(times[near], t0, t1, taper_s))
    if causal.any():
        c = np.minimum(c, closure_moves(a, times, plan.intervals[causal], plan.strengths[causal],
                                        stats.closed, taper_s, np.arange(len(a)), clamp=True,
                                        lead=False))
    return pcs + c[:, None] * stats.direction[None, :]


def closure_moves(aperture: np.ndarray, times: np.ndarray, intervals: np.ndarray,
                  strengths: np.ndarray, closed: float, taper_s: float, seen: np.ndarray,
                  at: np.ndarray | None = None, clamp: bool = False, lead: bool = True
                  ) -> np.ndarray:
    """Per frame t, the aperture move ``c(t)`` (mm, at most 0) of :func:`close_lips`, each
    interval's minimum taken over its frames up to ``seen[t]`` (frame t's own aperture when none
    of them is): the move a stream makes when it emits frame t (``seen = t``: causal). ``at``:
    the frames to compute (default all); the result is one move per frame of ``at``. With
    ``clamp``, no frame is moved past the closed aperture (offline a frame can be, where a taper
    after a segment meets a frame already closer than the segment's minimum); ``lead=False``: no
    taper before an interval (a stream does not know a closure before it begins).

    >>> a = np.array([15.0, 14.0, 13.0, 16.0, 15.0]); t = np.arange(5) / 10
    >>> iv, s = np.array([[0.1, 0.3]]), np.array([1.0])
    >>> closure_moves(a, t, iv, s, 11.0, 0.15, np.arange(5)).round(9).tolist()    # causal
    [-1.0, -3.0, -2.0, -2.0, -0.5]
    >>> closure_moves(a, t, iv, s, 11.0, 0.15, np.full(5, 4)).round(9).tolist()   # offline
    [-0.5, -2.0, -2.0, -2.0, -0.5]
    >>> closure_moves(a, t, iv, s, 11.0, 0.15, np.arange(5), lead=False).round(9).tolist()
    [0.0, -3.0, -2.0, -2.0, -0.5]
    """
    a = np.asarray(aperture, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    seen = np.asarray(seen)
    at = np.arange(len(a)) if at is None else np.asarray(at)
    c = np.zeros(len(at))
    for (t0, t1), s in zip(intervals, strengths, strict=True):
        idx = np.flatnonzero((times >= t0) & (times < t1))
        if idx.size == 0:                                # shorter than a frame: its nearest one
            idx = np.array([int(np.argmin(np.abs(times - 0.5 * (t0 + min(t1, times[-1])))))])
        w = bump(times[at], t0, t1, taper_s, lead=lead)
        for k in np.flatnonzero(w > 0):
            t = at[k]
            known = idx[idx <= seen[t]]
            m = float(a[known].min()) if known.size else float(a[t])
            c[k] = min(c[k], s * min(0.0, closed - m) * w[k])
    return c if not clamp else np.maximum(c, np.minimum(0.0, closed - a[at]))


def _support(times: np.ndarray, start: float, end: float, taper_s: float) -> slice:
    """The frames of ascending ``times`` where :func:`bump` of ``[start, end]`` and ``taper_s``
    may be non-zero (0 everywhere else): each interval's work is its own frames, not the input's.

    >>> _support(np.arange(10) / 10, 0.3, 0.4, 0.15)
    slice(2, 6, None)
    """
    taper = max(taper_s, 0.0)
    lo = np.searchsorted(times, start - taper, side="left")
    return slice(int(lo), int(np.searchsorted(times, end + taper, side="right")))


def labelled_speech(segments: Sequence[PhoneSegment], times: np.ndarray) -> np.ndarray:
    """Per frame time of ``times``, whether a phone of ``segments`` that is not a silence
    (``sil``, ``sp``, ``pau``, ...) holds it: a silence there that speech follows is a
    consonant's closure (the /θ t/ of "twentieth time" is 150 ms without energy), not a pause,
    and offline, where the labels of the whole input are known, the face does not rest in it.

    >>> segs = [PhoneSegment(0.0, 0.2, "sil"), PhoneSegment(0.2, 0.35, "t"), PhoneSegment(0.35, 0.6, "sp")]
    >>> labelled_speech(segs, np.array([0.1, 0.25, 0.34, 0.4, 0.7])).tolist()
    [False, True, True, False, False]
    """
    t = np.asarray(times, dtype=np.float64)
    out = np.zeros(len(t), dtype=bool)
    for s in segments:
        if normalise_label(s.label) != SILENCE:
            out |= (t >= s.start) & (t < s.end)
    return out


def outer_silence(silent: np.ndarray) -> np.ndarray:
    """Per frame, whether it belongs to the silence the input begins or ends in (it and every
    frame before it, or after it, silent): the talker has not started or has finished, whatever
    the labels say of it.

    >>> outer_silence(np.array([1, 0, 1, 1, 0, 1, 1], dtype=bool)).tolist()
    [True, False, False, False, False, True, True]
    """
    s = np.asarray(silent, dtype=bool)
    if not len(s):
        return s.copy()
    return np.logical_and.accumulate(s) | np.logical_and.accumulate(s[::-1])[::-1]


def rest_weights(silent: np.ndarray, rate: float, min_s: float, taper_s: float,
                 leading: bool = True, ahead: int = 0, ended: bool = False) -> np.ndarray:
    """Per frame t of ``silent`` (whether each frame is silent), how far the face rests, read from
    frame t, the frames before it and the ``ahead`` frames after it (what a stream has decided
    when it shows frame t): 0 on a speech frame; on a silent frame, the silence *seen* -- its
    frames up to t and those of the next ``ahead`` that are silent too -- counts: 0 until it is
    longer than ``min_s`` (a stop closure's silence is not a pause), then a raised-cosine rise
    over ``taper_s`` to 1. Outside the input is silence: a silence from the input's start
    (``leading``: no speech before ``silent``'s first frame) counts as long already, and where
    the input ends after ``silent``'s last frame (``ended``) the frames after it are silent
    (else they are not decided yet, and count as speech).

    >>> s = np.array([1, 1, 0, 0, 1, 1, 1, 1, 1, 1, 0], dtype=bool)
    >>> rest_weights(s, 10.0, 0.15, 0.1).round(3).tolist()
    [1.0, 1.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0, 0.0]
    >>> rest_weights(s, 10.0, 0.15, 0.1, leading=False)[:3].round(3).tolist()
    [0.0, 0.5, 0.0]
    >>> rest_weights(s, 10.0, 0.15, 0.1, ahead=1).round(3).tolist()
    [1.0, 1.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0]
    >>> e = np.array([0, 1, 1, 0, 1, 1, 1], dtype=bool)
    >>> rest_weights(e, 10.0, 0.25, 0.1, ahead=2).round(3).tolist()
    [0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5]
    >>> rest_weights(e, 10.0, 0.25, 0.1, ahead=2, ended=True).round(3).tolist()
    [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0]
    """
    s = np.asarray(silent, dtype=bool)
    n = len(s)
    if not n:
        return np.zeros(0)
    idx = np.arange(n)
    last_speech = np.maximum.accumulate(np.where(s, -1, idx))
    run = (idx - last_speech).astype(np.float64)            # silent frames ending at each frame
    if leading:
        run[last_speech < 0] = np.inf
    next_speech = np.minimum.accumulate(np.where(s, n, idx)[::-1])[::-1]
    after = next_speech - idx - 1                           # silent frames after it, in ``silent``
    if ended:                                               # and after the input's end
        after = np.where(next_speech == n, ahead, after)
    lasted = (run + np.minimum(after, ahead)) / float(rate)
    x = (lasted - min_s) / taper_s if taper_s > 0 else np.where(lasted > min_s, 1.0, 0.0)
    return np.where(s, ramp(np.where(np.isfinite(x), x, 1.0)), 0.0)


def rest_ahead_frames(rest_lookahead_s: float, rate: float) -> int:
    """The frames after a frame whose silence its rest reads (:func:`rest_weights`' ``ahead``):
    ``rest_lookahead_s`` at ``rate``, rounded.

    >>> rest_ahead_frames(0.05, 60.0)
    3
    """
    return max(0, int(round(rest_lookahead_s * rate)))


def rest_in_pauses(pcs: np.ndarray, plan: ClosurePlan, stats: ClosureStats, rate: float,
                   min_s: float, taper_s: float, ahead: int = 0) -> np.ndarray:
    """Step 2: the PCs ``(T, K)`` of frames 0 .. T-1 blend towards the rest face with the weights
    of :func:`rest_weights` (the plan's silent frames, from its first on, each frame reading
    ``ahead`` frames after it).

    >>> st = ClosureStats(1.0, np.array([1.0]), np.array([0.0]))
    >>> plan = ClosurePlan(np.zeros((0, 2)), np.zeros(0), np.array([0, 1, 1, 1, 1, 0], dtype=bool))
    >>> rest_in_pauses(np.full((6, 1), 2.0), plan, st, 10.0, 0.15, 0.1)[:, 0].round(9).tolist()
    [2.0, 2.0, 1.0, 0.0, 0.0, 2.0]
    """
    pcs = np.asarray(pcs, dtype=np.float64)
    b = frame_rest(plan, len(pcs), rate, min_s, taper_s, ahead=ahead)
    return pcs + b[:, None] * (stats.rest[None, :] - pcs)


def frame_rest(plan: ClosurePlan, count: int, rate: float, min_s: float, taper_s: float,
               first: int = 0, ahead: int = 0) -> np.ndarray:
    """The rest weights (:func:`rest_weights`) of frames ``first .. first + count - 1`` from the
    plan's silent frames, each frame reading ``ahead`` frames after it: those from the plan's
    ``end`` on are silent (the input has ended), other undecided ones speech."""
    stop = first + count
    span = max(stop + ahead - plan.silent_from, 0)
    silent = np.zeros(span, dtype=bool)
    known = plan.silent[:span]
    silent[:len(known)] = known
    if plan.end is not None:
        silent[max(plan.end - plan.silent_from, 0):] = True
    w = rest_weights(silent, rate, min_s, taper_s, plan.leading, ahead)
    out = np.zeros(count)
    lo = max(first, plan.silent_from)
    out[lo - first:] = w[lo - plan.silent_from:stop - plan.silent_from]
    return out


def apply_closure(pcs: np.ndarray, times: np.ndarray, plan: ClosurePlan, stats: ClosureStats,
                  a0: float, g: np.ndarray, rate: float, closure_taper_s: float = 0.05,
                  rest_pause_s: float = 0.1, rest_taper_s: float = 0.05,
                  rest_lookahead_s: float = 0.05) -> np.ndarray:
    """The whole step on smoothed PCs ``(T, K)`` of frames 0 .. T-1 at ``rate``: the lips close
    (:func:`close_lips`), then the face rests in pauses (:func:`rest_in_pauses`)."""
    return rest_in_pauses(close_lips(pcs, times, plan, stats, a0, g, closure_taper_s), plan, stats,
                          rate, rest_pause_s, rest_taper_s, rest_ahead_frames(rest_lookahead_s, rate))
