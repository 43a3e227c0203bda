"""Smoothing of synthesized PC trajectories (paper section 2.3): a 100 ms triangular window, or a
cubic spline.

Both are computed in numpy (:func:`convolve_nearest`, :func:`not_a_knot_spline`; tested equal to
``scipy.ndimage.convolve1d`` and ``scipy.interpolate.CubicSpline``): importing those scipy
modules takes longer than the app's whole synthesis of its first utterance (issue #15).
"""

from __future__ import annotations

import numpy as np


def triangular_window(rate: float, width_s: float = 0.1) -> np.ndarray:
    """A normalised triangular window spanning ``width_s`` (odd length, so zero phase).

    At 60 Hz, 100 ms gives 7 taps ``[1 2 3 4 3 2 1] / 16``.

    Examples
    --------
    >>> (triangular_window(60.0) * 16).round(6).tolist()
    [1.0, 2.0, 3.0, 4.0, 3.0, 2.0, 1.0]
    """
    n = int(round(width_s * rate))
    n = max(1, n + 1 if n % 2 == 0 else n)
    half = (n + 1) // 2
    w = np.concatenate([np.arange(1, half + 1), np.arange(half - 1, 0, -1)]).astype(float)
    return w / w.sum()


def convolve_nearest(x: np.ndarray, window: np.ndarray) -> np.ndarray:
    """``x`` convolved along axis 0 with a symmetric odd-length ``window``, the edges extended
    with the end values (``scipy.ndimage.convolve1d(x, window, axis=0, mode="nearest")``).

    >>> convolve_nearest(np.array([0.0, 0.0, 3.0]), np.ones(3) / 3).tolist()
    [0.0, 1.0, 2.0]
    """
    x = np.asarray(x, dtype=np.float64)
    half = len(window) // 2
    padded = np.concatenate([np.repeat(x[:1], half, axis=0), x, np.repeat(x[-1:], half, axis=0)])
    out = np.zeros_like(x)
    for k, w in enumerate(window):
        out += w * padded[k:k + len(x)]
    return out


def triangular_smooth(x: np.ndarray, rate: float, width_s: float = 0.1) -> np.ndarray:
    """Zero-phase triangular moving average along axis 0 (edges extended with the end values)."""
    return convolve_nearest(x, triangular_window(rate, width_s))


def not_a_knot_spline(knots: np.ndarray, values: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The not-a-knot cubic spline through ``(knots, values)`` (along axis 0 of ``values``)
    evaluated at ``at`` (within the knots): ``scipy.interpolate.CubicSpline(knots, values,
    axis=0, bc_type="not-a-knot")(at)``. Two knots give a line, three a parabola.

    >>> not_a_knot_spline(np.arange(5.0), np.arange(5.0) ** 3, np.array([1.5, 2.5])).round(9).tolist()
    [3.375, 15.625]
    """
    x = np.asarray(knots, dtype=np.float64)
    y = np.asarray(values, dtype=np.float64)
    dx = np.diff(x).reshape(-1, *([1] * (y.ndim - 1)))
    slope = np.diff(y, axis=0) / dx
    n = len(x)
    if n == 2:
        s = np.stack([slope[0], slope[0]])
    elif n == 3:
        a = np.array([[1.0, 1.0, 0.0],
                      [dx[1].item(), 2.0 * (dx[0] + dx[1]).item(), dx[0].item()],
                      [0.0, 1.0, 1.0]])
        b = np.stack([2 * slope[0], 3 * (dx[0] * slope[1] + dx[1] * slope[0]), 2 * slope[1]])
        s = np.linalg.solve(a, b.reshape(3, -1)).reshape(b.shape)
    else:
        s = _not_a_knot_slopes(dx, slope)
    i = np.clip(np.searchsorted(x, at, side="right") - 1, 0, n - 2)
    t = (np.asarray(at, dtype=np.float64) - x[i]).reshape(-1, *([1] * (y.ndim - 1)))
    h = dx[i]
    c2 = (3 * slope[i] - 2 * s[i] - s[i + 1]) / h
    c3 = (s[i] + s[i + 1] - 2 * slope[i]) / h ** 2
    return ((c3 * t + c2) * t + s[i]) * t + y[i]


def _not_a_knot_slopes(dx: np.ndarray, slope: np.ndarray) -> np.ndarray:
    """The spline's slopes at four or more knots: the tridiagonal system of
    ``scipy.interpolate.CubicSpline`` (continuous second derivative inside, not-a-knot at both
    ends), solved by elimination without pivoting (its pivots stay positive)."""
    n = len(dx) + 1
    lower = np.empty((n, *dx.shape[1:]))      # lower[i]: the coefficient of s[i - 1] in row i
    diag = np.empty_like(lower)
    upper = np.empty_like(lower)              # upper[i]: the coefficient of s[i + 1] in row i
    rhs = np.empty((n, *slope.shape[1:]))
    d0, d1 = dx[0] + dx[1], dx[-2] + dx[-1]
    diag[0], upper[0] = dx[1], d0
    rhs[0] = ((dx[0] + 2 * d0) * dx[1] * slope[0] + dx[0] ** 2 * slope[1]) / d0
    lower[1:-1], diag[1:-1], upper[1:-1] = dx[1:], 2 * (dx[:-1] + dx[1:]), dx[:-1]
    rhs[1:-1] = 3 * (dx[1:] * slope[:-1] + dx[:-1] * slope[1:])
    lower[-1], diag[-1] = d1, dx[-2]
    rhs[-1] = (dx[-1] ** 2 * slope[-2] + (2 * d1 + dx[-1]) * dx[-2] * slope[-1]) / d1
    for i in range(1, n):                     # forward elimination
        f = lower[i] / diag[i - 1]
        diag[i] = diag[i] - f * upper[i - 1]
        rhs[i] = rhs[i] - f * rhs[i - 1]
    s = np.empty_like(rhs)
    s[-1] = rhs[-1] / diag[-1]
    for i in range(n - 2, -1, -1):            # back substitution
        s[i] = (rhs[i] - upper[i] * s[i + 1]) / diag[i]
    return s


def spline_smooth(x: np.ndarray, rate: float, knot_s: float = 0.1) -> np.ndarray:
    """Spline smoothing along axis 0: a cubic spline through knots every ``knot_s`` seconds.

    The knot values are local means of ``x`` over ``knot_s`` (a box average centred on the knot),
    and the not-a-knot cubic spline through them is evaluated at every frame. The result passes
    smoothly between knots (more natural motion) but lags and undershoots fast gestures; the paper
    reports the same trade-off.
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    step = max(1, int(round(knot_s * rate)))
    if n < 4 or step >= n:
        return triangular_smooth(x, rate, knot_s)
    knots = np.arange(0, n, step)
    if knots[-1] != n - 1:
        knots = np.append(knots, n - 1)
    box = np.ones(step | 1) / (step | 1)
    local = convolve_nearest(x, box)
    return not_a_knot_spline(knots, local[knots], np.arange(n))


def smooth(x: np.ndarray, rate: float, method: str = "triangular", width_s: float = 0.1,
           knot_s: float = 0.1) -> np.ndarray:
    """Apply ``triangular``, ``spline`` or ``none`` smoothing along axis 0."""
    if method == "triangular":
        return triangular_smooth(x, rate, width_s)
    if method == "spline":
        return spline_smooth(x, rate, knot_s)
    if method == "none":
        return np.asarray(x, dtype=np.float64).copy()
    raise ValueError(f"unknown smoothing {method!r} (triangular, spline or none)")


class TriangularStream:
    """:func:`triangular_smooth` of frames that arrive in blocks.

    Smoothed frame t needs the raw frames up to ``t + lookahead`` (``lookahead`` = half the window
    minus one: 3 frames, 50 ms, for 100 ms at 60 Hz). The edges are extended with the end values
    as offline: the first frame is known when it arrives, the last one at :meth:`flush`. So the
    concatenated output equals the offline smoothing of all the frames, only ``lookahead`` frames
    later. ``width_s = 0`` (a one-tap window) passes frames through.

    >>> x = np.arange(10.0)[:, None] ** 2
    >>> s = TriangularStream(60.0)
    >>> y = np.concatenate([s.feed(x[:4]), s.feed(x[4:5]), s.feed(x[5:]), s.flush()])
    >>> bool(np.allclose(y, triangular_smooth(x, 60.0)))
    True
    """

    def __init__(self, rate: float, width_s: float = 0.1):
        self.window = triangular_window(rate, width_s) if width_s > 0 else np.ones(1)
        self.lookahead = len(self.window) // 2
        self._history: np.ndarray | None = None     # the last 2 * lookahead raw frames (padded)
        self._received = 0
        self._emitted = 0

    def _convolve(self, padded: np.ndarray, count: int) -> np.ndarray:
        n = len(self.window)
        return sum(self.window[k] * padded[k:k + count] for k in range(n))

    def feed(self, frames: np.ndarray) -> np.ndarray:
        """The smoothed frames that ``frames`` (the next raw frames, ``(n, K)``) complete."""
        frames = np.asarray(frames, dtype=np.float64)
        if len(frames) == 0:
            return frames.copy()
        if self._history is None:                     # 'nearest' edge: repeat the first frame
            self._history = np.repeat(frames[:1], self.lookahead, axis=0)
        buf = np.concatenate([self._history, frames])
        self._received += len(frames)
        count = max(0, self._received - self.lookahead - self._emitted)
        out = self._convolve(buf, count) if count else np.zeros((0, *frames.shape[1:]))
        self._emitted += count
        self._history = buf[max(0, len(buf) - 2 * self.lookahead):] if self.lookahead else buf[:0]
        return out

    def flush(self) -> np.ndarray:
        """The last ``lookahead`` smoothed frames (the end extended with the last frame)."""
        if self._history is None or self._emitted >= self._received:
            return np.zeros((0,) if self._history is None else (0, *self._history.shape[1:]))
        count = self._received - self._emitted
        buf = self._history[len(self._history) - (count + self.lookahead):]
        buf = np.concatenate([buf, np.repeat(buf[-1:], self.lookahead, axis=0)])
        self._emitted = self._received
        return self._convolve(buf, count)
