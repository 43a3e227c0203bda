"""A signal's gain kept out of what facetraj computes (issue 38): energy, LSFs, the speech/silence
decision and the labels are the same for any representable gain, so a float WAV scaled by 1e200
gives the same output file as the same audio unscaled; and no numpy warning reaches the user (the
command line run with warnings as errors)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from facetraj_engine.labels.alignment import pcm16
from facetraj_engine.level import peak_scaling, to_full_scale
from facetraj_engine.method.lsf import lsf_at
from facetraj_engine.method.speech import pauses, short_time_energy_db, speech_mask

ROOT = Path(__file__).resolve().parent.parent
CLIP = ROOT / "data_samples" / "s002.flac"          # "The boy enjoyed the noisy toy."
GAINS = (1e200, 1e-200, 3.7, 1e-5)


@pytest.fixture(scope="module")
def clip():
    return sf.read(CLIP)


@pytest.mark.parametrize("gain", GAINS)
def test_energy_lsf_and_speech_do_not_depend_on_the_gain(clip, gain):
    x, rate = clip
    y = x * gain
    e, _ = short_time_energy_db(x, rate)
    np.testing.assert_allclose(short_time_energy_db(y, rate)[0], e, atol=1e-9)
    times = np.arange(int(len(x) / rate * 60) + 1) / 60
    assert np.array_equal(speech_mask(y, rate, times), speech_mask(x, rate, times))
    np.testing.assert_allclose(pauses(y, rate, times), pauses(x, rate, times))
    np.testing.assert_allclose(lsf_at(y, rate, times), lsf_at(x, rate, times), atol=1e-12)
    assert np.array_equal(pcm16(y), pcm16(x))           # what PocketSphinx hears
    np.testing.assert_allclose(to_full_scale(y), to_full_scale(x), rtol=1e-15)


def test_peak_scaling_never_overflows():
    for p in (1e308, 5e-324, 1.0, 0.0, np.inf):
        k, f = peak_scaling(np.array([p, -p / 2]))
        assert np.isfinite(f) and (p in (0.0, np.inf) or np.ldexp(p, k) * f == 1.0)


def _cli(*args, cwd: Path) -> subprocess.CompletedProcess:
    """``facetraj`` in a fresh interpreter with every warning an error (numpy's too)."""
    return subprocess.run([sys.executable, "-W", "error", "-m", "facetraj", *map(str, args)],
                          cwd=cwd, capture_output=True, text=True, timeout=600)


def test_a_wav_scaled_by_1e200_gives_the_same_output_file(default_model, tmp_path):
    model = default_model.save(tmp_path / "model.npz")
    x, rate = sf.read(CLIP)
    for name, gain in (("a", 1.0), ("big", 1e200), ("tiny", 1e-200)):
        sf.write(tmp_path / f"{name}.wav", x * gain, rate, subtype="DOUBLE")
        shutil.copy(CLIP.with_suffix(".txt"), tmp_path / f"{name}.txt")      # aligned labels
        for suffix in ("c3d", "tsv"):
            run = _cli("synth", model, f"{name}.wav", "-o", f"{name}.{suffix}", cwd=tmp_path)
            assert run.returncode == 0, run.stderr
            assert "Warning" not in run.stderr
        run = _cli("synth", model, f"{name}.wav", "-o", f"{name}.acoustic.tsv", "--mode",
                   "acoustic", cwd=tmp_path)           # the closure detector's energy dips too
        assert run.returncode == 0 and "Warning" not in run.stderr, run.stderr
        run = _cli("live", "--model", model, "--from-file", f"{name}.wav", "--as-fast-as-possible",
                   "-o", f"{name}-take.tsv", cwd=tmp_path)
        assert run.returncode == 0, run.stderr
    for suffix in ("c3d", "tsv", "acoustic.tsv"):
        same = (tmp_path / f"a.{suffix}").read_bytes()
        assert (tmp_path / f"big.{suffix}").read_bytes() == same, suffix
        assert (tmp_path / f"tiny.{suffix}").read_bytes() == same, suffix
    takes = [np.loadtxt(tmp_path / f"{n}-take.tsv", skiprows=1) for n in ("a", "big", "tiny")]
    np.testing.assert_allclose(takes[1], takes[0], atol=2e-4)
    np.testing.assert_allclose(takes[2], takes[0], atol=2e-4)
