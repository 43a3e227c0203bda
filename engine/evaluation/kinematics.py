"""Lip kinematics as phoneticians measure them, and articulatory gesture landmarks.

Lip aperture (upper-to-lower lip distance), lip width (corner to corner) and protrusion (forward
displacement of the lips from the neutral face), the tangential velocity of any marker, and the
landmarks of a gesture found on the tangential velocity with a threshold (Tiede's ``findgest``
convention, 20 % of the peak by default):

``onset``      the velocity rises through ``threshold * peak`` before the closing peak;
``pvel``       the peak velocity of the closing movement;
``maxc``       maximum constriction, the velocity minimum between the two peaks;
``pvel2``      the peak velocity of the release movement;
``offset``     the velocity falls through ``threshold * release peak`` after the release peak.

Times are interpolated below a frame (linear for threshold crossings, parabolic for extrema), so
on a clean trajectory they land within a frame of the truth. Markers are ``(T, M, 3)`` mm in the
model's head frame (x right, y up, z forward).
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter1d

from ..data import PhoneSegment
from ..io.files import atomic_write

log = logging.getLogger(__name__)

LANDMARKS = ("onset", "pvel", "maxc", "pvel2", "offset")
#: Phones whose gestures are lip gestures (bilabials, labiodentals, rounding glide).
LABIAL_PHONES = ("p", "b", "m", "f", "v", "w")


# ---------------------------------------------------------------------- lip measures
@dataclass
class LipMeasures:
    """Per-frame lip measures in mm, each ``(T,)``; ``width`` is NaN without lip corners."""

    aperture: np.ndarray
    width: np.ndarray
    protrusion: np.ndarray


def lip_measures(markers: np.ndarray, upper: int, lower: int, corners: Sequence[int] = (),
                 neutral: np.ndarray | None = None, forward_axis: int = 2) -> LipMeasures:
    """Lip aperture, width and protrusion of ``(T, M, 3)`` markers.

    aperture : Euclidean distance between the upper and lower lip centre markers.
    width : distance between the two lip corners (``corners`` = right, left).
    protrusion : mean forward coordinate of the two lip centre markers, minus that of the
        ``neutral`` face ``(M, 3)`` when given (so 0 is the rest position).

    Examples
    --------
    >>> m = np.zeros((1, 4, 3)); m[0, 0] = [0, 5, 2]; m[0, 1] = [0, -3, 4]
    >>> m[0, 2] = [20, 0, 0]; m[0, 3] = [-20, 0, 0]
    >>> lm = lip_measures(m, 0, 1, (2, 3))
    >>> float(lm.aperture[0]), float(lm.width[0]), float(lm.protrusion[0])
    (8.246..., 40.0, 3.0)
    """
    m = np.asarray(markers, dtype=np.float64)
    aperture = np.linalg.norm(m[:, upper] - m[:, lower], axis=-1)
    if len(corners) >= 2:
        width = np.linalg.norm(m[:, corners[0]] - m[:, corners[1]], axis=-1)
    else:
        width = np.full(m.shape[0], np.nan)
    protrusion = 0.5 * (m[:, upper, forward_axis] + m[:, lower, forward_axis])
    if neutral is not None:
        protrusion = protrusion - 0.5 * (neutral[upper, forward_axis] + neutral[lower, forward_axis])
    return LipMeasures(aperture, width, protrusion)


def model_lip_measures(model, markers: np.ndarray) -> LipMeasures:
    """:func:`lip_measures` with the model's lip markers, protrusion relative to its neutral face."""
    return lip_measures(markers, model.upper_lip, model.lower_lip, model.lip_corners,
                        model.neutral_face())


# ---------------------------------------------------------------------- velocity
def tangential_velocity(trajectory: np.ndarray, rate: float, smooth_s: float = 0.0) -> np.ndarray:
    """Tangential velocity (speed, mm/s) of a trajectory ``(T, 3)`` (or ``(T,)``/``(T, D)``).

    Central differences (one-sided at the ends). ``smooth_s`` > 0 applies a light Gaussian
    smoothing of the positions first (its standard deviation in seconds); being symmetric it
    shifts no landmark. NaN positions are bridged by linear interpolation for the differences and
    give NaN velocity.

    Examples
    --------
    >>> x = np.stack([np.arange(5.0) * 2, np.zeros(5), np.zeros(5)], axis=1)   # 2 mm per frame
    >>> tangential_velocity(x, rate=60).tolist()
    [120.0, 120.0, 120.0, 120.0, 120.0]
    """
    x = np.asarray(trajectory, dtype=np.float64)
    if x.ndim == 1:
        x = x[:, None]
    bad = ~np.isfinite(x).all(axis=1)
    if bad.all():
        return np.full(x.shape[0], np.nan)
    if bad.any():
        good = np.flatnonzero(~bad)
        x = np.stack([np.interp(np.arange(len(x)), good, x[good, d]) for d in range(x.shape[1])],
                     axis=1)
    if smooth_s > 0:
        x = gaussian_filter1d(x, smooth_s * rate, axis=0, mode="nearest")
    if len(x) < 2:
        return np.zeros(len(x))
    v = np.linalg.norm(np.gradient(x, axis=0), axis=1) * rate
    v[bad] = np.nan
    return v


# ---------------------------------------------------------------------- landmarks
@dataclass
class Gesture:
    """The landmarks of one gesture, in seconds (NaN where not found).

    ``label`` names the gesture (usually its anchor phone), ``anchor`` is the time searched
    around; ``v_pvel`` and ``v_pvel2`` are the two peak velocities (mm/s).
    """

    label: str
    anchor: float
    onset: float
    pvel: float
    maxc: float
    pvel2: float
    offset: float
    v_pvel: float
    v_pvel2: float

    def times(self) -> dict[str, float]:
        """The five landmark times by name."""
        return {k: getattr(self, k) for k in LANDMARKS}


def _parabolic(v: np.ndarray, i: int) -> float:
    """Sub-frame position of an extremum at frame ``i`` (parabola through i-1, i, i+1)."""
    if i <= 0 or i >= len(v) - 1:
        return float(i)
    a, b, c = v[i - 1], v[i], v[i + 1]
    den = a - 2 * b + c
    if not np.isfinite(den) or abs(den) < 1e-12:
        return float(i)
    return float(i + 0.5 * (a - c) / den)


def _crossing(v: np.ndarray, start: int, level: float, step: int, stop: int) -> float:
    """Walk from ``start`` by ``step`` until ``v`` drops below ``level``; the interpolated
    fractional frame where it crosses, or ``stop`` when it never does."""
    i = start
    while i != stop:
        j = i + step
        if v[j] < level:
            frac = (v[i] - level) / (v[i] - v[j]) if v[i] != v[j] else 0.0
            return float(i + step * frac)
        i = j
    return float(stop)


def _local_minima(v: np.ndarray, lo: int, hi: int) -> np.ndarray:
    idx = np.arange(max(lo, 1), min(hi, len(v) - 1))
    if idx.size == 0:
        return idx
    ok = (v[idx] <= v[idx - 1]) & (v[idx] <= v[idx + 1]) & ((v[idx] < v[idx - 1]) | (v[idx] < v[idx + 1]))
    return idx[ok]


def _nearest_peak(v: np.ndarray, lo: int, hi: int, before: bool, strong: float = 0.5) -> int:
    """The local velocity maximum in ``[lo, hi]`` nearest ``hi`` (``before``) or ``lo`` among those
    at least ``strong`` times the largest; the plain maximum when there is no local maximum."""
    seg = v[lo:hi + 1]
    if seg.size < 3:
        return lo + int(np.argmax(seg))
    inner = np.arange(1, seg.size - 1)
    peaks = inner[(seg[inner] >= seg[inner - 1]) & (seg[inner] >= seg[inner + 1])
                  & ((seg[inner] > seg[inner - 1]) | (seg[inner] > seg[inner + 1]))]
    peaks = peaks[seg[peaks] >= strong * seg.max()]
    if peaks.size == 0:
        return lo + int(np.argmax(seg))
    return lo + int(peaks[-1] if before else peaks[0])


def find_gesture(velocity: np.ndarray, rate: float, anchor: float, threshold: float = 0.2,
                 window_s: float = 0.25, search: tuple[float, float] | None = None,
                 label: str = "", t0: float = 0.0) -> Gesture:
    """The landmarks of the gesture around time ``anchor`` on a tangential velocity ``(T,)``.

    Maximum constriction is the velocity minimum in ``search`` (seconds; default ``anchor`` +-
    ``window_s / 2``) nearest ``anchor``; the closing and release peaks are the velocity maxima
    within ``window_s`` before and after it (the nearest local maxima reaching half the largest
    one); onset and offset are where the velocity crosses ``threshold`` times the closing and the
    release peak, searched back (forward) no further than the velocity minimum before (after) the
    peak, which stands in when the speed never falls that low. ``t0`` is the time of frame 0.

    Examples
    --------
    >>> t = np.arange(61) / 60.0
    >>> v = np.abs(np.sin(2 * np.pi * t)) * 100        # peaks at 0.25 s and 0.75 s, min at 0.5 s
    >>> g = find_gesture(v, 60.0, anchor=0.5, window_s=0.5)
    >>> round(g.pvel, 3), round(g.maxc, 3), round(g.pvel2, 3)
    (0.25, 0.5, 0.75)
    """
    v = np.asarray(velocity, dtype=np.float64)
    v = np.where(np.isfinite(v), v, 0.0)
    n = len(v)
    nan = float("nan")
    none = Gesture(label, anchor, nan, nan, nan, nan, nan, nan, nan)
    if n < 3:
        return none
    a = (anchor - t0) * rate
    win = max(2, int(round(window_s * rate)))
    if search is None:
        lo, hi = int(math.floor(a - win / 2)), int(math.ceil(a + win / 2))
    else:
        lo, hi = int(math.floor((search[0] - t0) * rate)), int(math.ceil((search[1] - t0) * rate))
    lo, hi = max(lo, 0), min(hi, n - 1)
    if hi <= lo:
        return none
    minima = _local_minima(v, lo, hi + 1)
    if minima.size:
        deepest = v[minima].min()
        # of the clear minima (within 20 % of the peak range of the deepest) the one nearest anchor
        span = v[lo:hi + 1].max() - deepest
        clear = minima[v[minima] <= deepest + 0.2 * span]
        m = int(clear[np.argmin(np.abs(clear - a))])
    else:
        m = lo + int(np.argmin(v[lo:hi + 1]))
    b0 = max(0, m - win)
    b1 = min(n - 1, m + win)
    p1 = _nearest_peak(v, b0, m, before=True)
    p2 = _nearest_peak(v, m, b1, before=False)
    if v[p1] <= 0 or v[p2] <= 0:
        return none
    # onset/offset: the threshold crossing, searched no further than the velocity minimum between
    # the peak and the window edge (in running speech the speed rarely falls to 20 % between moves)
    lo_bound = b0 + int(np.argmin(v[b0:p1 + 1]))
    hi_bound = p2 + int(np.argmin(v[p2:b1 + 1]))
    onset = _crossing(v, p1, threshold * v[p1], -1, lo_bound) if p1 > lo_bound else float(lo_bound)
    offset = _crossing(v, p2, threshold * v[p2], 1, hi_bound) if p2 < hi_bound else float(hi_bound)
    to_t = lambda f: t0 + f / rate  # noqa: E731
    return Gesture(label, anchor, to_t(onset), to_t(_parabolic(v, p1)), to_t(_parabolic(v, m)),
                   to_t(_parabolic(v, p2)), to_t(offset), float(v[p1]), float(v[p2]))


def gesture_anchors(phones: Sequence[PhoneSegment],
                    labels: Iterable[str] = LABIAL_PHONES) -> list[PhoneSegment]:
    """The phone segments whose label is in ``labels`` (the gestures to measure)."""
    wanted = {x.lower() for x in labels}
    return [s for s in phones if s.label.lower() in wanted]


def find_gestures(velocity: np.ndarray, rate: float, segments: Sequence[PhoneSegment],
                  threshold: float = 0.2, window_s: float = 0.25, margin_s: float = 0.05,
                  t0: float = 0.0) -> list[Gesture]:
    """One gesture per phone segment: maximum constriction searched inside the segment (widened
    by ``margin_s`` on each side), anchored at its centre; see :func:`find_gesture`."""
    out = []
    for s in segments:
        mid = 0.5 * (s.start + s.end)
        out.append(find_gesture(velocity, rate, mid, threshold, window_s,
                                (s.start - margin_s, s.end + margin_s), s.label, t0))
    return out


@dataclass
class GestureMeasurement:
    """Tangential velocity and gestures of one marker in the original and the synthesized
    trajectories (the original parts are empty/None without original markers)."""

    marker: int
    threshold: float
    times: np.ndarray
    v_original: np.ndarray | None
    v_synthesized: np.ndarray
    original: list[Gesture]
    synthesized: list[Gesture]

    def levels(self, g: Gesture) -> tuple[float, float]:
        """The onset and offset threshold levels (mm/s) of gesture ``g``."""
        return self.threshold * g.v_pvel, self.threshold * g.v_pvel2

    def pairs(self) -> list[LandmarkTiming]:
        """Original and synthesized gestures paired by anchor (empty without the original)."""
        return compare_landmarks(self.original, self.synthesized) if self.v_original is not None else []


def measure_gestures(synthesized: np.ndarray, original: np.ndarray | None, marker: int, rate: float,
                     phones: Sequence[PhoneSegment], labels: Iterable[str] = LABIAL_PHONES,
                     threshold: float = 0.2, smooth_s: float = 0.0, window_s: float = 0.25,
                     t0: float = 0.0) -> GestureMeasurement:
    """Tangential velocity of ``marker`` in ``(T, M, 3)`` synthesized (and original) markers and
    the gestures anchored on the phone segments labelled with ``labels``."""
    segs = gesture_anchors(phones, labels)
    vs = tangential_velocity(synthesized[:, marker], rate, smooth_s)
    gs = find_gestures(vs, rate, segs, threshold, window_s, t0=t0)
    vo, go = None, []
    if original is not None:
        vo = tangential_velocity(original[:, marker], rate, smooth_s)
        go = find_gestures(vo, rate, segs, threshold, window_s, t0=t0)
    times = t0 + np.arange(len(vs)) / rate
    return GestureMeasurement(marker, threshold, times, vo, vs, go, gs)


@dataclass
class LandmarkTiming:
    """One gesture found in the original and the synthesized trajectory, and the timing error
    (synthesized minus original, seconds) of each landmark."""

    original: Gesture
    synthesized: Gesture

    def errors(self) -> dict[str, float]:
        o, s = self.original.times(), self.synthesized.times()
        return {k: s[k] - o[k] for k in LANDMARKS}


def compare_landmarks(original: Sequence[Gesture], synthesized: Sequence[Gesture]) -> list[LandmarkTiming]:
    """Pair the gestures found on the same anchors (both lists from the same segments)."""
    if len(original) != len(synthesized):
        raise ValueError("original and synthesized gestures must come from the same anchors")
    return [LandmarkTiming(o, s) for o, s in zip(original, synthesized, strict=True)]


@dataclass(frozen=True)
class LandmarkError:
    """One row of the landmark table: gesture number (from 1), its phone, the landmark, and its
    times (s) in the original and the synthesized trajectory; ``error`` is synthesized minus
    original (s), NaN where either is missing."""

    gesture: int
    label: str
    landmark: str
    original: float
    synthesized: float

    @property
    def error(self) -> float:
        return self.synthesized - self.original


def landmark_rows(m: GestureMeasurement) -> list[LandmarkError]:
    """The landmark table of a measurement, gesture by gesture in :data:`LANDMARKS` order (the
    original times NaN without original markers)."""
    pairs = m.pairs()
    if pairs:
        return [LandmarkError(gi + 1, p.original.label, k, p.original.times()[k],
                              p.synthesized.times()[k])
                for gi, p in enumerate(pairs) for k in LANDMARKS]
    return [LandmarkError(gi + 1, g.label, k, float("nan"), t)
            for gi, g in enumerate(m.synthesized) for k, t in g.times().items()]


def mean_abs_timing_error(pairs: Sequence[LandmarkTiming]) -> dict[str, float]:
    """Mean absolute timing error (seconds) of each landmark over gesture pairs (NaN skipped).

    Examples
    --------
    >>> g = lambda t: Gesture("m", 0, t, t, t, t, t, 1, 1)
    >>> mean_abs_timing_error([LandmarkTiming(g(1.0), g(1.02)), LandmarkTiming(g(2.0), g(1.96))])["maxc"]
    0.03...
    """
    out = {}
    for k in LANDMARKS:
        e = np.array([p.errors()[k] for p in pairs], dtype=float)
        e = e[np.isfinite(e)]
        out[k] = float(np.abs(e).mean()) if e.size else float("nan")
    return out


# ---------------------------------------------------------------------- export
def write_landmarks_tsv(path: str | os.PathLike[str], gestures: Mapping[str, Sequence[Gesture]],
                        marker: str = "", overwrite: bool = True) -> Path:
    """Write gestures as TSV: one row per gesture with ``source`` (e.g. original / synthesized),
    ``marker``, the gesture fields, and for sources after the first the timing error of each
    landmark against the first source's gesture on the same anchor (``d_<landmark>``)."""
    path = Path(path)
    names = [f.name for f in fields(Gesture)]
    sources = list(gestures)
    ref = list(gestures[sources[0]]) if sources else []
    header = ["source", "marker", *names, *(f"d_{k}" for k in LANDMARKS)]
    lines = ["\t".join(header)]
    for src in sources:
        for i, g in enumerate(gestures[src]):
            row = asdict(g)
            cells = [src, marker] + [row["label"]] + [_fmt(row[n]) for n in names[1:]]
            if src != sources[0] and i < len(ref):
                cells += [_fmt(getattr(g, k) - getattr(ref[i], k)) for k in LANDMARKS]
            else:
                cells += [""] * len(LANDMARKS)
            lines.append("\t".join(cells))
    with atomic_write(path, overwrite) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _fmt(x: float) -> str:
    return "" if not np.isfinite(x) else f"{x:.4f}"


def write_landmarks_textgrid(path: str | os.PathLike[str], gestures: Mapping[str, Sequence[Gesture]],
                             duration: float, overwrite: bool = True) -> Path:
    """Write one Praat point tier per source; each point is labelled ``<landmark> <gesture label>``
    (e.g. ``maxc m``). Points closer than 0.1 ms to an earlier one on the same tier are dropped
    (Praat needs distinct times)."""
    from praatio import textgrid

    path = Path(path)
    duration = round(float(duration), 6)
    tg = textgrid.Textgrid()
    for src, gs in gestures.items():
        points: list[tuple[float, str]] = []
        for g in gs:
            for k, t in g.times().items():
                if np.isfinite(t) and 0.0 <= t <= duration:
                    points.append((round(float(t), 6), f"{k} {g.label}".strip()))
        points.sort()
        kept: list[tuple[float, str]] = []
        for t, lab in points:
            if kept and t - kept[-1][0] < 1e-4:
                continue
            kept.append((t, lab))
        tg.addTier(textgrid.PointTier(src, kept, 0.0, duration))
    with atomic_write(path, overwrite) as tmp:
        tg.save(str(tmp), format="long_textgrid", includeBlankSpaces=True)
    return path
