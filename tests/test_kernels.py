"""The compiled kernels (issue 28: engine/method/compiled_lsf.py, compiled_search.py) against
their numpy references, to rounding: the LSF analysis, eq 4's search, the LSF index's search,
and whole syntheses of a default-corpus utterance in both modes; the switch between them
(engine/method/kernels.py) and that numba stays out of the engine's import."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.method import aot, kernels, prebuilt
from facetraj_engine.method.kernels import kernel_choice, use_kernels
from facetraj_engine.method.lsf import lsf2poly, lsf_at, poly2lsf
from facetraj_engine.method.lsf_index import build_index
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.similarity import context_similarity, top_context_phones, top_contexts

ROOT = Path(__file__).resolve().parent.parent
#: LSFs in radians: the reference polishes each root to a Newton step of 1e-9 (an error of order
#: 1e-18 in cos w); the two autocorrelations (FFT and direct sums) differ by rounding
LSF_ATOL = 1e-10


@pytest.fixture(params=["compiled", "jit"])
def kind(request):
    """The compiled kernels each comparison runs: the prebuilt extension (``make`` builds it:
    ``python -m facetraj_engine.method.aot``) and numba's just-in-time ones (an install without it)."""
    if request.param == "compiled" and kernels.prebuilt() is None:
        pytest.fail("the prebuilt kernels are missing or stale: python -m facetraj_engine.method.aot")
    return request.param


def both(kind, fn, *args, **kwargs):
    """``fn`` run with the numpy reference and with the compiled kernels ``kind``."""
    with use_kernels("numpy"):
        ref = fn(*args, **kwargs)
    with use_kernels(kind):
        fast = fn(*args, **kwargs)
    return ref, fast


def frame_times(audio: np.ndarray, rate: int, marker_rate: float = 60.0) -> np.ndarray:
    return np.arange(int(len(audio) / rate * marker_rate) + 1) / marker_rate


def test_the_compiled_kernels_load_here():
    """Both ways: the prebuilt extension (built by make) and numba's just-in-time kernels."""
    assert kernels.prebuilt() is not None, "python -m facetraj_engine.method.aot builds them"
    assert kernels.warm_up()
    assert kernels.loaded()
    with use_kernels("jit"):
        assert kernels.warm_up() and kernels.loaded()
        assert kernels.compiled("compiled_lsf") is not kernels.prebuilt()
    assert kernels.compiled("compiled_lsf") is kernels.prebuilt()


def test_lsf_analysis_equals_the_reference_on_corpus_speech(default_corpus, kind):
    for utt_id in list(default_corpus.info.test)[:3]:
        utt = default_corpus.utterance(utt_id)
        times = frame_times(utt.audio, utt.sample_rate)
        ref, fast = both(kind, lsf_at, utt.audio, utt.sample_rate, times)
        assert fast.shape == ref.shape and np.isfinite(fast).all()
        np.testing.assert_allclose(fast, ref, rtol=0, atol=LSF_ATOL)


@pytest.mark.parametrize("rate", [16000, 44100])
def test_lsf_analysis_equals_the_reference_on_edge_cases(rate, kind):
    rng = np.random.default_rng(3)
    noise = rng.standard_normal(rate // 2)
    cases = {
        "silence": np.zeros(rate // 2),
        "one frame": noise[: rate // 100],
        "a click in silence": np.r_[np.zeros(rate // 4), 1.0, np.zeros(rate // 4)],
        "a pure tone": np.sin(2 * np.pi * 440 * np.arange(rate // 2) / rate),
        "tiny samples": noise * 1e-300,
        "huge samples": noise * 1e300,
    }
    for name, audio in cases.items():
        times = frame_times(audio, rate)[:1] if name == "one frame" else frame_times(audio, rate)
        ref, fast = both(kind, lsf_at, audio, rate, times)
        assert np.isfinite(fast).all(), name
        np.testing.assert_allclose(fast, ref, rtol=0, atol=LSF_ATOL, err_msg=name)


def test_a_frame_the_grid_cannot_bracket_goes_to_the_reference(kind, monkeypatch):
    """Two LSFs closer than a grid cell (pi/128): the kernel flags the frame, the reference's
    eigenvalues solve it."""
    from facetraj_engine.method import lsf as lsf_module

    lsf = np.linspace(0.2, 2.9, 18)
    lsf[5] = lsf[4] + 0.004
    a = lsf2poly(lsf)
    rng = np.random.default_rng(0)
    calls = []

    def fallback(polys):
        calls.append(len(polys))
        return poly2lsf(polys)

    # a frame whose LPC is a: the signal filtered by 1/A(z), analysed on its own
    from scipy.signal import lfilter

    x = lfilter([1.0], a, rng.standard_normal(4000))
    pad = np.r_[np.zeros(200), x, np.zeros(400)]
    monkeypatch.setattr(lsf_module, "poly2lsf", fallback)
    with use_kernels(kind):
        got = lsf_module.compiled_frame_lsf(kernels.compiled("compiled_lsf"), pad,
                                            np.array([2000]), np.hamming(400), 18)
    with use_kernels("numpy"):
        from facetraj_engine.method.lsf import lpc

        ref = poly2lsf(lpc(pad[2000:2400] * np.hamming(400), 18))
    np.testing.assert_allclose(got, ref[None], rtol=0, atol=LSF_ATOL)
    assert np.isfinite(got).all()
    assert sum(calls) <= 1


def test_eq4_search_equals_the_reference_to_the_bit(default_model, kind):
    m = default_model
    cb = m.codebook
    rng = np.random.default_rng(1)
    query = rng.integers(0, len(m.phones), (300, cb.contexts.shape[1]))
    s = m.similarity(10.0)
    for xi, context, count in ((20.0, 3, 3), (2.0, 1, 5), (20.0, 0, 1)):
        (top0, n0), (top1, n1) = both(kind, top_context_phones, query, cb.contexts, s, xi, context, count)
        np.testing.assert_array_equal(top1, top0)
        np.testing.assert_array_equal(n1, n0)
    # and the full computation it replaces
    full = context_similarity(query[:20], cb.contexts, s, 20.0, 0)
    np.testing.assert_array_equal(top1[:20], top_contexts(full, 1))


def test_eq4_ties_the_lower_index_first(kind):
    s = np.array([[1.0, 0.5], [0.5, 1.0]])
    cb = np.array([[1, 0, 1], [0, 0, 0], [1, 0, 1]])
    (top0, n0), (top1, n1) = both(kind, top_context_phones, np.array([[0, 0, 1]]), cb, s, 10.0, 1, 2)
    assert top1.tolist() == top0.tolist() == [[0, 1]]          # all three score 1.15
    np.testing.assert_array_equal(n1, n0)


def test_lsf_index_search_chooses_the_reference_codewords(default_model, default_corpus, kind):
    m = default_model
    ix, cb = m.lsf_index(), m.codebook.lsf
    utt = default_corpus.utterance(next(iter(default_corpus.info.test)))
    w = m.input_lsf(utt.audio, utt.sample_rate, frame_times(utt.audio, utt.sample_rate))
    for count, probe in ((128, 8), (1, 8), (40, 1), (128, ix.n_cells)):
        ref, fast = both(kind, ix.nearest, w, cb, count, probe)
        assert fast.shape == ref.shape
        np.testing.assert_array_equal(fast, ref, err_msg=f"count {count}, probe {probe}")


def test_lsf_index_search_small_and_exhaustive(kind):
    lsf = np.sort(np.random.default_rng(2).uniform(0.1, 3.0, (500, 6)), axis=1)
    ix = build_index(lsf)
    w = np.sort(np.random.default_rng(5).uniform(0.1, 3.0, (50, 6)), axis=1)
    for count, probe in ((1, 1), (7, 3), (500, 1), (30, ix.n_cells)):
        ref, fast = both(kind, ix.nearest, w, lsf, count, probe)
        np.testing.assert_array_equal(fast, ref)
    ref, fast = both(kind, ix.nearest, w[:0], lsf, 7, 3)
    assert fast.shape == ref.shape == (0, 7)


def test_eqs_5_to_8_equal_the_reference(default_model, default_corpus, kind):
    from facetraj_engine.method.synthesis import gamma_grid, weight_frames

    m = default_model
    cb = m.codebook
    utt = default_corpus.utterance(next(iter(default_corpus.info.test)))
    w = m.input_lsf(utt.audio, utt.sample_rate, frame_times(utt.audio, utt.sample_rate))
    cand = np.random.default_rng(4).integers(0, len(cb.lsf), (len(w), 15))
    for gammas in (gamma_grid(), gamma_grid(0.5, 1.0, 3), np.array([0.2, 0.3, 1.7])):
        ref, fast = both(kind, weight_frames, w, cand, cb.lsf, cb.pcs, gammas)
        np.testing.assert_array_equal(fast.gamma, ref.gamma)
        np.testing.assert_array_equal(fast.candidates, ref.candidates)
        for name in ("pcs", "weights", "lsf_hat", "error"):
            np.testing.assert_allclose(getattr(fast, name), getattr(ref, name), rtol=1e-10,
                                       atol=1e-12, err_msg=name)
    ref, fast = both(kind, weight_frames, w[:1], cand[:1], cb.lsf, cb.pcs, gamma_grid())     # one frame
    np.testing.assert_allclose(fast.pcs, ref.pcs, rtol=1e-10, atol=1e-12)


def test_eqs_5_to_8_where_gammas_tie(toy_model, kind):
    """One codeword dominating: every gamma's error equal to rounding, so the kernel and the
    reference may choose different gammas; the weights and PCs agree to rounding."""
    from facetraj_engine.method.synthesis import gamma_grid, weight_frames

    cb = toy_model.codebook
    rng = np.random.default_rng(1)
    w = cb.lsf[rng.choice(len(cb.lsf), 6)] + 0.01
    cand = rng.choice(len(cb.lsf), (6, 9))
    ref, fast = both(kind, weight_frames, w, cand, cb.lsf, cb.pcs, gamma_grid())
    np.testing.assert_allclose(fast.pcs, ref.pcs, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fast.weights, ref.weights, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fast.error, ref.error, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("mode", ["phonetic", "acoustic"])
def test_synthesized_trajectories_equal_the_reference(default_model, default_corpus, mode, kind):
    utt = default_corpus.utterance(list(default_corpus.info.test)[1])
    ref, fast = both(kind, synthesize, default_model, utt.audio, utt.sample_rate,
                     utt.phones if mode == "phonetic" else None, SynthConfig(mode=mode), voice=True)
    np.testing.assert_array_equal(fast.frames.candidates, ref.frames.candidates)
    np.testing.assert_allclose(fast.lsf, ref.lsf, rtol=0, atol=LSF_ATOL)
    np.testing.assert_allclose(fast.markers, ref.markers, rtol=0, atol=1e-7)    # mm
    np.testing.assert_allclose(fast.pcs, ref.pcs, rtol=0, atol=1e-7)
    assert fast.voice_match == pytest.approx(ref.voice_match, abs=1e-9)


def test_the_choice_by_environment_and_by_context(monkeypatch):
    monkeypatch.setenv(kernels.KERNELS_ENV, "numpy")
    assert kernel_choice() == "numpy" and kernels.compiled("compiled_lsf") is None
    with use_kernels("compiled"):
        assert kernel_choice() == "compiled"
    monkeypatch.setenv(kernels.KERNELS_ENV, "something else")
    assert kernel_choice() == "compiled"
    with pytest.raises(ValueError):
        with use_kernels("fortran"):
            pass


def test_a_kernel_module_that_fails_to_load_falls_back_to_numpy(monkeypatch, caplog):
    """numba's kernels failing to import (no prebuilt ones: ``jit``) give numpy's results."""
    monkeypatch.setattr(kernels, "_loaded", {})
    real = __import__("importlib").import_module

    def broken(name, *args):
        if name.endswith("compiled_lsf"):
            raise ImportError("no numba here")
        return real(name, *args)

    monkeypatch.setattr("importlib.import_module", broken)
    with use_kernels("jit"):
        assert kernels.compiled("compiled_lsf") is None
    assert "using numpy" in caplog.text
    audio = np.random.default_rng(0).standard_normal(8000)
    ref, fast = both("jit", lsf_at, audio, 16000, frame_times(audio, 16000))
    np.testing.assert_array_equal(fast, ref)


def test_numba_is_not_imported_by_the_engine_nor_the_command_line():
    code = ("import json, sys; import facetraj_engine.method.pipeline, facetraj_engine.method.model, facetraj.cli; "
            "print(json.dumps(sorted(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=ROOT)
    assert not [m for m in json.loads(out.stdout) if m.split(".")[0] == "numba"]


def test_a_synthesis_with_the_prebuilt_kernels_imports_no_numba(toy_model, tmp_path):
    """A new process synthesizes with the prebuilt kernels from its first call: numba is never
    imported, and the result equals the reference's."""
    code = """
import sys
import numpy as np
from facetraj_engine.method import kernels
from facetraj_engine.method.model import Model
from facetraj_engine.config import SynthConfig
from facetraj_engine.method.pipeline import synthesize
model = Model.load(sys.argv[1])
audio = np.random.default_rng(1).standard_normal(16000) * 0.1
config = SynthConfig(mode="acoustic")
fast = synthesize(model, audio, 16000, None, config).pcs
print("numba" in sys.modules, kernels.compiled("compiled_lsf") is kernels.prebuilt() is not None)
with kernels.use_kernels("numpy"):
    ref = synthesize(model, audio, 16000, None, config).pcs
print(np.abs(fast - ref).max() < 1e-9)
"""
    toy_model.save(tmp_path / "toy.npz")
    env = {k: v for k, v in os.environ.items() if k != kernels.KERNELS_ENV}
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "toy.npz")],
                         capture_output=True, text=True, cwd=ROOT, timeout=600, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["False", "True", "True"]


def test_prebuilt_kernels_missing_broken_or_stale_give_way_to_numba(monkeypatch, tmp_path, caplog):
    """No extension where it is looked for, a file that is not one, or one built from other
    sources: each is refused (the last two with a warning naming the file), numba's kernels run."""
    monkeypatch.setenv(prebuilt.DIR_ENV, str(tmp_path))
    assert prebuilt.load() is None
    broken = tmp_path / f"{prebuilt.MODULE}{__import__('importlib').machinery.EXTENSION_SUFFIXES[0]}"
    broken.write_bytes(b"\x7fELF not really")
    assert prebuilt.load() is None
    assert "unusable" in caplog.text and str(broken) in caplog.text
    monkeypatch.delenv(prebuilt.DIR_ENV)
    assert prebuilt.load() is not None
    monkeypatch.setattr(prebuilt, "fingerprint", lambda: 12345)
    assert prebuilt.load() is None
    assert "stale" in caplog.text
    assert aot.main(["--check"]) == 1


def test_the_build_runs_only_when_the_fingerprint_says_stale(monkeypatch):
    """``python -m facetraj_engine.method.aot`` (what ``make`` runs every time) builds nothing while the
    extension is current, and builds when it is stale or ``--force`` is given."""
    built = []
    monkeypatch.setattr(aot, "build", lambda: built.append(1) or prebuilt.folder())
    assert aot.main([]) == 0 and built == []
    assert aot.main(["--force"]) == 0 and built == [1]
    monkeypatch.setattr(prebuilt, "fingerprint", lambda: 12345)
    assert aot.main([]) == 0 and built == [1, 1]


def test_a_read_only_install_does_not_crash():
    """Nowhere to keep numba's cache (a read-only install without a user cache folder: numba
    finds no cache locator, here by being told to try only one that never applies): the kernels
    compile without their cache (in every process: seconds) and give the same LSFs."""
    code = """
import numpy as np
from facetraj_engine.method.kernels import use_kernels
from facetraj_engine.method.lsf import lsf_at
x = np.random.default_rng(0).standard_normal(8000)
with use_kernels("jit"):
    fast = lsf_at(x, 16000, np.arange(10) / 60)
with use_kernels("numpy"):
    ref = lsf_at(x, 16000, np.arange(10) / 60)
print(fast.shape, float(np.abs(fast - ref).max()) < 1e-10)
"""
    env = {**os.environ, "NUMBA_CACHE_LOCATOR_CLASSES": "numba.core.caching.IPythonCacheLocator"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                         timeout=600, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "(10, 18) True"
    assert "using numpy" not in out.stderr          # compiled, not the fallback


def test_the_choice_holds_in_the_frame_threads():
    from facetraj_engine.threads import map_spans

    with use_kernels("numpy"):
        assert map_spans(lambda a, b: kernel_choice(), 3000, 2) == ["numpy", "numpy"]
    with use_kernels("compiled"):
        assert map_spans(lambda a, b: kernel_choice(), 3000, 2) == ["compiled", "compiled"]


def test_a_live_stream_never_waits_for_the_kernels_to_load(toy_model, tmp_path):
    """A fresh process streams with numpy's reference (numba not even imported) until the kernels
    are loaded, then with the compiled ones; the frames equal a stream of numpy's throughout."""
    code = """
import sys
import numpy as np
from facetraj_engine.method import aot, kernels, prebuilt
from facetraj_engine.method.model import Model
from facetraj_engine.streaming.synthesizer import StreamingSynthesizer
model = Model.load(sys.argv[1])
audio = np.random.default_rng(1).standard_normal(16000) * 0.1
def stream(between):
    s = StreamingSynthesizer(model)
    first = s.feed(audio[:8000]).pcs
    between()
    return np.concatenate([first, s.feed(audio[8000:]).pcs, s.flush().pcs])
cold = stream(lambda: None)
print("numba" in sys.modules, kernels.loaded())
warmed = stream(kernels.warm_up)
print("numba" in sys.modules, kernels.loaded())
with kernels.use_kernels("numpy"):
    ref = stream(lambda: None)
print(np.abs(cold - ref).max() < 1e-9, np.abs(warmed - ref).max() < 1e-9)
"""
    toy_model.save(tmp_path / "toy.npz")
    env = {k: v for k, v in os.environ.items() if k != kernels.KERNELS_ENV}
    env[prebuilt.DIR_ENV] = str(tmp_path)                    # an install without prebuilt kernels
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "toy.npz")],
                         capture_output=True, text=True, cwd=ROOT, timeout=600, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["False", "False", "True", "True", "True", "True"]


def test_a_fork_waits_for_a_warm_up_under_way_in_another_thread(monkeypatch):
    """The app warms the kernels in a background thread; work forked meanwhile (``fan_out``,
    whose hooks ``prepare_fork`` runs) waits until it is done, whatever this thread's choice, so
    no child inherits numba's locks held mid-compile."""
    import threading

    from facetraj_engine.fanout import prepare_fork
    from facetraj_engine.method import compiled_lsf

    monkeypatch.setenv(kernels.KERNELS_ENV, "jit")      # numba's kernels, compiled when asked
    started, release = threading.Event(), threading.Event()
    order = []
    real = compiled_lsf.warm_up

    def slow_warm_up():                    # the compile of the first kernel, made slow
        started.set()
        release.wait(5)
        real()
        order.append("warm-up done")

    monkeypatch.setattr(compiled_lsf, "warm_up", slow_warm_up)
    t = threading.Thread(target=kernels.warm_up)
    t.start()
    assert started.wait(5)
    threading.Timer(0.2, release.set).start()
    monkeypatch.delenv(kernels.KERNELS_ENV)
    with use_kernels("numpy"):
        prepare_fork()
    order.append("fork")
    t.join()
    assert order == ["warm-up done", "fork"]
