"""The layering: the engine imports nothing from ``app``, ``facetraj`` or a GUI library."""

from __future__ import annotations

import pkgutil
import subprocess
import sys
from pathlib import Path

import engine

ROOT = Path(__file__).resolve().parent.parent

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
        if info.name.startswith("engine.corpusgen"):     # the corpus extra: optional packages
            continue
        names.append(info.name)
    return names


def test_every_engine_module_imports_without_gui_libraries_or_upper_layers():
    modules = engine_modules()
    assert {"engine.model", "engine.training", "engine.pipeline", "engine.synthesis",
            "engine.paper", "engine.report.discussion", "engine.analysis.metrics"} <= set(modules)
    proc = subprocess.run([sys.executable, "-c", PROBE, *modules], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_probe_does_block_a_gui_import():
    proc = subprocess.run([sys.executable, "-c", PROBE, "app.main_window"], capture_output=True,
                          text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 1 and "blocked import" in proc.stdout
