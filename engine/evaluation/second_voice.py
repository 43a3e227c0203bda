"""A second voice for testing speaker normalisation (issue 13): the training voice made to sound as
if from a shorter vocal tract and a higher larynx voice, with its timing unchanged sample for
sample, so that the original face markers still line up with it frame for frame.

It is a source-filter transform (LPC analysis-synthesis, Markel & Gray, *Linear Prediction of
Speech*, 1976, ch. 10): every 5 ms the LPC polynomial of the speech is found (autocorrelation
method), the speech is inverse-filtered to its residual (the excitation), the residual's pitch is
raised by resampling it and time-stretching it back to its length by WSOLA (Verhelst & Roelands,
ICASSP 1993), and the raised excitation drives the all-pole filter whose pole angles (the
formants) are moved by a nonuniform frequency map. The map scales low frequencies (F1) less than
the F2/F3 region, as Fant's female/male "k factors" do (Fant, "A note on vocal tract size factors
and non-uniform F-pattern scalings", STL-QPSR 7(4), 1966: about 1.1 to 1.2 depending on formant
and vowel); at the top of the band it returns to the identity so that the map stays inside
``(0, nyquist)``. Finally the level is matched to the original's short-time level (so silence
stays silence and the speech/silence detection sees the same frames).

The normaliser (``facetraj_engine.method.speaker``) warps LSFs by one factor below a knee; this voice's map has
factors that change with frequency, so it is not one of the normaliser's own warps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..errors import InputError
from ..method.lsf import lpc

#: the frame hop of the analysis-synthesis (s)
HOP_S = 0.005
#: the LPC analysis window (s)
WINDOW_S = 0.025


@dataclass(frozen=True)
class VoiceSpec:
    """What the second voice is.

    Attributes
    ----------
    formant_factors : ``(Hz, factor)`` anchors: a frequency ``f`` moves to ``k(f) f`` with ``k``
        piecewise-linear between the anchors (constant outside them).
    top_hz : above it the map is the straight line from ``(top, k(top) top)`` to
        ``(nyquist, nyquist)``.
    f0_factor : the factor on the fundamental frequency.
    """

    formant_factors: tuple[tuple[float, float], ...] = ((500.0, 1.10), (1500.0, 1.20),
                                                        (4000.0, 1.20))
    top_hz: float = 5000.0
    f0_factor: float = 1.7
    name: str = "shorter vocal tract (female-like)"


def check_audio(audio: np.ndarray, what: str = "audio", min_samples: int = 2) -> np.ndarray:
    """``audio`` as a float64 1-D array, or an :class:`InputError` naming what is wrong.

    >>> check_audio([0.0, 0.5]).tolist()
    [0.0, 0.5]
    >>> check_audio([0.0, float("nan")])
    Traceback (most recent call last):
    ...
    facetraj_engine.errors.InputError: audio: the audio has 1 sample that is not a finite number (NaN or inf)
    """
    x = np.asarray(audio, dtype=np.float64)
    if x.ndim != 1:
        raise InputError(what, f"the audio must be one channel (1-D), got shape {x.shape}")
    if len(x) < min_samples:
        raise InputError(what, f"the audio has {len(x)} sample{'s' * (len(x) != 1)}; at least "
                               f"{min_samples} are needed")
    bad = int(np.count_nonzero(~np.isfinite(x)))
    if bad:
        raise InputError(what, f"the audio has {bad} sample{'s' * (bad != 1)} that "
                               f"{'is' if bad == 1 else 'are'} not a finite number (NaN or inf)")
    return x


def formant_map(f_hz: np.ndarray, spec: VoiceSpec, nyquist: float) -> np.ndarray:
    """The nonuniform frequency map of ``spec``: ``k(f) f`` up to ``spec.top_hz``, then linear to
    ``(nyquist, nyquist)`` (Fant 1966's frequency-dependent female/male scale factors).

    >>> spec = VoiceSpec(((500.0, 1.1), (1500.0, 1.2)), top_hz=5000.0)
    >>> np.round(formant_map(np.array([250.0, 500.0, 1000.0, 2000.0, 8000.0]), spec, 8000.0), 1).tolist()
    [275.0, 550.0, 1150.0, 2400.0, 8000.0]
    """
    f = np.asarray(f_hz, dtype=np.float64)
    anchors = np.array(spec.formant_factors, dtype=np.float64)

    def scaled(v: np.ndarray) -> np.ndarray:
        return np.interp(v, anchors[:, 0], anchors[:, 1]) * v

    top = min(spec.top_hz, 0.9 * nyquist)
    top_to = float(scaled(np.array(top)))
    if top_to >= nyquist:
        raise ValueError(f"the map takes {top:g} Hz to {top_to:g} Hz, above the Nyquist frequency")
    upper = top_to + (nyquist - top_to) * (f - top) / (nyquist - top)
    return np.where(f <= top, scaled(f), upper)


def warp_poles(a: np.ndarray, warp, rate: float) -> np.ndarray:
    """The LPC polynomials ``a`` (``(..., P+1)``, ``a[..., 0] = 1``) with each complex pole's
    frequency moved by ``warp`` (Hz -> Hz) and its radius (bandwidth) kept; real poles unchanged.
    Radii are kept, so a stable filter stays stable.

    >>> a = np.poly([0.9 * np.exp(1j * np.pi / 4), 0.9 * np.exp(-1j * np.pi / 4)]).real
    >>> b = warp_poles(a, lambda f: 1.5 * f, 8000.0)
    >>> np.round(np.angle(np.roots(b)) / np.pi, 4).tolist(), np.round(np.abs(np.roots(b)), 4).tolist()
    ([0.375, -0.375], [0.9, 0.9])
    """
    a = np.asarray(a, dtype=np.float64)
    out = np.empty_like(a)
    flat_in, flat_out = a.reshape(-1, a.shape[-1]), out.reshape(-1, a.shape[-1])
    for i, poly in enumerate(flat_in):
        roots = np.roots(poly)
        cplx = np.abs(roots.imag) > 1e-9
        theta = np.abs(np.angle(roots[cplx]))
        moved = np.asarray(warp(theta * rate / (2 * np.pi))) * 2 * np.pi / rate
        moved = np.clip(moved, 1e-4, np.pi - 1e-4)
        roots[cplx] = np.abs(roots[cplx]) * np.exp(1j * np.sign(roots[cplx].imag) * moved)
        flat_out[i] = np.poly(roots).real if len(roots) else poly
    return out


def frame_lpc(x: np.ndarray, rate: float, order: int, hop: int, window: int) -> np.ndarray:
    """LPC polynomials ``(K, order + 1)`` of Hann-windowed frames centred every ``hop`` samples
    (frame k at sample ``k hop``; zero outside the signal), by :func:`facetraj_engine.method.lsf.lpc`."""
    n_frames = len(x) // hop + 1
    pad = np.concatenate([np.zeros(window // 2), x, np.zeros(window)])
    idx = np.arange(n_frames)[:, None] * hop + np.arange(window)[None, :]
    return lpc(pad[idx] * np.hanning(window + 2)[1:-1], order)


def inverse_filter(x: np.ndarray, a: np.ndarray, hop: int) -> np.ndarray:
    """The residual ``e[n] = sum_j a_k[j] x[n - j]``, with ``a_k`` the polynomial of the frame
    nearest to sample n (the FIR filter switched every ``hop`` samples).

    >>> inverse_filter(np.array([1.0, 2.0, 3.0]), np.array([[1.0, -1.0]]), 10).tolist()
    [1.0, 1.0, 1.0]
    """
    order = a.shape[1] - 1
    k = np.minimum((np.arange(len(x)) + hop // 2) // hop, len(a) - 1)
    pad = np.concatenate([np.zeros(order), x])
    lagged = np.stack([pad[order - j: order - j + len(x)] for j in range(order + 1)], axis=1)
    return np.einsum("nj,nj->n", lagged, a[k])


def all_pole_filter(e: np.ndarray, a: np.ndarray, hop: int) -> np.ndarray:
    """``y[n] = e[n] - sum_{j>=1} a_k[j] y[n - j]``: the all-pole filters ``1 / A_k(z)`` switched
    every ``hop`` samples as :func:`inverse_filter` switches them, the output history carried
    across switches (``scipy.signal.lfiltic``). With the same ``a`` it undoes :func:`inverse_filter`.

    >>> x = np.sin(np.arange(50.0))
    >>> a = np.array([[1.0, -0.5], [1.0, 0.3], [1.0, -0.1]])
    >>> bool(np.allclose(all_pole_filter(inverse_filter(x, a, 20), a, 20), x))
    True
    """
    from scipy.signal import lfilter, lfiltic

    order = a.shape[1] - 1
    y = np.zeros(len(e))
    for k in range(len(a)):
        lo, hi = max(0, k * hop - hop // 2), min(len(e), k * hop + (hop + 1) // 2)
        if k == len(a) - 1:
            hi = len(e)
        if hi <= lo:
            continue
        past = y[max(0, lo - order):lo][::-1]
        zi = lfiltic([1.0], a[k], past) if order else np.zeros(0)
        y[lo:hi], _ = lfilter([1.0], a[k], e[lo:hi], zi=zi)
    return y


def wsola(x: np.ndarray, n_out: int, window: int = 320, tolerance: int = 80) -> np.ndarray:
    """``x`` time-stretched to ``n_out`` samples by WSOLA (Verhelst & Roelands 1993): Hann
    windows every ``window / 2`` output samples, each taken near its nominal input position,
    shifted by up to ``tolerance`` samples to best continue the previous one (cross-correlation),
    and overlap-added. The local spectrum (pitch and envelope) is kept; the duration changes.

    >>> t = np.arange(8000) / 8000.0
    >>> y = wsola(np.sin(2 * np.pi * 200 * t), 12000, window=160, tolerance=40)
    >>> len(y), round(float(np.abs(np.fft.rfft(y[2000:10000])).argmax() * 8000 / 8000), 0)
    (12000, 200.0)
    """
    x = np.asarray(x, dtype=np.float64)
    hop = window // 2
    win = np.hanning(window + 1)[:-1]                       # periodic: sums to 1 at hop w/2
    n_frames = int(np.ceil(n_out / hop)) + 1
    rate = len(x) / max(n_out, 1)
    pad = np.concatenate([np.zeros(window + tolerance), x, np.zeros(2 * window + 2 * tolerance)])
    off = window + tolerance                                   # x[i] is pad[i + off]
    y = np.zeros(n_frames * hop + window)
    prev = None
    for k in range(n_frames):
        nominal = int(round(k * hop * rate)) - hop + off
        if prev is None:
            start = nominal
        else:
            target = pad[prev + hop: prev + hop + window]
            region = pad[nominal - tolerance: nominal + tolerance + window]
            c = np.correlate(region, target, mode="valid")
            start = nominal - tolerance + int(np.argmax(c)) if np.any(target) else nominal
        y[k * hop: k * hop + window] += win * pad[start: start + window]
        prev = start
    return y[hop: hop + n_out]


def shift_pitch(x: np.ndarray, factor: float, window: int = 320, tolerance: int = 80) -> np.ndarray:
    """``x`` with every frequency times ``factor`` (resampling) and then its own length again
    (:func:`wsola`): the pitch of an excitation raised by ``factor``, its timing kept."""
    if factor == 1.0:
        return np.asarray(x, dtype=np.float64).copy()
    from scipy.signal import resample_poly

    ratio = Fraction(factor).limit_denominator(100)
    faster = resample_poly(x, ratio.denominator, ratio.numerator)
    return wsola(faster, len(x), window, tolerance)


def short_time_rms(x: np.ndarray, hop: int, window: int) -> np.ndarray:
    """RMS of Hann-windowed frames centred every ``hop`` samples (as :func:`frame_lpc`)."""
    n_frames = len(x) // hop + 1
    pad = np.concatenate([np.zeros(window // 2), x, np.zeros(window)])
    idx = np.arange(n_frames)[:, None] * hop + np.arange(window)[None, :]
    w = np.hanning(window + 2)[1:-1]
    return np.sqrt(np.sum((pad[idx] * w) ** 2, axis=1) / np.sum(w ** 2))


def match_level(y: np.ndarray, x: np.ndarray, hop: int, window: int) -> np.ndarray:
    """``y`` scaled, smoothly over time, to the short-time RMS of ``x`` (where ``x`` is silent,
    so is the result).

    >>> x = np.r_[np.zeros(400), np.ones(400)]
    >>> out = match_level(3.0 * x, x, 80, 160)
    >>> float(np.abs(out[:300]).max()), round(float(out[600]), 3)
    (0.0, 1.0)
    """
    rx, ry = short_time_rms(x, hop, window), short_time_rms(y, hop, window)
    gain = np.where(ry > 1e-12, rx / np.maximum(ry, 1e-12), 0.0)
    centres = np.arange(len(gain)) * hop
    return y * np.interp(np.arange(len(y)), centres, gain)


def second_voice(audio: np.ndarray, rate: int, spec: VoiceSpec | None = None,
                 order: int | None = None, preemphasis: float = 0.97) -> np.ndarray:
    """The voice of ``spec`` (default: :class:`VoiceSpec`, female-like) speaking ``audio``: same
    length and timing, formants moved by :func:`formant_map`, pitch times ``spec.f0_factor``,
    the original short-time level (module docstring).

    ``order`` is the LPC order (default ``2 + rate / 1000``); the analysis is of the signal
    pre-emphasised by ``preemphasis`` (undone at the end).
    """
    from scipy.signal import lfilter

    spec = spec or VoiceSpec()
    x = check_audio(audio)
    if rate <= 0:
        raise InputError("audio", f"the sample rate must be positive, got {rate}")
    order = order or int(round(2 + rate / 1000))
    hop, window = max(1, int(round(HOP_S * rate))), max(2, int(round(WINDOW_S * rate)))
    pre = lfilter([1.0, -preemphasis], [1.0], x)
    a = frame_lpc(pre, rate, order, hop, window)
    residual = inverse_filter(pre, a, hop)
    wsola_window = int(round(0.02 * rate))
    excitation = shift_pitch(residual, spec.f0_factor, wsola_window, wsola_window // 4)
    moved = warp_poles(a, lambda f: formant_map(f, spec, rate / 2.0), rate)
    y = lfilter([1.0], [1.0, -preemphasis], all_pole_filter(excitation, moved, hop))
    return match_level(y, x, hop, window)


# --------------------------------------------------------------------------- checking a voice
def formant_tracks(audio: np.ndarray, rate: int, n: int = 3, order: int | None = None,
                   max_bandwidth: float = 400.0) -> np.ndarray:
    """The lowest ``n`` formants (Hz) every 10 ms, ``(T, n)``, NaN where fewer were found: LPC pole
    frequencies above 90 Hz with a bandwidth below ``max_bandwidth`` (Markel & Gray ch. 7)."""
    from scipy.signal import lfilter

    x = check_audio(audio)
    order = order or int(round(2 + rate / 1000))
    hop, window = int(round(0.01 * rate)), int(round(0.03 * rate))
    a = frame_lpc(lfilter([1.0, -0.97], [1.0], x), rate, order, hop, window)
    out = np.full((len(a), n), np.nan)
    for k, poly in enumerate(a):
        r = np.roots(poly)
        r = r[r.imag > 0]
        f = np.angle(r) * rate / (2 * np.pi)
        bw = -np.log(np.maximum(np.abs(r), 1e-12)) * rate / np.pi
        f = np.sort(f[(f > 90.0) & (f < rate / 2 - 90.0) & (bw < max_bandwidth)])[:n]
        out[k, :len(f)] = f
    return out


def f0_track(audio: np.ndarray, rate: int, fmin: float = 60.0, fmax: float = 500.0,
             threshold: float = 0.5) -> np.ndarray:
    """F0 (Hz) every 10 ms by the normalised autocorrelation peak of 40 ms frames (NaN where the
    peak is below ``threshold``: unvoiced or silent).

    >>> t = np.arange(8000) / 16000.0
    >>> pulses = (np.arange(8000) % 128 == 0).astype(float)       # 125 Hz
    >>> float(np.nanmedian(f0_track(pulses, 16000)))
    125.0
    """
    x = check_audio(audio)
    hop, window = int(round(0.01 * rate)), int(round(0.04 * rate))
    lo, hi = int(rate / fmax), int(np.ceil(rate / fmin))
    n_frames = max(0, (len(x) - window) // hop + 1)
    out = np.full(n_frames, np.nan)
    for k in range(n_frames):
        f = x[k * hop: k * hop + window]
        f = f - f.mean()
        r = np.correlate(f, f, mode="full")[window - 1:]
        if r[0] <= 0 or hi >= window:
            continue
        r = r / r[0]
        lag = lo + int(np.argmax(r[lo:hi]))
        if r[lag] >= threshold:
            out[k] = rate / lag
    return out


def voice_ratios(original: np.ndarray, voiced: np.ndarray, rate: int) -> dict[str, float]:
    """Median over frames of the second voice's F1, F2, F3 and F0 over the original's (frames
    where both have a value), with the peak level and whether the lengths match."""
    fa, fb = formant_tracks(original, rate), formant_tracks(voiced, rate)
    out: dict[str, float] = {}
    for i in range(fa.shape[1]):
        ok = np.isfinite(fa[:, i]) & np.isfinite(fb[:, i])
        out[f"F{i + 1}"] = float(np.median(fb[ok, i] / fa[ok, i])) if ok.any() else float("nan")
    pa, pb = f0_track(original, rate), f0_track(voiced, rate)
    ok = np.isfinite(pa) & np.isfinite(pb)
    out["F0"] = float(np.median(pb[ok] / pa[ok])) if ok.any() else float("nan")
    out["peak"] = float(np.abs(voiced).max())
    out["same_length"] = float(len(voiced) == len(original))
    return out


def median_ratios(rows: Sequence[dict[str, float]]) -> dict[str, float]:
    """The median of each ratio over utterances."""
    keys = rows[0].keys() if rows else ()
    return {k: float(np.nanmedian([r[k] for r in rows])) for k in keys}
