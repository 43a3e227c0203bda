"""Shared fixtures: the toy corpus (fast, made on the fly) and the default corpus (data_samples/)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_CORPUS = ROOT / "data_samples"
MOCHA = ROOT.parent / "shared" / "data" / "mocha_fsew0_001"
#: the screens every window is tested on (issue 39): a large desktop and a small laptop
SCREENS = ("1920x1200", "1366x768")
#: set in a test run that has a screen of that size ("WxH"); tests for other sizes skip there
SCREEN_ENV = "FACETRAJ_TEST_SCREEN"


def edited_model_file(src: Path, dst: Path, **arrays) -> Path:
    """A copy of the saved model ``src`` at ``dst`` with some arrays replaced; an array given as
    ``None`` is left out (as in a model file written by an older facetraj)."""
    import numpy as np

    with np.load(src, allow_pickle=False) as z:
        out = {k: z[k] for k in z.files}
    for name, value in arrays.items():
        if value is None:
            out.pop(name)
        else:
            out[name] = value
    np.savez(dst, **out)
    return dst


@pytest.fixture(scope="session", autouse=True)
def _isolated_cache(tmp_path_factory):
    """One private model cache for the whole session, never the user's (a run on a screen of its
    own, started by the ``screen`` fixture, shares its parent's: the model is trained once)."""
    if os.environ.get(SCREEN_ENV) and os.environ.get("FACETRAJ_CACHE_DIR"):
        return
    os.environ["FACETRAJ_CACHE_DIR"] = str(tmp_path_factory.mktemp("cache"))


@pytest.fixture(scope="session")
def _screen_runs():
    from screens import ScreenRuns

    return ScreenRuns()


@pytest.fixture(params=SCREENS)
def screen(request, _screen_runs):
    """The screen size a test is for (each of ``SCREENS``; a test for fewer sizes parametrizes
    ``screen`` indirectly). On a display of that size (a child run) the test runs here; otherwise
    the module's tests for that size run once in a child pytest on a private Xvfb of the size
    (the trained model cache shared), and this test reports its outcome there without running
    its body here (``pytest_pyfunc_call``)."""
    from screens import Screen

    size = request.param
    assert size in SCREENS
    here = os.environ.get(SCREEN_ENV)
    if here == size:
        return Screen(size, local=True)
    if here:
        pytest.skip(f"a test for the {size} screen, in the {here} screen's run")
    if not os.environ.get("DISPLAY"):
        pytest.skip("the screen tests need Xvfb")
    request.getfixturevalue("trained_cache")           # trained here once, read by the child
    outcome, message = _screen_runs.outcome(str(request.node.path), size, request.node.name)
    if outcome == "failed" or outcome == "missing":
        pytest.fail(f"on a {size} screen:\n{message}", pytrace=False)
    if outcome == "skipped":
        pytest.skip(message)
    return Screen(size, local=False)


@pytest.hookimpl(tryfirst=True)
def pytest_pyfunc_call(pyfuncitem):
    """A test whose screen is not this display's ran in its own child (the ``screen`` fixture)."""
    screen = pyfuncitem.funcargs.get("screen")
    if screen is not None and not screen.local:
        return True
    return None


@pytest.fixture(scope="session")
def toy_corpus_dir(tmp_path_factory) -> Path:
    from toycorpus import build_toy_corpus

    return build_toy_corpus(tmp_path_factory.mktemp("toy"))


@pytest.fixture(scope="session")
def toy_corpus(toy_corpus_dir):
    from facetraj_engine.io.corpus import load_corpus

    return load_corpus(toy_corpus_dir)


@pytest.fixture(scope="session")
def toy_model(toy_corpus):
    from facetraj_engine.method.training import train

    return train(toy_corpus)


@pytest.fixture(scope="session")
def fuzz_workspace(tmp_path_factory, toy_corpus_dir, toy_model):
    """The fuzz suite's valid inputs (tests/fuzzing.py): three toy utterances and a toy model."""
    from fuzzing import make_workspace

    root = tmp_path_factory.mktemp("fuzz")
    toy_model.save(root / "toy-model.npz")
    return make_workspace(root, toy_corpus_dir, root / "toy-model.npz")


@pytest.fixture(scope="session")
def default_corpus():
    from facetraj_engine.io.corpus import load_corpus

    assert (DEFAULT_CORPUS / "corpus.json").exists(), "the default corpus data_samples/ is missing"
    return load_corpus(DEFAULT_CORPUS)


@pytest.fixture(scope="session")
def default_model(default_corpus):
    """The default model, trained once per session into the (test) cache the app also reads."""
    from facetraj_engine.workflow.model_cache import load_or_train

    return load_or_train(default_corpus)


@pytest.fixture(scope="session")
def trained_cache(default_model) -> Path:
    """The session cache, holding the default model (trained once for every test that needs it)."""
    return Path(os.environ["FACETRAJ_CACHE_DIR"])


def shown_corpus_window(qtbot, path: Path, monkeypatch, timeout_ms: int = 240_000):
    """The app's window on the corpus at ``path`` with its first utterance shown, no error dialog
    on the way (the wait is a hang guard, not a speed limit)."""
    from PyQt6.QtWidgets import QMessageBox

    from facetraj_app.main import build_window

    errors: list[str] = []
    monkeypatch.setattr(QMessageBox, "critical", lambda *a, **k: errors.append(a[2]))
    win = build_window(path, use_audio=False)
    qtbot.addWidget(win)
    win.resize(1400, 900)
    win.show()
    qtbot.waitUntil(lambda: errors or win.settled, timeout=timeout_ms)
    assert not errors, errors
    monkeypatch.undo()
    return win
