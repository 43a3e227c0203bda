"""Line spectral frequencies (paper section 2.1): LPC by autocorrelation + Levinson-Durbin, LSF
from the roots of the sum and difference polynomials.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from itertools import pairwise

import numpy as np

from ..level import unit_exponent
from ..threads import above_blas, map_spans

#: white-noise correction added to r[0] (a -40 dB noise floor) so that LPC of near-silent or
#: perfectly periodic frames stays well conditioned.
WHITE_NOISE_CORRECTION = 1e-4


def levinson(r: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Levinson-Durbin recursion on autocorrelations ``r[..., 0..order]``.

    Returns ``a`` with ``a[..., 0] = 1`` (so that ``A(z) = sum a_k z^-k``) and the final
    prediction error. Vectorised over leading axes.

    Examples
    --------
    >>> a, err = levinson(np.array([1.0, 0.5, 0.25]), 2)   # an AR(1) process, pole 0.5
    >>> (np.round(a, 6) + 0.0).tolist(), float(np.round(err, 6))
    ([1.0, -0.5, 0.0], 0.75)
    """
    r = np.asarray(r, dtype=np.float64)
    lead = r.shape[:-1]
    a = np.zeros((*lead, order + 1))
    a[..., 0] = 1.0
    err = r[..., 0].copy()
    for i in range(1, order + 1):
        acc = r[..., i] + np.einsum("...k,...k->...", a[..., 1:i], r[..., i - 1:0:-1])
        safe = np.where(err > 0, err, 1.0)
        k = np.where(err > 0, -acc / safe, 0.0)
        prev = a[..., 1:i].copy()
        a[..., 1:i] = prev + k[..., None] * prev[..., ::-1]
        a[..., i] = k
        err = err * (1.0 - k * k)
    return a, err


@lru_cache(maxsize=8)
def _autocorrelation_basis(n_fft: int, lags: int) -> np.ndarray:
    """``(n_fft/2 + 1, lags)`` matrix taking a power spectrum ``|X_f|^2`` (rfft bins) to the
    autocorrelation lags ``0 .. lags-1``: the inverse real DFT of those columns only."""
    f = np.arange(n_fft // 2 + 1)
    twice = np.full(len(f), 2.0)
    twice[0] = twice[-1] = 1.0                       # DC and Nyquist appear once in a real DFT
    return _frozen(np.cos(2.0 * np.pi * np.outer(f, np.arange(lags)) / n_fft) * (twice / n_fft)[:, None])


def autocorrelation(frames: np.ndarray, lags: int) -> np.ndarray:
    """``r[..., k] = sum_n x[n] x[n+k]`` for ``k < lags`` of frames ``(..., n)``.

    Through a power-of-2 FFT of at least ``n + lags - 1`` points (no circular wrap-around reaches
    the lags kept) and one matrix product for those lags, instead of a full inverse FFT.

    >>> autocorrelation(np.array([1.0, 2.0, 3.0]), 3).round(12).tolist()
    [14.0, 8.0, 3.0]
    """
    frames = np.asarray(frames, dtype=np.float64)
    n = frames.shape[-1]
    n_fft = 1 << max(1, (n + lags - 2).bit_length())
    spec = np.fft.rfft(frames, n_fft, axis=-1)
    return (spec.real ** 2 + spec.imag ** 2) @ _autocorrelation_basis(n_fft, lags)


def lpc(frames: np.ndarray, order: int) -> np.ndarray:
    """LPC polynomial ``a`` (``a[0] = 1``) of each windowed frame by the autocorrelation method.

    ``frames`` is ``(..., n)``; the result is ``(..., order + 1)``.
    """
    r = autocorrelation(frames, order + 1)
    r[..., 0] *= 1.0 + WHITE_NOISE_CORRECTION
    r[..., 0] = np.where(r[..., 0] > 0, r[..., 0], 1.0)  # all-zero frame: A(z) = 1
    a, _ = levinson(r, order)
    return a


def _sum_difference(a: np.ndarray) -> tuple[tuple[int, ...], int, np.ndarray, np.ndarray]:
    """Leading shape, order P and the rows of P(z) = A(z) + z^-(P+1) A(1/z) and
    Q(z) = A(z) - z^-(P+1) A(1/z) (``(B, P+2)`` coefficients in powers of z^-1)."""
    a = np.asarray(a, dtype=np.float64)
    a2 = a.reshape(-1, a.shape[-1])
    ext = np.concatenate([a2, np.zeros((a2.shape[0], 1))], axis=1)
    rev = ext[:, ::-1]
    return a.shape[:-1], a2.shape[1] - 1, ext + rev, ext - rev


def _poly2lsf_companion(a: np.ndarray) -> np.ndarray:
    """:func:`poly2lsf` for any order, through batched (P+1 x P+1) companion-matrix eigenvalues
    of P(z) and Q(z); the trivial roots at z = +-1 are dropped. Used for odd orders."""
    lead, order, p_rows, q_rows = _sum_difference(a)
    angles = []
    for poly in (p_rows, q_rows):
        # companion matrix of the monic polynomial (highest power first is z^0 of A(z^-1) form;
        # the coefficient sequences are palindromic up to sign, so the order does not matter)
        deg = poly.shape[1] - 1
        comp = np.zeros((poly.shape[0], deg, deg))
        comp[:, 0, :] = -poly[:, 1:] / poly[:, :1]
        comp[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
        roots = np.linalg.eigvals(comp)
        ang = np.angle(roots)
        angles.append(ang)
    both = np.concatenate(angles, axis=1)
    # keep angles strictly inside (0, pi): the upper half plane roots, trivial ones at 0 and pi out
    eps = 1e-9
    both = np.where((both > eps) & (both < np.pi - eps), both, np.inf)
    both.sort(axis=1)
    out = both[:, :order]
    if not np.all(np.isfinite(out)):
        raise ValueError("LPC polynomial has roots off the unit circle pairs; is it minimum phase?")
    return out.reshape(*lead, order)


def colleague_eigenvalues(c: np.ndarray) -> np.ndarray:
    """Roots (complex) of Chebyshev series rows ``c`` (``(B, m+1)``, highest last) by batched
    colleague-matrix eigenvalues (numpy's ``chebcompanion``, vectorised over rows)."""
    m = c.shape[1] - 1
    if m == 1:
        return (-c[:, :1] / c[:, 1:]).astype(complex)
    base = np.zeros((m, m))
    idx = np.arange(m - 1)
    base[idx, idx + 1] = 0.5
    base[idx + 1, idx] = 0.5
    base[0, 1] = base[1, 0] = np.sqrt(0.5)
    scl = np.r_[1.0, np.full(m - 1, np.sqrt(0.5))]
    mat = np.broadcast_to(base, (c.shape[0], m, m)).copy()
    mat[:, :, -1] -= (c[:, :-1] / c[:, -1:]) * (scl / scl[-1]) * 0.5
    return np.linalg.eigvals(mat)


#: grid of the root bracketing in :func:`chebyshev_real_roots`: cells of pi/128 rad in w
ROOT_GRID = 128
#: most frames per :func:`chebyshev_real_roots` call in :func:`poly2lsf` (equal chunks)
_ROOT_CHUNK = 1024


def _clenshaw(c: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value and derivative of Chebyshev series at ``x`` (``(R,)``), coefficient ``k`` of every
    series in row ``c[k]`` (``(m+1, R)``: the rows are contiguous), by Clenshaw's recurrence
    ``b_k = c_k + 2x b_(k+1) - b_(k+2)`` and its derivative."""
    m = c.shape[0] - 1
    x2 = 2.0 * x
    b1, b2 = c[m].copy(), np.zeros_like(x)
    d1, d2 = np.zeros_like(x), np.zeros_like(x)
    for k in range(m - 1, 0, -1):
        d1, d2 = 2.0 * b1 + x2 * d1 - d2, d1
        b1, b2 = c[k] + x2 * b1 - b2, b1
    return c[0] + x * b1 - b2, b1 + x * d1 - d2


@lru_cache(maxsize=8)
def root_grid(m: int, grid: int) -> tuple[np.ndarray, np.ndarray]:
    """The grid ``x = cos(w)`` of :func:`chebyshev_real_roots` and ``T_k(x) = cos(k w)``,
    ``(m+1, grid+1)``."""
    w = np.linspace(0.0, np.pi, grid + 1)
    return _frozen(np.cos(w)), _frozen(np.cos(np.outer(np.arange(m + 1), w)))


def _frozen(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only: a cached table is shared by every caller."""
    a.setflags(write=False)
    return a


def chebyshev_real_roots(c: np.ndarray, grid: int = ROOT_GRID, tol: float = 1e-9,
                         max_iter: int = 12) -> np.ndarray:
    """The ``m`` roots in (-1, 1), descending, of Chebyshev series rows ``c`` (``(B, m+1)``,
    highest last) whose roots are all real and inside: the fast kernel of :func:`poly2lsf`.

    Each row is evaluated on ``x = cos(w)`` for ``grid + 1`` angles ``w`` in [0, pi] (one matrix
    product); each sign change brackets one root, which Newton's method (Clenshaw values and
    derivatives, bisection when a step leaves the bracket) polishes until a Newton step is below
    ``tol`` (the step after it would be of order ``tol^2``, at rounding level); a polished root
    leaves the iteration, so its value does not depend on the other rows of the call. A row with
    fewer than ``m`` sign changes (two roots closer than a grid cell) or a root not polished in
    ``max_iter`` steps is solved by the reference instead: the eigenvalues of its colleague matrix
    (:func:`colleague_eigenvalues`). Tested equal to the reference to 1e-12.

    >>> chebyshev_real_roots(np.array([[0.0, 0.0, 1.0]])).round(12).tolist()   # T2: +-1/sqrt 2
    [[0.707106781187, -0.707106781187]]
    """
    c = np.asarray(c, dtype=np.float64)
    n_rows, m = c.shape[0], c.shape[1] - 1
    xg, basis = root_grid(m, grid)
    values = c @ basis                                             # (B, grid+1)
    neg = values < 0
    change = neg[:, 1:] != neg[:, :-1]
    whole = np.count_nonzero(change, axis=1) == m
    flat = np.flatnonzero(change & whole[:, None])
    rows, cells = np.divmod(flat, grid)
    lo, hi = xg[cells + 1], xg[cells]                              # x descends as w ascends
    f_lo, f_hi = values[rows, cells + 1], values[rows, cells]
    x = lo + (hi - lo) * (f_lo / (f_lo - f_hi))                    # regula falsi start
    cr, neg_lo = np.ascontiguousarray(c.T)[:, rows], f_lo < 0
    roots = np.empty(x.shape)
    live = np.arange(x.size)                                       # the roots not yet polished
    for _ in range(max_iter):
        f, fp = _clenshaw(cr, x)
        above = (f < 0) == neg_lo                                  # the root is above x
        lo, hi = np.where(above, x, lo), np.where(above, hi, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = f / fp
        # a Newton step of size s leaves an error of order s^2: done after a small one
        done = np.abs(step) <= tol
        new = x - step
        x = np.where(done | ((new >= lo) & (new <= hi)), new, 0.5 * (lo + hi))
        roots[live[done]] = x[done]
        if done.all():
            live = live[:0]
            break
        if done.any():                                             # iterate on the rest only
            more = ~done
            live, x, lo, hi = live[more], x[more], lo[more], hi[more]
            neg_lo, cr = neg_lo[more], cr[:, more]
    out = np.empty((n_rows, m))
    out[whole] = roots.reshape(-1, m)
    redo = ~whole
    redo[rows[live]] = True
    if redo.any():
        out[redo] = -np.sort(-colleague_eigenvalues(c[redo]).real, axis=1)
    return out


def lsf_chebyshev_series(p_rows: np.ndarray, q_rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Chebyshev series in ``x = cos w`` (``(B, P/2 + 1)``, lowest first) whose roots are the
    LSFs of P(z) and of Q(z) (rows of :func:`_sum_difference`, even order P): the trivial root
    (z = -1 of P, z = +1 of Q) divided out, the symmetric rest folded into a cosine series."""
    order = p_rows.shape[1] - 2
    half = order // 2
    chebs = []
    for poly, sign in ((p_rows, -1.0), (q_rows, 1.0)):
        # divide by (1 - sign z^-1): g_k = p_k + sign g_(k-1); degree P, symmetric
        g = np.empty((poly.shape[0], order + 1))
        g[:, 0] = poly[:, 0]
        for k in range(1, order + 1):
            g[:, k] = poly[:, k] + sign * g[:, k - 1]
        # cosine series: g_half + 2 sum_k g_(half-k) cos(k w) -> Chebyshev coefficients
        chebs.append(np.concatenate([g[:, half:half + 1], 2.0 * g[:, half - 1::-1]], axis=1))
    return chebs[0], chebs[1]


def poly2lsf(a: np.ndarray) -> np.ndarray:
    """LSF in radians, ascending in (0, pi), of LPC polynomials ``a`` (``(..., P+1)``, ``a0 = 1``).

    ``P(z) = A(z) + z^-(P+1) A(1/z)`` and ``Q(z) = A(z) - z^-(P+1) A(1/z)``; their roots lie on
    the unit circle and interlace; the LSF are their angles. The trivial roots (z = -1 of P,
    z = +1 of Q for even order) are divided out, which leaves two symmetric polynomials of degree
    P; on the unit circle each is ``e^(-j w P/2)`` times a cosine series of order P/2, i.e. a
    Chebyshev series in ``x = cos w``, whose P/2 real roots in [-1, 1] are found by
    :func:`chebyshev_real_roots` (grid bracketing and Newton polishing; the batched (P/2 x P/2)
    colleague-matrix eigenvalues are its reference and fallback).

    Examples
    --------
    >>> np.round(poly2lsf(np.array([1.0, 0.0, 0.0])), 4)   # A(z) = 1: uniformly spaced LSF
    array([1.0472, 2.0944])
    """
    lead, order, p_rows, q_rows = _sum_difference(a)
    if order % 2 or order < 2:
        return _poly2lsf_companion(a)
    chebs = lsf_chebyshev_series(p_rows, q_rows)
    n = p_rows.shape[0]
    out = np.empty((n, order))
    bounds = np.linspace(0, n, -(-n // _ROOT_CHUNK) + 1).astype(int).tolist()
    for a0, b0 in pairwise(bounds):                                # a chunk's arrays stay in cache
        x = chebyshev_real_roots(np.concatenate([chebs[0][a0:b0], chebs[1][a0:b0]]))
        both = np.arccos(np.clip(x, -1.0, 1.0))
        out[a0:b0] = np.sort(np.concatenate([both[:b0 - a0], both[b0 - a0:]], axis=1), axis=1)
    if not np.all(np.isfinite(out)):
        raise ValueError("LPC polynomial has roots off the unit circle pairs; is it minimum phase?")
    return out.reshape(*lead, order)


def lsf2poly(lsf: np.ndarray) -> np.ndarray:
    """LPC polynomial from LSF in radians (inverse of :func:`poly2lsf`), for even order."""
    lsf = np.asarray(lsf, dtype=np.float64)
    order = lsf.shape[-1]
    if order % 2:
        raise ValueError("lsf2poly needs an even LPC order")
    p_ang, q_ang = lsf[0::2], lsf[1::2]
    p = np.array([1.0])
    q = np.array([1.0])
    for w in p_ang:
        p = np.convolve(p, [1.0, -2 * np.cos(w), 1.0])
    for w in q_ang:
        q = np.convolve(q, [1.0, -2 * np.cos(w), 1.0])
    p = np.convolve(p, [1.0, 1.0])
    q = np.convolve(q, [1.0, -1.0])
    return 0.5 * (p + q)[: order + 1]


def resample_audio(audio: np.ndarray, rate: int, target: int) -> np.ndarray:
    """Resample with a polyphase filter (``scipy.signal.resample_poly``)."""
    if rate == target:
        return np.asarray(audio, dtype=np.float64)
    g = np.gcd(int(rate), int(target))
    from scipy.signal import resample_poly  # here: scipy.signal takes 1-2 s to import

    return resample_poly(np.asarray(audio, dtype=np.float64), target // g, rate // g)


class ResampleStream:
    """:func:`resample_audio` of a signal that arrives in blocks: the same polyphase filter
    (``scipy.signal.resample_poly``'s Kaiser-windowed sinc, zero outside the signal), each output
    sample computed as soon as the input it depends on has arrived (about ``10 max(up, down) / up``
    input samples of lookahead). The concatenated output equals ``resample_audio`` of the whole
    signal to rounding.

    >>> x = np.sin(np.arange(1000) / 7.0)
    >>> stream = ResampleStream(44100, 16000)
    >>> y = np.concatenate([stream.feed(x[:333]), stream.feed(x[333:]), stream.flush()])
    >>> bool(np.allclose(y, resample_audio(x, 44100, 16000), atol=1e-12))
    True
    """

    def __init__(self, rate: int, target: int):
        g = int(np.gcd(int(rate), int(target)))
        self.up, self.down = int(target) // g, int(rate) // g
        self._identity = self.up == self.down
        #: input samples an output sample waits for beyond its own time
        self.lookahead = 0.0
        if not self._identity:
            from scipy.signal import firwin
            max_rate = max(self.up, self.down)
            half_len = 10 * max_rate
            h = firwin(2 * half_len + 1, 1.0 / max_rate, window=("kaiser", 5.0)) * self.up
            pre = self.down - half_len % self.down
            h = np.concatenate([np.zeros(pre), h])
            self._offset = (half_len + pre) // self.down            # outputs dropped at the start
            taps = -(-len(h) // self.up)
            poly = np.zeros((self.up, taps))                        # poly[phase, m] = h[phase + up m]
            for phase in range(self.up):
                sub = h[phase::self.up]
                poly[phase, :len(sub)] = sub
            self._poly = poly
            self._taps = taps
            self.lookahead = self._offset * self.down / self.up
        self._buffer = np.zeros(0)       # input samples from index self._first on
        self._first = 0
        self._received = 0
        self._emitted = 0

    def _outputs(self, stop: int, n_input: int) -> np.ndarray:
        """Output samples ``self._emitted .. stop-1``, input beyond ``n_input`` taken as zero."""
        i = np.arange(self._emitted, stop)
        j = (i + self._offset) * self.down
        phase, last = j % self.up, j // self.up                     # newest input sample used
        idx = last[:, None] - np.arange(self._taps)[None, :]
        valid = (idx >= 0) & (idx < n_input)
        x = np.where(valid, self._buffer[np.clip(idx - self._first, 0, None)
                                         .clip(max=max(len(self._buffer) - 1, 0))]
                     if len(self._buffer) else 0.0, 0.0)
        y = np.einsum("it,it->i", self._poly[phase], x)
        self._emitted = stop
        keep = max(0, (stop + self._offset) * self.down // self.up - self._taps + 1)
        if keep > self._first:                                      # drop input no longer needed
            self._buffer = self._buffer[keep - self._first:]
            self._first = keep
        return y

    def feed(self, block: np.ndarray) -> np.ndarray:
        """The output samples that ``block`` (the next input samples) completes."""
        block = np.asarray(block, dtype=np.float64).ravel()
        if self._identity:
            self._received += len(block)
            return block.copy()
        self._buffer = np.concatenate([self._buffer, block])
        self._received += len(block)
        # output i is complete once its newest input sample (i + offset) down / up has arrived
        stop = (self._received * self.up - 1) // self.down - self._offset + 1
        stop = max(stop, self._emitted)
        return self._outputs(stop, self._received) if stop > self._emitted else np.zeros(0)

    def flush(self) -> np.ndarray:
        """The remaining output samples, the input ended (``ceil(n up / down)`` in all)."""
        if self._identity:
            return np.zeros(0)
        total = -(-self._received * self.up // self.down)
        return self._outputs(total, self._received) if total > self._emitted else np.zeros(0)


def frame_starts(times: np.ndarray, rate: int) -> np.ndarray:
    """The first sample of the analysis frame centred on each of ``times``, as an index into the
    signal preceded by half a window of zeros (:func:`analysis_frames`).

    >>> frame_starts(np.array([0.0, 1 / 60, 0.5]), 16000).tolist()
    [0, 267, 8000]
    """
    return np.round(np.asarray(times, dtype=np.float64) * rate).astype(int)


def frame_start(time: float, rate: int) -> int:
    """:func:`frame_starts` of one time, in Python numbers (a stream asks for one frame at a
    time, where a numpy call costs more than the arithmetic): the same rounding, half to even.

    >>> t = np.arange(100000) / 60
    >>> [frame_start(x, 16000) for x in t.tolist()] == frame_starts(t, 16000).tolist()
    True
    """
    return int(round(float(time) * rate))


def preemphasize(x: np.ndarray, coefficient: float, previous: float | None = None,
                 out: np.ndarray | None = None) -> np.ndarray:
    """First-order pre-emphasis ``y[i] = x[i] - c x[i-1]``; the first sample is kept as it is, or
    uses ``previous`` (the sample before ``x``, when a signal arrives in blocks). ``out``: where
    to write ``y`` (as long as ``x``, not overlapping it; e.g. the middle of a padded buffer).

    >>> preemphasize(np.array([1.0, 2.0, 4.0]), 0.5).tolist()
    [1.0, 1.5, 3.0]
    >>> preemphasize(np.array([4.0]), 0.5, previous=2.0).tolist()
    [3.0]
    """
    x = np.asarray(x, dtype=np.float64)
    if not coefficient or len(x) == 0:
        if out is None:
            return x
        out[:] = x
        return out
    out = np.empty_like(x) if out is None else out
    np.multiply(x[:-1], -coefficient, out=out[1:])
    out[1:] += x[1:]
    out[0] = x[0] if previous is None else x[0] - coefficient * previous
    return out


def padded_signal(audio: np.ndarray, rate: int, times: np.ndarray, window_s: float,
                  preemphasis: float = 0.0, exponent: int = 0) -> tuple[np.ndarray, np.ndarray, int]:
    """The pre-emphasized signal with half a window of zeros before it and a window after, the
    start in it of the frame of ``window_s`` centred on each of ``times``, and the frame length:
    frame ``t`` is ``pad[starts[t]:starts[t] + n]`` (zero outside the signal). ``exponent``: the
    signal is scaled by ``2 ** exponent`` after its pre-emphasis, in place (exact: as if scaled
    before it, without a copy of the signal; a caller scales down before, where the pre-emphasis
    could overflow)."""
    x = np.asarray(audio, dtype=np.float64)
    n = int(round(window_s * rate))
    pad = np.empty(n // 2 + len(x) + n)                      # written once, not zeroed first
    pad[:n // 2] = 0.0
    signal = pad[n // 2:n // 2 + len(x)]
    preemphasize(x, preemphasis, out=signal)
    if exponent:
        np.ldexp(signal, exponent, out=signal)
    pad[n // 2 + len(x):] = 0.0
    starts = np.minimum(np.maximum(frame_starts(times, rate), 0), len(x))   # clip, without its checks
    return pad, starts, n


def analysis_frames(audio: np.ndarray, rate: int, times: np.ndarray, window_s: float,
                    preemphasis: float = 0.0, exponent: int = 0) -> np.ndarray:
    """Hamming-windowed frames of ``window_s`` centred on ``times`` (zero outside the signal;
    ``exponent`` as :func:`padded_signal`'s)."""
    return windowed(*padded_signal(audio, rate, times, window_s, preemphasis, exponent))


def windowed(pad: np.ndarray, starts: np.ndarray, n: int) -> np.ndarray:
    """The Hamming-windowed frames ``pad[s:s + n]`` of :func:`padded_signal` at ``starts``."""
    frames = np.lib.stride_tricks.sliding_window_view(pad, n)[starts]     # a copy: windowed in place
    frames *= np.hamming(n)
    return frames


def frame_lsf(frames: np.ndarray, order: int) -> np.ndarray:
    """LSF vectors ``(..., order)`` of windowed analysis frames ``(..., n)`` (LPC, then LSF)."""
    return poly2lsf(lpc(frames, order))


def lsf_at(audio: np.ndarray, rate: int, times: np.ndarray, order: int = 18,
           window_s: float = 0.025, audio_rate: int = 16000,
           preemphasis: float = 0.97, threads: int | None = 1) -> np.ndarray:
    """LSF vectors ``(len(times), order)`` from 25 ms Hamming frames centred on ``times``.

    The audio is resampled to ``audio_rate`` first (the paper analyses 16 kHz speech). The frames
    are analysed in ``threads`` spans at once (``None``: :func:`facetraj_engine.threads.frame_threads`).
    The LSFs equal one thread's to rounding: BLAS's matrix products (autocorrelation lags, the
    root bracketing grid) may add a row's terms in another order for another number of rows.
    BLAS runs on one thread here (:func:`facetraj_engine.threads.above_blas`), so the LSFs do not
    depend on the caller's BLAS threads: a caller's ``Model.input_lsf`` is synthesis's own.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> lsf_at(rng.standard_normal(16000), 16000, np.array([0.5]), order=10).shape
    (1, 10)
    """
    return lsf_frames_at(audio, rate, times, order, window_s, audio_rate, preemphasis, threads)[0]


@above_blas
def lsf_frames_at(audio: np.ndarray, rate: int, times: np.ndarray, order: int = 18,
                  window_s: float = 0.025, audio_rate: int = 16000, preemphasis: float = 0.97,
                  threads: int | None = 1,
                  per_frame: Callable[[np.ndarray], np.ndarray] | None = None
                  ) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`lsf_at`, and ``per_frame`` of its windowed frames (a function of frames ``(n, N)``
    giving ``(n, ...)``, run in each span beside the LSFs: e.g. the closure detector's frame
    energies, from the frames already made; ``None``: not asked). The frames are those of the
    input brought to a peak in [0.5, 1) by a power of two before any resampling (the resampled
    signal's peak may then lie just outside it)."""
    x = np.asarray(audio, dtype=np.float64)
    # to a peak in [0.5, 1) by a power of 2 (facetraj_engine.level): exact, and LPC is scale-free,
    # so huge samples cannot overflow to inf; up after the pre-emphasis (padded_signal), down or
    # to resample before
    exponent = unit_exponent(x)
    if exponent < 0 or (exponent and rate != audio_rate):
        x, exponent = np.ldexp(x, exponent), 0
    x = resample_audio(x, rate, audio_rate)
    times = np.asarray(times, dtype=np.float64)
    pad, starts, n = padded_signal(x, audio_rate, times, window_s, preemphasis, exponent)
    # each span windows its own frames (:func:`windowed`), beside the others: the same values as
    # :func:`analysis_frames` makes at once, without one thread gathering them all first
    def span(a: int, b: int) -> tuple[np.ndarray | None, np.ndarray]:
        frames = windowed(pad, starts[a:b], n)
        return None if per_frame is None else per_frame(frames), frame_lsf(frames, order)

    spans = map_spans(span, len(starts), threads)
    lsf = np.concatenate([lsf for _, lsf in spans])
    return lsf, None if per_frame is None else np.concatenate([f for f, _ in spans])
