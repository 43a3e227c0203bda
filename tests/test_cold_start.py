"""Cold start (issue #15): what the window's first frame imports, and the spectrogram kernel that
replaces scipy.signal's there."""

import subprocess
import sys

import numpy as np
import pytest


def test_app_window_module_does_not_import_scipy_signal():
    """scipy.signal (1-2 s to import) is imported only where a function needs it."""
    code = ("import sys; import app.main_window; "
            "print(sorted(m for m in sys.modules if m.startswith(('scipy.signal', 'scipy.stats'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={"QT_QPA_PLATFORM": "offscreen", "PATH": ""})
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize(("n", "rate", "offset"), [(16000, 16000, 0.3), (44107, 22050, -1.0),
                                                   (1000, 8000, 0.0)])
def test_spectrogram_equals_scipy(n, rate, offset):
    from scipy.signal import spectrogram as scipy_spectrogram

    from app.timeline import spectrogram

    x = np.random.default_rng(n).standard_normal(n) + offset
    nper, hop = max(16, int(0.006 * rate)), max(1, int(0.002 * rate))
    ref = scipy_spectrogram(x, rate, window="hamming", nperseg=nper, noverlap=nper - hop,
                            nfft=256, mode="psd")
    got = spectrogram(x, rate, nper, hop, 256)
    for r, g in zip(ref, got, strict=True):
        assert g.shape == r.shape
        np.testing.assert_allclose(g, r, rtol=1e-12, atol=1e-12 * float(np.abs(r).max()))
