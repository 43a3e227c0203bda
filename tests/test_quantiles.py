"""Percentiles and medians without numpy's masked arrays (issue 48): numpy's figures to the bit,
and a synthesis that never imports ``numpy.ma``."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from facetraj.paths import default_corpus
from facetraj_engine.method.quantiles import median, percentiles


@pytest.mark.parametrize("seed", range(300))
def test_numpys_percentiles_and_median_to_the_bit(seed):
    """Odd and even counts from 1, ties, magnitudes from 1e-3 to 1e3, negatives, a NaN, an
    infinity; the speech mask's 5th and 99th percentiles and others from 0 to 100."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 40)) if seed % 3 else int(rng.integers(40, 3000))
    x = rng.normal(0, 10.0 ** rng.integers(-3, 4), n)
    if seed % 4 == 0:
        x = np.round(x)
    if seed % 11 == 0:
        x[rng.integers(0, n)] = np.nan
    if seed % 13 == 0:
        x[rng.integers(0, n)] = np.inf
    q = [5, 99] if seed % 2 else [*rng.uniform(0, 100, 4).tolist(), 0, 50, 100]
    with np.errstate(invalid="ignore"):
        want = np.percentile(x, q)
        got = percentiles(x, q)
    np.testing.assert_array_equal(got, want)
    assert got.dtype == want.dtype and got.shape == want.shape
    assert median(x) == float(np.median(x)) or (np.isnan(median(x)) and np.isnan(np.median(x)))


def test_the_input_is_left_as_it_was():
    x = np.array([3.0, 1.0, 2.0, 5.0])
    percentiles(x, [50])
    median(x)
    assert x.tolist() == [3.0, 1.0, 2.0, 5.0]
    with pytest.raises(ValueError, match="no values"):
        percentiles(np.zeros(0), [50])


def test_a_synthesis_imports_no_masked_arrays(default_model, tmp_path):
    """``facetraj synth`` acoustic-only and phonetic (the voice match, the closure step and its
    detector, the pauses): numpy.ma, which numpy.percentile and numpy.median import on their
    first call, is never imported."""
    model = default_model.save(tmp_path / "model.npz")
    sentence = default_corpus() / "s001.flac"
    code = ("import sys, facetraj.cli\n"
            "for mode in ('acoustic', 'phonetic'):\n"
            "    assert facetraj.cli.main(['-q', 'synth', *sys.argv[1:], '--mode', mode]) == 0\n"
            "print('numpy.ma' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code, str(model), str(sentence), "-o",
                          str(tmp_path / "face.tsv"), "--overwrite"], capture_output=True,
                         text=True, check=True)
    assert out.stdout.split()[-1] == "False"
