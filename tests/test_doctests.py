"""The examples in the docstrings run: every module of facetraj_engine, facetraj and facetraj_app
that has one, imported by its installed name (not by its path: the folders' names are not the
import names, and importing a module twice under two names would hide a stale import)."""

from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = {"engine": "facetraj_engine", "facetraj": "facetraj", "app": "facetraj_app"}
OPTIONAL = ("facetraj_engine.corpusgen",)        # the corpus extra's libraries


def modules_with_examples() -> list[str]:
    names = []
    for folder, package in FOLDERS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            if ">>>" not in path.read_text(encoding="utf-8"):
                continue
            parts = [package, *path.relative_to(ROOT / folder).with_suffix("").parts]
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            names.append(name)
    return names


def test_the_modules_are_found():
    names = modules_with_examples()
    assert {"facetraj_engine.method.synthesis", "facetraj_engine.method.modes",
            "facetraj_engine.method.similarity", "facetraj_app.provenance"} <= set(names)


@pytest.mark.parametrize("name", modules_with_examples())
def test_the_docstring_examples_run(name):
    if name.startswith(OPTIONAL):
        pytest.importorskip("vocaltractlab_cython")
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    tests = [t for t in finder.find(module, name) if t.examples]
    assert tests, f"{name} has '>>>' but no example was found"
    for test in tests:
        runner.run(test)
    results = runner.summarize(verbose=False)
    assert results.failed == 0, f"{results.failed} of {results.attempted} examples failed in {name}"
