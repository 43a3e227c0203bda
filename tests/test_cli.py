"""The facetraj command, run in-process: every subcommand, and exit status 2 on bad input."""

import json
import os

import numpy as np
import pytest

from facetraj.cli import main
from facetraj_engine.io.markerfiles import read_c3d, read_marker_table


@pytest.fixture(scope="module")
def model_file(toy_corpus_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "model.npz"
    assert main(["-q", "train", str(toy_corpus_dir), "-o", str(out)]) == 0
    return out


def test_synth_outputs(model_file, toy_corpus_dir, tmp_path, capsys):
    wav = toy_corpus_dir / "toy030.wav"
    tg = toy_corpus_dir / "toy030.TextGrid"
    assert main(["-q", "synth", str(model_file), str(wav), "--labels", str(tg),
                 "-o", str(tmp_path / "o.c3d")]) == 0
    c3d = read_c3d(tmp_path / "o.c3d")
    assert c3d.markers.shape[1:] == (12, 3) and c3d.rate == 60.0
    assert main(["-q", "synth", str(model_file), str(wav), "--smoothing", "spline", "-N", "5",
                 "-o", str(tmp_path / "o.tsv")]) == 0
    tsv = read_marker_table(tmp_path / "o.tsv")
    assert tsv.markers.shape == c3d.markers.shape
    assert main(["-q", "synth", str(model_file), str(wav), "--labels", str(tg),
                 "-o", str(tmp_path / "o.npz")]) == 0
    with np.load(tmp_path / "o.npz", allow_pickle=False) as z:
        assert z["markers"].shape == c3d.markers.shape
        np.testing.assert_allclose(z["markers"], c3d.markers, atol=0.006)


def test_eval_sweep_similarity(model_file, toy_corpus_dir, capsys):
    assert main(["-q", "eval", str(model_file), str(toy_corpus_dir), "--split", "test",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    rows = {(r["split"], r["smoothing"]): r for r in out["table"]}
    assert set(rows) == {("test", "triangular"), ("test", "spline")}
    assert 0.5 < rows[("test", "triangular")]["lower_lip"] <= 1.0
    assert main(["-q", "sweep", str(model_file), str(toy_corpus_dir), "--max-n", "2",
                 "--split", "test", "--json"]) == 0
    sweep = json.loads(capsys.readouterr().out)
    assert sweep["n"] == [1, 2] and len(sweep["whole_face"]["test"]) == 2
    assert main(["-q", "similarity", str(model_file)]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[0].split()[:2] == ["Phoneme", "Closest"] and len(table) == 1 + 7
    assert main(["-q", "similarity", str(model_file), "--csv", "--nu", "5"]) == 0
    csv = capsys.readouterr().out.splitlines()
    assert csv[0].split(",")[0] == "phone" and len(csv) == 1 + 8


@pytest.mark.parametrize("args, message", [
    (["synth", "{model}", "{missing}", "-o", "{out}"], "missing.wav: no such audio file"),
    (["synth", "{bad}", "{wav}", "-o", "{out}"], "bad.npz: not a facetraj model"),
    (["synth", "{model}", "{wav}", "--labels", "{short}", "-o", "{out}"], "short.lab: labels end at"),
    (["synth", "{model}", "{wav}", "--labels", "{alien}", "-o", "{out}"],
     "alien.lab: labels in no phone alphabet facetraj knows: 'zz' (at 0.500 s)"),
    (["synth", "{model}", "{wav}", "-o", "{exists}"], "exists.c3d: already exists"),
    (["train", "{empty}", "-o", "{out}"], "no corpus.json"),
])
def test_bad_input_exit_2(args, message, model_file, toy_corpus_dir, tmp_path, capsys):
    (tmp_path / "bad.npz").write_text("not a model")
    (tmp_path / "short.lab").write_text("0 0.5 sil\n")
    (tmp_path / "alien.lab").write_text("0 0.5 sil\n0.5 1.5 zz\n1.5 1.8333 sil\n")
    (tmp_path / "exists.c3d").write_text("keep me")
    (tmp_path / "empty").mkdir()
    paths = {"model": model_file, "missing": tmp_path / "missing.wav", "out": tmp_path / "o.c3d",
             "bad": tmp_path / "bad.npz", "wav": toy_corpus_dir / "toy030.wav",
             "short": tmp_path / "short.lab", "alien": tmp_path / "alien.lab",
             "exists": tmp_path / "exists.c3d", "empty": tmp_path / "empty"}
    code = main(["-q", *[a.format(**paths) for a in args]])
    err = capsys.readouterr().err
    assert code == 2
    assert message in err and "Traceback" not in err
    assert (tmp_path / "exists.c3d").read_text() == "keep me"


def test_report_command(model_file, toy_corpus_dir, tmp_path):
    assert main(["-q", "report", str(toy_corpus_dir), "-o", str(tmp_path), "--model", str(model_file),
                 "--max-n", "2"]) == 0
    text = (tmp_path / "results.md").read_text()
    assert "Table 1" in text and "Table 2" in text
    assert (tmp_path / "results.json").exists()


LOGGING_PROBE = """
import logging, sys
from facetraj.cli import configure_logging
configure_logging(int(sys.argv[1]))
import matplotlib
matplotlib.use("Agg")
from matplotlib.figure import Figure
fig = Figure()
fig.text(0.5, 0.5, "a font is looked up")
fig.savefig(sys.argv[2])
logging.getLogger("facetraj_engine.probe").debug("our own debug line")
logging.getLogger("matplotlib.probe").warning("a library warning")
"""


@pytest.mark.parametrize("verbose", [1, 2])
def test_verbose_logs_ours_and_libraries_only_when_asked(verbose, tmp_path):
    """``-v``: facetraj's debug messages, the libraries' warnings only (it printed matplotlib's
    font matching: 292 of 323 lines); ``-vv``: everything."""
    import subprocess
    import sys

    env = {**os.environ, "MPLCONFIGDIR": str(tmp_path / "mpl")}   # a font cache to build: lines
    proc = subprocess.run([sys.executable, "-c", LOGGING_PROBE, str(verbose), str(tmp_path / "f.png")],
                          capture_output=True, text=True, timeout=120, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stderr.splitlines()
    assert "DEBUG: our own debug line" in lines
    assert "WARNING: a library warning" in lines
    library_debug = [ln for ln in lines if ln.startswith("DEBUG:") and "our own" not in ln]
    if verbose == 1:
        assert library_debug == []
    else:
        assert any("findfont" in ln for ln in library_debug)


def test_every_subcommand_takes_verbosity_after_it_too():
    """``-v``/``-q`` before the subcommand or after it, nested ones (``corpus show``) included;
    what is given before stands when nothing is given after."""
    from facetraj.cli import build_parser

    parser = build_parser()
    cases = {("-q", "synth", "m.npz", "a.wav", "-o", "x.c3d"): (0, True),
             ("synth", "m.npz", "a.wav", "-o", "x.c3d", "-vv"): (2, False),
             ("-v", "corpus", "show", "folder"): (1, False),
             ("corpus", "show", "folder", "-q"): (0, True),
             ("eval", "m.npz", "corpus", "-v", "--split", "test"): (1, False)}
    for argv, (verbose, quiet) in cases.items():
        args = parser.parse_args(list(argv))
        assert (args.verbose, args.quiet) == (verbose, quiet), argv



def test_the_command_starts_no_blas_thread_per_core():
    """facetraj makes every matrix product on one BLAS thread (facetraj_engine.threads), so as a
    program it tells OpenBLAS to start no thread per core, unless the environment says
    otherwise (issue 48)."""
    import os
    import subprocess
    import sys

    code = ("import facetraj.cli, numpy\n"
            "from threadpoolctl import threadpool_info\n"
            "print(max(i['num_threads'] for i in threadpool_info() if i['user_api'] == 'blas'))")
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    for setting, threads in ((None, 1), ("2", 2)):
        if setting:
            env["OPENBLAS_NUM_THREADS"] = setting
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, check=True)
        assert int(out.stdout.split()[-1]) == threads


def test_as_the_program_it_freezes_its_objects_before_exiting(tmp_path):
    """Run as the program (no arguments given to main: sys.argv), the command freezes what is
    left for the garbage collector before the interpreter's teardown; called with arguments
    (a caller's process, these tests) it leaves the collector alone (issue 48)."""
    import gc
    import subprocess
    import sys

    argv = ["facetraj", "-q", "synth", str(tmp_path / "no.npz"), str(tmp_path / "no.wav"), "-o",
            str(tmp_path / "out.tsv")]
    code = ("import gc, sys, facetraj.cli\n"
            f"sys.argv = {argv!r}\n"
            "code = facetraj.cli.main()\n"
            "print(code, gc.get_freeze_count())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    status, frozen = map(int, out.stdout.split())
    assert status == 2 and frozen > 1000
    before = gc.get_freeze_count()
    assert main(argv[1:]) == 2
    assert gc.get_freeze_count() == before
