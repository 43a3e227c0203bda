"""The docs that name the code's modules and functions name ones that exist (a renamed or removed
function fails here, not in a reader's hands), and the code's docstrings and comments carry no
benchmark timings (those go stale; they live in docs/benchmarks.md)."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: the docs checked name for name
CHECKED_DOCS = ("architecture.md", "api.md")
#: the import packages, and the folders that hold them
PACKAGES = {"facetraj_engine": "engine", "facetraj_app": "app", "facetraj": "facetraj"}
NAME = re.compile(r"`((?:" + "|".join(PACKAGES) + r")(?:\.[A-Za-z_][A-Za-z0-9_]*)+)(?:\(\))?`")


def resolves(dotted: str) -> bool:
    """Whether ``dotted`` is a module, or an attribute (a class's too) of the longest module
    prefix of it."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            if not hasattr(obj, name):
                return False
            obj = getattr(obj, name)
        return True
    return False


def names_in(doc: Path) -> list[str]:
    return sorted(set(NAME.findall(doc.read_text())))


@pytest.mark.parametrize("doc", CHECKED_DOCS)
def test_every_name_a_doc_gives_exists(doc):
    path = ROOT / "docs" / doc
    if not path.exists():
        pytest.skip(f"docs/{doc} is not written")
    names = names_in(path)
    assert len(names) >= 2, "the pattern finds the doc's names"
    missing = [n for n in names if not resolves(n)]
    assert missing == [], f"docs/{doc} names what the code does not have: {missing}"


def test_the_check_finds_a_stale_name(tmp_path):
    doc = tmp_path / "x.md"
    doc.write_text("`facetraj_engine.method.pipeline.synthesize` and "
                   "`facetraj_engine.method.pipeline.mode_for`")
    assert {n: resolves(n) for n in names_in(doc)} == {"facetraj_engine.method.pipeline.synthesize": True,
                                                       "facetraj_engine.method.pipeline.mode_for": False}


#: what a benchmark timing in prose looks like: "4.4 -> 2.9 ms", "took 5 ms", "156 ms against 4"
TIMING = re.compile(r"(?:->|→)\s*[0-9.]+\s*(?:ms|s)\b|\btook\s+[0-9]|[0-9]\s*ms\s+against\b|"
                    r"\bmeasured\s+[0-9]|[0-9.]+\s*(?:x|times)\s+(?:faster|slower)\b")


def test_no_benchmark_timings_in_the_codes_docstrings_and_comments():
    found = []
    for folder in PACKAGES.values():
        for path in sorted((ROOT / folder).rglob("*.py")):
            for k, line in enumerate(path.read_text().splitlines(), 1):
                if TIMING.search(line):
                    found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert found == [], "timings belong in docs/benchmarks.md:\n" + "\n".join(found)
