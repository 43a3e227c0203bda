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
    """One private model cache for the whole session, never the user's."""
    os.environ["FACETRAJ_CACHE_DIR"] = str(tmp_path_factory.mktemp("cache"))


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
    from facetraj_app.cache import load_or_train

    return load_or_train(default_corpus)


@pytest.fixture(scope="session")
def trained_cache(default_model) -> Path:
    """The session cache, holding the default model (trained once for every test that needs it)."""
    return Path(os.environ["FACETRAJ_CACHE_DIR"])
