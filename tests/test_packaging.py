"""The two distributions' metadata (docs/install.md): every package folder is in a distribution,
the version is written once, the app pins the engine of that version, and nothing installs a
generic top-level name. (``packaging/check_install.py`` builds and installs the wheels.)"""

from __future__ import annotations

import runpy
import subprocess
import sys
import tomllib
import types
from pathlib import Path

import facetraj_engine

ROOT = Path(__file__).resolve().parent.parent
APP = ROOT / "packaging" / "app"


def packages_under(folder: str, name: str) -> set[str]:
    return {".".join((name, *p.parent.relative_to(ROOT / folder).parts))
            for p in (ROOT / folder).rglob("__init__.py")}


def test_every_package_folder_is_in_a_distribution():
    engine = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    app = tomllib.loads((APP / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert engine["package-dir"] == {"": "packaging/engine"}
    assert app["package-dir"] == {"": "src"}
    assert set(engine["packages"]) == packages_under("engine", "facetraj_engine") | \
        packages_under("facetraj", "facetraj")
    assert set(app["packages"]) == packages_under("app", "facetraj_app") | {"facetraj_app.corpus"}
    links = {ROOT / "packaging" / "engine" / "facetraj_engine": ROOT / "engine",
             ROOT / "packaging" / "engine" / "facetraj": ROOT / "facetraj",
             APP / "src" / "facetraj_app": ROOT / "app", ROOT / "app" / "corpus": ROOT / "data_samples",
             APP / "engine_version.py": ROOT / "engine" / "__init__.py"}
    for link, target in links.items():
        assert link.is_symlink() and link.resolve() == target.resolve(), link


def test_the_editable_installs_are_quiet():
    """Every package sits in a folder of its import name under one root (the links above), so
    that setuptools' editable install puts that root on the path with a .pth file; a package
    mapped from a folder of another name made it install an import hook and print, for each
    distribution at every ``make run`` on a fresh clone, "BuildBackendWarning ... folders in
    your working directory with the same name as your package" (issue 54). Nothing else is in
    the root: the path gets no other name."""
    for project in (ROOT, APP):
        config = tomllib.loads((project / "pyproject.toml").read_text())["tool"]["setuptools"]
        assert set(config["package-dir"]) == {""}, project       # one root for every package
        root = project / config["package-dir"][""]
        for package in config["packages"]:
            assert root.joinpath(*package.split(".")).is_dir(), package     # by its own name
        assert sorted(p.name for p in root.iterdir() if not p.name.endswith(".egg-info")) == \
            sorted({p.split(".")[0] for p in config["packages"]})


def test_the_version_is_written_once_and_the_app_pins_that_engine(monkeypatch):
    setup = (APP / "setup.py").read_text()
    assert "engine_version.py" in setup and facetraj_engine.__version__ not in setup
    for path in (ROOT / "pyproject.toml", APP / "pyproject.toml"):
        project = tomllib.loads(path.read_text())["project"]
        assert "version" not in project and "version" in project["dynamic"], path
    given: dict = {}
    fake = types.ModuleType("setuptools")
    fake.setup = lambda **kwargs: given.update(kwargs)
    monkeypatch.setitem(sys.modules, "setuptools", fake)
    runpy.run_path(str(APP / "setup.py"))
    version = facetraj_engine.__version__
    assert given["version"] == version
    assert f"facetraj-engine=={version}" in given["install_requires"]


def test_the_default_corpus_files_are_all_packaged():
    patterns = tomllib.loads((APP / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"]["facetraj_app.corpus"]
    suffixes = {p.removeprefix("*") for p in patterns}
    unpackaged = [p.name for p in (ROOT / "data_samples").iterdir()
                  if p.is_file() and p.suffix not in suffixes]
    assert unpackaged == []


def test_no_generic_name_is_importable_outside_the_checkout(tmp_path):
    """From a folder that is not the checkout, the old generic names do not import."""
    probe = ("import importlib.util as u; "
             "print([n for n in ('engine', 'app') if u.find_spec(n) is not None])")
    out = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"
