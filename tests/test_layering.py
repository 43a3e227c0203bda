"""The layering: the engine's stages import only downward; the engine imports nothing from
``app``, ``facetraj`` or a GUI library; no import circle anywhere; no oversized definition."""

from __future__ import annotations

import pkgutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from structure import Import, circles, definitions, import_graph, mermaid, picture_in

import facetraj_engine

ROOT = Path(__file__).resolve().parent.parent

#: The engine's top-level modules outside every stage: small things every stage uses.
SHARED = {"facetraj_engine.config", "facetraj_engine.data", "facetraj_engine.errors", "facetraj_engine.fanout", "facetraj_engine.progress",
          "facetraj_engine.threads"}

# Run in a fresh interpreter in which every GUI package and the upper layers cannot be imported.
PROBE = """
import importlib, sys
class Block:
    BLOCKED = ("PyQt6", "pyvista", "pyvistaqt", "vtk", "vtkmodules", "matplotlib", "app", "facetraj")
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in self.BLOCKED:
            raise ImportError(f"blocked import of {name}")
        return None
sys.meta_path.insert(0, Block())
failed = []
for name in sys.argv[1:]:
    try:
        importlib.import_module(name)
    except ImportError as exc:
        failed.append(f"{name}: {exc}")
print("\\n".join(failed))
sys.exit(1 if failed else 0)
"""


def engine_modules() -> list[str]:
    names = ["engine"]
    for info in pkgutil.walk_packages(engine.__path__, "engine."):
        if info.name.startswith("facetraj_engine.corpusgen"):     # the corpus extra: optional packages
            continue
        names.append(info.name)
    return names


def stage_level(module: str) -> int:
    """0 for ``engine`` and its shared modules, else 1 + the stage's place in facetraj_engine.STAGES."""
    parts = module.split(".")
    if module == "engine" or module in SHARED:
        return 0
    for level, stage in enumerate(facetraj_engine.STAGES, 1):
        if parts[1] in (stage if isinstance(stage, tuple) else (stage,)):
            return level
    raise AssertionError(f"{module} is in no stage of facetraj_engine.STAGES")


def upward(edges: list[Import]) -> list[str]:
    """Imports from a lower stage to a higher one (and between the top stages)."""
    bad = []
    for e in edges:
        if not (e.importer.startswith("engine") and e.target.startswith("engine")):
            continue
        a, b = stage_level(e.importer), stage_level(e.target)
        top_peers = a == b == len(facetraj_engine.STAGES) and e.importer.split(".")[1] != e.target.split(".")[1]
        if b > a or top_peers:
            bad.append(f"{e.importer} (line {e.line}) imports {e.target}")
    return bad


def test_every_engine_module_imports_without_gui_libraries_or_upper_layers():
    modules = engine_modules()
    assert {"facetraj_engine.method.model", "facetraj_engine.method.training", "facetraj_engine.method.pipeline",
            "facetraj_engine.method.synthesis", "facetraj_engine.evaluation.paper", "facetraj_engine.report.discussion",
            "facetraj_engine.analysis.metrics"} <= set(modules)
    proc = subprocess.run([sys.executable, "-c", PROBE, *modules], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_probe_does_block_a_gui_import():
    proc = subprocess.run([sys.executable, "-c", PROBE, "facetraj_app.main_window"], capture_output=True,
                          text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 1 and "blocked import" in proc.stdout


def test_every_engine_module_sits_in_a_stage_or_is_a_shared_one():
    outside = [m for m in engine_modules() if m.count(".") == 1 and m not in SHARED
               and m.split(".")[1] not in {s for st in facetraj_engine.STAGES
                                          for s in (st if isinstance(st, tuple) else (st,))}]
    assert outside == []
    assert all(stage_level(m) >= 0 for m in engine_modules())


def test_stages_import_only_downward():
    assert upward(import_graph(("engine",))) == []


def test_the_stage_check_catches_an_upward_import():
    fake = [Import("facetraj_engine.method.pipeline", "facetraj_engine.evaluation.scores", 1, True),
            Import("facetraj_engine.labels.alignment", "facetraj_engine.io.files", 2, False),
            Import("facetraj_engine.report.markdown", "facetraj_engine.analysis.metrics", 3, True),
            Import("facetraj_engine.evaluation.scores", "facetraj_engine.method.model", 4, True),
            Import("facetraj_engine.config", "facetraj_engine.io.files", 5, True)]
    assert upward(fake) == ["facetraj_engine.method.pipeline (line 1) imports facetraj_engine.evaluation.scores",
                            "facetraj_engine.labels.alignment (line 2) imports facetraj_engine.io.files",
                            "facetraj_engine.report.markdown (line 3) imports facetraj_engine.analysis.metrics",
                            "facetraj_engine.config (line 5) imports facetraj_engine.io.files"]


def test_no_import_circle_in_the_project():
    assert circles(import_graph()) == []


def test_the_circle_finder_finds_one():
    edges = [Import("a", "b", 1, True), Import("b", "c", 1, False), Import("c", "a", 1, True),
             Import("c", "d", 1, True)]
    assert circles(edges) == [["a", "b", "c"]]


def test_no_function_over_80_lines_and_no_class_over_400():
    big = [d for d in definitions()
           if d.lines > (400 if d.kind == "class" else 80)]
    assert big == []


@pytest.mark.parametrize("old, name", [("engine.pipeline", "synthesize"),
                                       ("engine.model", "Model"),
                                       ("facetraj_engine.formats", "read_markers"),
                                       ("engine.phones", "context_ids"),
                                       ("engine.labelmap", "write_label_map")])
def test_old_module_paths_still_import_with_a_deprecation_warning(old, name):
    sys.modules.pop(old, None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        module = __import__(old, fromlist=[name])
    assert callable(getattr(module, name))
    assert any(issubclass(w.category, DeprecationWarning) and old in str(w.message) for w in caught)


def test_the_architecture_picture_is_generated_from_the_code_as_it_is():
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    assert picture_in(page) == mermaid(), "stale: run python tests/structure.py"
