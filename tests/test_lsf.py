"""LSF (paper 2.1): LPC by Levinson-Durbin and LSF from the sum/difference polynomials, checked
against independent implementations (spectrum's poly2lsf, scipy's Toeplitz solver)."""

import numpy as np
import pytest
from scipy.linalg import solve_toeplitz
from scipy.signal import lfilter

from facetraj_engine.method.lsf import analysis_frames, levinson, lpc, lsf2poly, lsf_at, poly2lsf


def _stable_poly(rng, order):
    """A random minimum-phase LPC polynomial from random poles inside the unit circle."""
    poles = []
    for _ in range(order // 2):
        r, th = rng.uniform(0.5, 0.97), rng.uniform(0.05, np.pi - 0.05)
        poles += [r * np.exp(1j * th), r * np.exp(-1j * th)]
    if order % 2:
        poles.append(rng.uniform(-0.9, 0.9))
    return np.real(np.poly(poles))


@pytest.mark.parametrize("order", [2, 9, 10, 18])
def test_poly2lsf_matches_spectrum(order):
    spectrum = pytest.importorskip("spectrum", reason="the test extra provides spectrum")
    rng = np.random.default_rng(order)
    for _ in range(20):
        a = _stable_poly(rng, order)
        ours = poly2lsf(a)
        theirs = np.sort(np.asarray(spectrum.poly2lsf(a)))
        np.testing.assert_allclose(ours, theirs, atol=1e-6)


def test_poly2lsf_batched_equals_single():
    rng = np.random.default_rng(3)
    polys = np.stack([_stable_poly(rng, 18) for _ in range(7)])
    batch = poly2lsf(polys)
    for a, row in zip(polys, batch, strict=True):
        np.testing.assert_allclose(poly2lsf(a), row, atol=1e-12)


def test_lsf_properties_and_round_trip():
    rng = np.random.default_rng(4)
    a = _stable_poly(rng, 18)
    w = poly2lsf(a)
    assert np.all(np.diff(w) > 0) and w[0] > 0 and w[-1] < np.pi
    np.testing.assert_allclose(lsf2poly(w), a, atol=1e-9)


def test_flat_spectrum_gives_uniform_lsf():
    # A(z) = 1: P and Q roots are the (P+1)-th roots of -1 and 1 -> LSF k*pi/(P+1)
    w = poly2lsf(np.r_[1.0, np.zeros(18)])
    np.testing.assert_allclose(w, np.arange(1, 19) * np.pi / 19, atol=1e-9)


def test_levinson_matches_toeplitz_solve():
    rng = np.random.default_rng(5)
    x = lfilter([1], [1, -1.2, 0.7], rng.standard_normal(4000))
    r = np.array([x[: len(x) - k] @ x[k:] for k in range(19)])
    a, err = levinson(r, 18)
    np.testing.assert_allclose(a[1:], -solve_toeplitz(r[:18], r[1:19]), atol=1e-10)
    assert err == pytest.approx(r[0] + a[1:] @ r[1:19])


def test_lpc_recovers_ar2_process():
    rng = np.random.default_rng(6)
    x = lfilter([1], [1, -1.2, 0.7], rng.standard_normal(40000))
    a = lpc(x[None, :] * np.hamming(len(x)), 2)[0]
    np.testing.assert_allclose(a, [1, -1.2, 0.7], atol=0.02)


def test_lsf_pair_brackets_a_resonance():
    # one sharp resonance at 1000 Hz: the closest LSF pair sits near 2 pi 1000 / 16000 rad
    # (within the bias of a 25 ms Hamming-window LPC estimate, ~0.03 rad = 76 Hz)
    rate, f = 16000, 1000.0
    r = 0.99
    x = lfilter([1], [1, -2 * r * np.cos(2 * np.pi * f / rate), r * r],
                np.random.default_rng(7).standard_normal(rate))
    w = lsf_at(x, rate, np.array([0.5]), order=4, preemphasis=0.0)[0]
    target = 2 * np.pi * f / rate
    gaps = np.diff(w)
    k = int(np.argmin(gaps))
    assert abs((w[k] + w[k + 1]) / 2 - target) < 0.03
    assert gaps[k] < 0.1


def test_frames_are_centred_on_times():
    x = np.zeros(1000)
    x[500] = 1.0
    fr = analysis_frames(x, 1000, np.array([0.5]), window_s=0.011)  # 11 samples, centre index 5
    assert np.argmax(fr[0]) == 5


def test_resampling_to_16k():
    rng = np.random.default_rng(8)
    x = rng.standard_normal(44100)
    w44 = lsf_at(x, 44100, np.array([0.3, 0.6]))
    assert w44.shape == (2, 18) and np.all(np.isfinite(w44))


def _cheb_rows(a):
    """The Chebyshev rows poly2lsf solves (P and Q with the trivial roots divided out)."""
    from facetraj_engine.method.lsf import _sum_difference, lsf_chebyshev_series

    _, _, p_rows, q_rows = _sum_difference(a)
    return np.concatenate(lsf_chebyshev_series(p_rows, q_rows))


def test_fast_root_kernel_equals_colleague_eigenvalues():
    """The grid + Newton kernel against its reference, the colleague-matrix eigenvalues, on
    random minimum-phase polynomials and on LPC of real-like frames (AR(2) noise)."""
    from facetraj_engine.method.lsf import chebyshev_real_roots, colleague_eigenvalues

    rng = np.random.default_rng(11)
    polys = [_stable_poly(rng, 18) for _ in range(300)]
    x = lfilter([1], [1, -1.2, 0.7], rng.standard_normal(40 * 400)).reshape(40, 400)
    polys += list(lpc(x * np.hamming(400), 18))
    c = _cheb_rows(np.array(polys))
    fast = chebyshev_real_roots(c)
    ref = -np.sort(-colleague_eigenvalues(c).real, axis=1)
    np.testing.assert_allclose(fast, ref, atol=1e-12)


def test_close_lsf_pairs_fall_back_to_the_reference(monkeypatch):
    """A P root pair closer than a grid cell (pi/128) is not bracketed: the row is solved by the
    eigenvalues, so the LSFs still come back right; a row of well-separated LSFs does not."""
    from facetraj_engine.method import lsf as lsf_mod

    w = np.linspace(0.1, 3.0, 18)
    close = w.copy()
    close[2] = close[0] + 0.004            # LSFs 0 and 2 (both P roots) inside one grid cell
    close[1] = close[0] + 0.002
    calls = []
    real = lsf_mod.colleague_eigenvalues

    def spy(c):
        calls.append(len(c))
        return real(c)

    monkeypatch.setattr(lsf_mod, "colleague_eigenvalues", spy)
    np.testing.assert_allclose(poly2lsf(lsf2poly(w)), w, atol=1e-9)
    assert calls == []
    np.testing.assert_allclose(poly2lsf(lsf2poly(close)), close, atol=1e-7)
    assert calls == [1]


def test_autocorrelation_equals_the_direct_sums():
    from facetraj_engine.method.lsf import autocorrelation

    x = np.random.default_rng(12).standard_normal((5, 400))
    direct = np.array([[row[: 400 - k] @ row[k:] for k in range(19)] for row in x])
    np.testing.assert_allclose(autocorrelation(x, 19), direct, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("kernels", ["compiled", "numpy"])
@pytest.mark.parametrize(("peak", "rate"), [(0.3, 16000), (1e-3, 16000), (1e-170, 16000), (0.7, 16000),
                                            (40.0, 16000), (1e200, 16000), (0.3, 8000),
                                            (40.0, 22050)])
def test_the_peak_scaling_equals_scaling_the_signal_first(peak, rate, kernels):
    """``lsf_at`` brings the peak to [0.5, 1) by a power of 2; scaling up after the pre-emphasis
    (without a copy of the signal) gives the LSFs of the signal scaled first, to the bit, and huge
    samples do not overflow."""
    from facetraj_engine.method.kernels import use_kernels
    from facetraj_engine.method.lsf import resample_audio

    rng = np.random.default_rng(3)
    x = lfilter([1.0], [1.0, -1.6, 0.8], rng.standard_normal(rate // 2))
    x *= peak / np.abs(x).max()
    scaled = resample_audio(np.ldexp(x, -int(np.frexp(np.abs(x).max())[1])), rate, 16000)
    times = np.arange(1, 29) / 60
    with use_kernels(kernels):
        got = lsf_at(x, rate, times, order=18)
        first = lsf_at(scaled, 16000, times, order=18)
    assert np.isfinite(got).all()
    assert np.array_equal(got, first)
