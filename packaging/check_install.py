"""The wheels as a lab installs them: both built from this checkout (``python -m build``), then
installed into fresh virtual environments that hold only pip, used from a folder outside the
checkout, with nothing of the checkout on the path.

1. the engine alone: ``import facetraj_engine`` works and PyQt6 is not there; ``facetraj
   --version``, ``train`` on a few sentences, ``synth``, ``eval``, ``live --from-file`` and
   ``report`` (without its figures) work; ``facetraj gui`` says in one line how to get the app;
2. the engine and the app: ``facetraj --version``, ``synth`` and ``facetraj --screenshot`` (the
   app on the default corpus, which the app's wheel carries) work;
3. the names the two distributions put at the top of site-packages are facetraj's own.

``python packaging/check_install.py`` (``make check-install``; CI runs it after the tests). Each
step's command and time is printed; the first failure ends the run with status 1. It needs the
network only for pip to fetch the dependencies (none at run time), and ``xvfb-run`` for the
screenshot when there is no display.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OWN_NAMES = {"facetraj", "facetraj_engine", "facetraj_app"}
TOP_NAMES = """
import importlib.metadata as md, json
names = {}
for dist in ("facetraj-engine", "facetraj"):
    try:
        files = md.files(dist) or []
    except md.PackageNotFoundError:
        continue
    names[dist] = sorted({f.parts[0] for f in files if not f.parts[0].endswith((".dist-info", ".data"))
                          and f.parts[0] != ".." and f.suffix != ".pth"})
print(json.dumps(names))
"""


class Failed(Exception):
    pass


def run(argv: list[str], cwd: Path, env: dict | None = None, expect: int = 0,
        timeout: float = 1800) -> str:
    """Run a step, print it with its time; its output (stdout + stderr)."""
    t0 = time.perf_counter()
    proc = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    took = time.perf_counter() - t0
    shown = " ".join(str(a) for a in argv)
    print(f"  [{took:6.1f} s] exit {proc.returncode}: {shown}", flush=True)
    out = proc.stdout + proc.stderr
    if proc.returncode != expect:
        raise Failed(f"{shown}: exit {proc.returncode}, expected {expect}\n{out[-3000:]}")
    return out


def fresh_python() -> str:
    """A Python whose ``venv`` holds only pip (3.12 and later: on the PATH, or one pyenv keeps);
    else this one (the setuptools its venvs hold is removed)."""
    found = [shutil.which(n) for n in ("python3.12", "python3.13")]
    found += sorted(str(p) for p in Path.home().glob(".pyenv/versions/3.1[23]*/bin/python3"))
    for candidate in filter(None, found):
        if subprocess.run([candidate, "-c", "import venv"], capture_output=True).returncode == 0:
            return candidate
    return sys.executable


def make_venv(where: Path) -> Path:
    """A new virtual environment that holds only pip; its ``bin``."""
    subprocess.run([fresh_python(), "-m", "venv", str(where)], check=True)
    pip = [str(where / "bin" / "python"), "-m", "pip"]
    subprocess.run([*pip, "uninstall", "-q", "-y", "setuptools"], capture_output=True)
    held = subprocess.run([*pip, "list", "--format", "json"], capture_output=True, text=True,
                          check=True).stdout
    names = sorted(p["name"] for p in json.loads(held))
    if names != ["pip"]:
        raise Failed(f"{where}: a fresh environment holds {names}, not only pip")
    return where / "bin"


def small_corpus(where: Path, n_train: int = 40, n_test: int = 3) -> Path:
    """A corpus of a few sentences of the default corpus (its files linked, not copied)."""
    source = ROOT / "data_samples"
    info = json.loads((source / "corpus.json").read_text())
    info["train"], info["test"] = info["train"][:n_train], info["test"][:n_test]
    where.mkdir()
    for utt in info["train"] + info["test"]:
        for path in source.glob(f"{utt}.*"):
            (where / path.name).symlink_to(path)
    (where / "corpus.json").write_text(json.dumps(info))
    return where


def build(dist: Path) -> tuple[Path, Path]:
    """Both wheels (and sdists) into ``dist``; the engine's and the app's wheel."""
    for project in (ROOT, ROOT / "packaging" / "app"):
        run([sys.executable, "-m", "build", "-o", str(dist), str(project)], cwd=ROOT)
    engine = next(dist.glob("facetraj_engine-*.whl"))
    app = next(p for p in dist.glob("facetraj-*.whl") if not p.name.startswith("facetraj_engine"))
    return engine, app


def engine_alone(tmp: Path, wheel: Path, env: dict) -> None:
    print("the engine alone:", flush=True)
    bin_ = make_venv(tmp / "venv-engine")
    run([str(bin_ / "pip"), "install", "-q", str(wheel)], cwd=tmp)
    work = tmp / "engine-work"
    work.mkdir()
    corpus = small_corpus(work / "corpus")
    first_test = json.loads((corpus / "corpus.json").read_text())["test"][0]
    facetraj = str(bin_ / "facetraj")
    py = str(bin_ / "python")
    run([py, "-c", "import facetraj_engine, facetraj_engine.method.pipeline, facetraj.cli"], cwd=work,
        env=env)
    out = run([py, "-c", "import PyQt6"], cwd=work, env=env, expect=1)
    assert "No module named 'PyQt6'" in out, out
    assert "engine only" in run([facetraj, "--version"], cwd=work, env=env)
    run([facetraj, "train", "corpus", "-o", "model.npz"], cwd=work, env=env)
    run([facetraj, "synth", "model.npz", f"corpus/{first_test}.flac", "-o", "face.c3d"], cwd=work, env=env)
    out = run([facetraj, "eval", "model.npz", "corpus", "--split", "test"], cwd=work, env=env)
    print("    " + "\n    ".join(out.strip().splitlines()[-4:]))
    run([facetraj, "live", "--from-file", f"corpus/{first_test}.flac", "--model", "model.npz",
         "--as-fast-as-possible", "-o", "take.tsv"], cwd=work, env=env)
    out = run([facetraj, "report", "corpus", "--model", "model.npz", "-o", "report", "--max-n", "2"],
              cwd=work, env=env)
    assert (work / "report" / "results.md").is_file() and "without its figures" in out, out[-500:]
    for argv in (["gui"], [], ["video", "model.npz", f"corpus/{first_test}.flac", "-o", "v.mp4"]):
        out = run([facetraj, *argv], cwd=work, env=env, expect=2)
        assert "needs the app, which is not installed: pip install facetraj" in out, out
        assert "Traceback" not in out and len(out.strip().splitlines()) == 1, out
        print(f"    facetraj {' '.join(argv)} without the app: {out.strip()}")


def engine_and_app(tmp: Path, wheels: tuple[Path, Path], env: dict, keep: Path | None) -> None:
    print("the engine and the app:", flush=True)
    bin_ = make_venv(tmp / "venv-app")
    run([str(bin_ / "pip"), "install", "-q", *map(str, wheels)], cwd=tmp)
    work = tmp / "app-work"
    work.mkdir()
    facetraj = str(bin_ / "facetraj")
    out = run([facetraj, "--version"], cwd=work, env=env)
    assert "engine only" not in out, out
    model = tmp / "engine-work" / "model.npz"
    sample = next((tmp / "engine-work" / "corpus").glob("*.flac"))
    run([facetraj, "synth", str(model), str(sample), "-o", "face.tsv"], cwd=work, env=env)
    shot = work / "shot.png"
    xvfb = [] if os.environ.get("DISPLAY") else ["xvfb-run", "-a", "-s", "-screen 0 1920x1200x24"]
    run([*xvfb, facetraj, "--screenshot", str(shot), "--time", "1.0"], cwd=work, env=env)
    if not shot.is_file() or shot.stat().st_size < 50_000:
        raise Failed(f"{shot}: no screenshot of the app")
    print(f"    screenshot of the app on the default corpus from the wheel: {shot.stat().st_size} bytes")
    if keep is not None:
        shutil.copy(shot, keep)
    names = json.loads(run([str(bin_ / "python"), "-c", TOP_NAMES], cwd=work, env=env))
    print(f"    top-level names: {names}")
    extra = {n for dist in names.values() for n in dist} - OWN_NAMES
    if extra or set(names) != {"facetraj-engine", "facetraj"}:
        raise Failed(f"names at the top of site-packages that are not facetraj's: {sorted(extra)}")


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--screenshot-to", type=Path, help="keep the app's screenshot here")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="facetraj-install-") as tmp_name:
        tmp = Path(tmp_name)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
        env.update(FACETRAJ_CACHE_DIR=str(tmp / "cache"), MPLCONFIGDIR=str(tmp / "mpl"),
                   FACETRAJ_SHARED=str(ROOT.parent / "shared"))
        try:
            print("building the wheels:", flush=True)
            wheels = build(tmp / "dist")
            print(f"    {wheels[0].name} ({wheels[0].stat().st_size // 1024} KiB), "
                  f"{wheels[1].name} ({wheels[1].stat().st_size // 1024} KiB)")
            engine_alone(tmp, wheels[0], env)
            engine_and_app(tmp, wheels, env, args.screenshot_to)
        except (Failed, AssertionError, subprocess.TimeoutExpired) as exc:
            print(f"check-install FAILED: {exc}", file=sys.stderr)
            return 1
    print("check-install: every step passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
