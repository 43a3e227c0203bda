"""Line spectral frequencies (paper section 2.1): LPC by autocorrelation + Levinson-Durbin, LSF
from the roots of the sum and difference polynomials.
"""

from __future__ import annotations

import numpy as np

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


def lpc(frames: np.ndarray, order: int) -> np.ndarray:
    """LPC polynomial ``a`` (``a[0] = 1``) of each windowed frame by the autocorrelation method.

    ``frames`` is ``(..., n)``; the result is ``(..., order + 1)``.
    """
    frames = np.asarray(frames, dtype=np.float64)
    n = frames.shape[-1]
    spec = np.fft.rfft(frames, 2 * n, axis=-1)
    r = np.fft.irfft(np.abs(spec) ** 2, axis=-1)[..., : order + 1]
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


def _cheb_colleague_eigs(c: np.ndarray) -> np.ndarray:
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


def poly2lsf(a: np.ndarray) -> np.ndarray:
    """LSF in radians, ascending in (0, pi), of LPC polynomials ``a`` (``(..., P+1)``, ``a0 = 1``).

    ``P(z) = A(z) + z^-(P+1) A(1/z)`` and ``Q(z) = A(z) - z^-(P+1) A(1/z)``; their roots lie on
    the unit circle and interlace; the LSF are their angles. The trivial roots (z = -1 of P,
    z = +1 of Q for even order) are divided out, which leaves two symmetric polynomials of degree
    P; on the unit circle each is ``e^(-j w P/2)`` times a cosine series of order P/2, i.e. a
    Chebyshev series in ``x = cos w``, whose P/2 real roots in [-1, 1] are found as the
    eigenvalues of batched (P/2 x P/2) colleague matrices (instead of (P+1 x P+1) companions).

    Examples
    --------
    >>> np.round(poly2lsf(np.array([1.0, 0.0, 0.0])), 4)   # A(z) = 1: uniformly spaced LSF
    array([1.0472, 2.0944])
    """
    lead, order, p_rows, q_rows = _sum_difference(a)
    if order % 2 or order < 2:
        return _poly2lsf_companion(a)
    half = order // 2
    angles = []
    for poly, sign in ((p_rows, -1.0), (q_rows, 1.0)):
        # divide by (1 - sign z^-1): g_k = p_k + sign g_(k-1); degree P, symmetric
        g = np.empty((poly.shape[0], order + 1))
        g[:, 0] = poly[:, 0]
        for k in range(1, order + 1):
            g[:, k] = poly[:, k] + sign * g[:, k - 1]
        # cosine series: g_half + 2 sum_k g_(half-k) cos(k w) -> Chebyshev coefficients
        cheb = np.concatenate([g[:, half:half + 1], 2.0 * g[:, half - 1::-1]], axis=1)
        x = _cheb_colleague_eigs(cheb).real
        angles.append(np.arccos(np.clip(x, -1.0, 1.0)))
    out = np.sort(np.concatenate(angles, axis=1), axis=1)
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


def analysis_frames(audio: np.ndarray, rate: int, times: np.ndarray, window_s: float,
                    preemphasis: float = 0.0) -> np.ndarray:
    """Hamming-windowed frames of ``window_s`` centred on ``times`` (zero outside the signal)."""
    x = np.asarray(audio, dtype=np.float64)
    if preemphasis:
        x = np.concatenate([x[:1], x[1:] - preemphasis * x[:-1]])
    n = int(round(window_s * rate))
    half = n // 2
    pad = np.concatenate([np.zeros(half), x, np.zeros(n)])
    starts = np.round(np.asarray(times) * rate).astype(int)
    starts = np.clip(starts, 0, len(x))
    idx = starts[:, None] + np.arange(n)[None, :]
    return pad[idx] * np.hamming(n)[None, :]


def lsf_at(audio: np.ndarray, rate: int, times: np.ndarray, order: int = 18,
           window_s: float = 0.025, audio_rate: int = 16000,
           preemphasis: float = 0.97) -> np.ndarray:
    """LSF vectors ``(len(times), order)`` from 25 ms Hamming frames centred on ``times``.

    The audio is resampled to ``audio_rate`` first (the paper analyses 16 kHz speech).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> lsf_at(rng.standard_normal(16000), 16000, np.array([0.5]), order=10).shape
    (1, 10)
    """
    x = np.asarray(audio, dtype=np.float64)
    peak = float(np.max(np.abs(x))) if x.size else 0.0
    if 0 < peak < np.inf:  # to a peak in [0.5, 1) by a power of 2: exact, and LPC is scale-free,
        x = np.ldexp(x, -int(np.frexp(peak)[1]))  # so huge samples cannot overflow to inf
    x = resample_audio(x, rate, audio_rate)
    frames = analysis_frames(x, audio_rate, np.asarray(times, dtype=np.float64), window_s,
                             preemphasis)
    return poly2lsf(lpc(frames, order))
