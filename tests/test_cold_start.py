"""Cold start (issue #15): what the window's first frame imports and reads, the kernels that
replace scipy's there (spectrogram, smoothing), and the corpus fingerprint known from the files'
stamps. No timings: the cold-start benchmark (benchmarks/startup.py) measures them."""

import json
import os
import pathlib
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from facetraj_engine.errors import InputError
from facetraj_engine.io import hash_memo
from facetraj_engine.io.corpus import load_corpus

ROOT = Path(__file__).resolve().parent.parent

#: modules the first frame does not use (each took from milliseconds to seconds to import)
NOT_IN_FIRST_FRAME = (
    "scipy.signal", "scipy.stats", "scipy.interpolate", "scipy.optimize", "scipy.ndimage",
    "scipy.spatial", "multiprocessing", "concurrent.futures.process",
    # numba: the first frame is synthesized by the prebuilt kernels (no numba), or where they
    # are missing by the numpy reference, numba's kernels loaded in the background afterwards
    # (facetraj_engine.method.kernels)
    "numba", "facetraj_engine.method.compiled_lsf", "facetraj_engine.method.compiled_search",
    "facetraj_engine.method.training", "facetraj_engine.labels.alignment", "facetraj_engine.io.labelling", "facetraj_engine.report",
    # the analysis views' numbers (facetraj_engine.analysis.lips, the lips at closure, is the 3-D view's:
    # under a millisecond to import, its package's __init__ a docstring)
    "facetraj_engine.analysis.similarity", "facetraj_engine.analysis.errors", "facetraj_engine.analysis.metrics",
    "facetraj_engine.analysis.inspector", "facetraj_engine.analysis.pc_modes", "facetraj_engine.analysis.common",
    "facetraj_engine.evaluation.kinematics", "facetraj_engine.evaluation.second_voice",
    "facetraj_app.gallery", "facetraj_app.video", "facetraj_app.report_figures", "facetraj_app.analysis.figures",
    "facetraj_app.analysis.errors_view", "facetraj_app.analysis.metrics_view", "facetraj_app.analysis.pc_modes",
    "facetraj_app.analysis.inspector", "facetraj_app.analysis.similarity_view", "facetraj_app.analysis.kinematics_panels",
)


def _loaded(modules: list[str]) -> list[str]:
    """The modules of NOT_IN_FIRST_FRAME among ``modules`` (names from ``sys.modules``)."""
    return sorted(set(NOT_IN_FIRST_FRAME) & set(modules))


def test_app_window_module_imports_nothing_the_first_frame_does_not_use():
    code = "import json, sys; import facetraj_app.main_window; print(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=ROOT, env={"QT_QPA_PLATFORM": "offscreen", "PATH": ""})
    assert _loaded(json.loads(out.stdout)) == []


FIRST_FRAME = """
import json, os, sys
import facetraj_engine.io.corpus
audio_reads = []
read_audio = facetraj_engine.io.corpus.read_audio
def counted(path, *args, **kwargs):
    audio_reads.append(os.path.basename(str(path)))
    return read_audio(path, *args, **kwargs)
facetraj_engine.io.corpus.read_audio = counted
from facetraj.cli import main
rc = main(["-q", "gui", "data_samples", "--screenshot", sys.argv[1]])
with open(sys.argv[2], "w") as fh:
    json.dump({"rc": rc, "modules": sorted(sys.modules), "audio_reads": audio_reads}, fh)
"""


@pytest.mark.gui
def test_first_frame_imports_and_reads_only_what_it_shows(trained_cache, tmp_path):
    """The whole ``facetraj --screenshot`` path, a second start (the model and the face surface
    cached by the first): none of the modules above, and the audio of one utterance read (the
    one shown), once."""
    report = tmp_path / "report.json"
    env = {**os.environ, "FACETRAJ_CACHE_DIR": str(trained_cache)}
    for _start in range(2):
        proc = subprocess.run([sys.executable, "-c", FIRST_FRAME, str(tmp_path / "shot.png"),
                               str(report)], cwd=ROOT, env=env, capture_output=True, text=True,
                              timeout=300)
        assert proc.returncode == 0, proc.stderr[-2000:]
    got = json.loads(report.read_text())
    assert got["rc"] == 0 and (tmp_path / "shot.png").stat().st_size > 0
    assert _loaded(got["modules"]) == []
    assert len(got["audio_reads"]) == 1, got["audio_reads"]


MATPLOTLIB_QUICKLY = """
import inspect, json, sys
import numpy as np
from facetraj_app.main import matplotlib_without_property_docs
with matplotlib_without_property_docs():
    import matplotlib.artist
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
fig = Figure(figsize=(2, 1), dpi=50)
ax = fig.add_subplot()
line, = ax.plot([0, 1], [0, 1])
line.set(color="red", lw=3)
FigureCanvasAgg(fig).draw()
rgba = np.asarray(fig.canvas.buffer_rgba())
with matplotlib_without_property_docs():       # matplotlib imported: nothing changes
    kwdoc_inside = matplotlib.artist.kwdoc(Line2D)
print(json.dumps({
    "table_in_set_doc": "antialiased" in (Line2D.set.__doc__ or ""),
    "set_signature": "color" in inspect.signature(Line2D.set).parameters,
    "kwdoc": "antialiased" in matplotlib.artist.kwdoc(Line2D),
    "kwdoc_inside": "antialiased" in kwdoc_inside,
    "red": bool(((rgba[..., 0] > 200) & (rgba[..., 1] < 60)).any()),
}))
"""


def test_matplotlib_is_imported_without_its_property_tables_only():
    out = subprocess.run([sys.executable, "-c", MATPLOTLIB_QUICKLY], capture_output=True, text=True,
                         check=True, cwd=ROOT, env={"PATH": "", "MPLBACKEND": "agg"})
    assert json.loads(out.stdout) == {"table_in_set_doc": False, "set_signature": True,
                                      "kwdoc": True, "kwdoc_inside": True, "red": True}


# ---------------------------------------------------------------------- the corpus fingerprint
@pytest.fixture
def corpus_copy(toy_corpus_dir, tmp_path, monkeypatch):
    """A copy of the toy corpus, with its own cache folder (the content-hash memo)."""
    monkeypatch.setenv("FACETRAJ_CACHE_DIR", str(tmp_path / "cache"))
    return Path(shutil.copytree(toy_corpus_dir, tmp_path / "toy"))


@pytest.fixture
def reads(monkeypatch):
    """The names of the files read whole (``Path.read_bytes``, as the fingerprint reads them)."""
    names: list[str] = []
    read_bytes = pathlib.Path.read_bytes

    def counted(self):
        names.append(self.name)
        return read_bytes(self)

    monkeypatch.setattr(pathlib.Path, "read_bytes", counted)
    return names


def test_a_corpus_opened_again_reads_no_data_file_for_its_fingerprint(corpus_copy, reads, monkeypatch):
    monkeypatch.setattr(hash_memo, "RACY_S", -1.0)     # the copy's files are seconds old
    first = load_corpus(corpus_copy).fingerprint()
    assert len(reads) == len([p for p in corpus_copy.iterdir() if p.name != "corpus.json"])
    reads.clear()
    again = load_corpus(corpus_copy)
    assert again.fingerprint() == first and reads == []
    # a changed file is read again, and changes the fingerprint
    txt = next(corpus_copy.glob("*.txt"), None) or next(corpus_copy.glob("*.TextGrid"))
    txt.write_bytes(txt.read_bytes() + b" ")
    reads.clear()
    changed = load_corpus(corpus_copy).fingerprint()
    assert changed != first and len(reads) > 1
    # files changed within RACY_S seconds are not trusted by their stamps: read every time
    monkeypatch.setattr(hash_memo, "RACY_S", 3600.0)
    txt.write_bytes(txt.read_bytes() + b" ")
    third = load_corpus(corpus_copy).fingerprint()
    reads.clear()
    assert load_corpus(corpus_copy).fingerprint() == third and len(reads) > 1


def test_an_unreadable_memo_costs_only_the_recomputation(corpus_copy, reads, monkeypatch):
    monkeypatch.setattr(hash_memo, "RACY_S", -1.0)
    first = load_corpus(corpus_copy).fingerprint()
    memo = Path(os.environ["FACETRAJ_CACHE_DIR"]) / hash_memo.MEMO_NAME
    for garbage in (b"{not json", b"[1, 2]", b'{"folder:x": 3}', b"\xff\xfe"):
        memo.write_bytes(garbage)
        reads.clear()
        assert load_corpus(corpus_copy).fingerprint() == first and reads
    reads.clear()
    assert load_corpus(corpus_copy).fingerprint() == first and reads == []   # remembered again


def test_an_utterance_is_read_and_checked_when_it_is_used(corpus_copy, monkeypatch):
    """Opening a corpus reads its description only; a broken utterance is found (with its file
    named) when it is loaded, and the others still load."""
    import facetraj_engine.io.corpus

    corpus = load_corpus(corpus_copy)
    bad, good = corpus.info.test[0], corpus.info.test[1]
    (corpus_copy / f"{bad}.c3d").write_bytes(b"not a c3d file")
    audio: list[str] = []
    read_audio = facetraj_engine.io.corpus.read_audio
    monkeypatch.setattr(facetraj_engine.io.corpus, "read_audio",
                        lambda path, *a, **k: audio.append(Path(path).stem) or read_audio(path, *a, **k))
    corpus = load_corpus(corpus_copy)
    assert audio == []
    with pytest.raises(InputError, match=f"{bad}.c3d"):
        corpus.utterance(bad)
    assert corpus.utterance(good).name == good
    assert audio == [bad, good]


# ---------------------------------------------------------------------- numpy kernels
@pytest.mark.parametrize(("n", "rate", "offset"), [(16000, 16000, 0.3), (44107, 22050, -1.0),
                                                   (1000, 8000, 0.0)])
def test_spectrogram_equals_scipy(n, rate, offset):
    from scipy.signal import spectrogram as scipy_spectrogram

    from facetraj_app.timeline import spectrogram

    x = np.random.default_rng(n).standard_normal(n) + offset
    nper, hop = max(16, int(0.006 * rate)), max(1, int(0.002 * rate))
    ref = scipy_spectrogram(x, rate, window="hamming", nperseg=nper, noverlap=nper - hop,
                            nfft=256, mode="psd")
    got = spectrogram(x, rate, nper, hop, 256)
    for r, g in zip(ref, got, strict=True):
        assert g.shape == r.shape
        np.testing.assert_allclose(g, r, rtol=1e-12, atol=1e-12 * float(np.abs(r).max()))


@pytest.mark.parametrize("n", [1, 2, 3, 7, 60, 500])
@pytest.mark.parametrize("window", [[1.0], [0.25, 0.5, 0.25], list(np.ones(7) / 7),
                                    list(np.arange(1, 32) / 256.0)])
def test_convolve_nearest_equals_scipy(n, window):
    from scipy.ndimage import convolve1d

    from facetraj_engine.method.smoothing import convolve_nearest

    w = np.array(window)
    w = (w + w[::-1]) / 2                                    # symmetric, as the smoothings use
    x = np.random.default_rng(n).standard_normal((n, 4, 3)) * 10
    np.testing.assert_allclose(convolve_nearest(x, w), convolve1d(x, w, axis=0, mode="nearest"),
                               rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("n_knots", [2, 3, 4, 5, 9, 200])
@pytest.mark.parametrize("spacing", ["even", "uneven"])
def test_not_a_knot_spline_equals_scipy(n_knots, spacing):
    from scipy.interpolate import CubicSpline

    from facetraj_engine.method.smoothing import not_a_knot_spline

    rng = np.random.default_rng(n_knots)
    knots = (np.arange(n_knots) * 6.0 if spacing == "even"
             else np.cumsum(rng.uniform(0.5, 9.0, n_knots)))
    if spacing == "even" and n_knots > 2:
        knots[-1] -= 4.0                                     # a short last interval, as at the end
    values = rng.standard_normal((n_knots, 5)) * 20
    at = np.linspace(knots[0], knots[-1], 7 * n_knots)
    ref = CubicSpline(knots, values, axis=0, bc_type="not-a-knot")(at)
    np.testing.assert_allclose(not_a_knot_spline(knots, values, at), ref, rtol=1e-10,
                               atol=1e-10 * float(np.abs(ref).max()))


def test_spline_smooth_unchanged():
    """The spline smoothing as it was computed with scipy (knots every 100 ms, local means)."""
    from scipy.interpolate import CubicSpline
    from scipy.ndimage import convolve1d

    from facetraj_engine.method.smoothing import spline_smooth

    x = np.cumsum(np.random.default_rng(5).standard_normal((203, 6)), axis=0)
    knots = np.append(np.arange(0, 203, 6), 202)
    local = convolve1d(x, np.ones(7) / 7, axis=0, mode="nearest")
    ref = CubicSpline(knots, local[knots], axis=0, bc_type="not-a-knot")(np.arange(203))
    np.testing.assert_allclose(spline_smooth(x, 60.0, 0.1), ref, rtol=1e-10, atol=1e-10)
