"""``facetraj synth MODEL INPUTS... -o OUTDIR`` (issue 28): a folder of the default corpus's
recordings with one corrupt file, through ``facetraj.cli.main``."""

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest
from conftest import DEFAULT_CORPUS

from facetraj.batch import SUMMARY_NAME, collect_inputs, is_batch, output_paths
from facetraj.cli import main
from facetraj_engine.io.markerfiles import read_marker_table


@pytest.fixture(scope="module")
def model_path(default_model, tmp_path_factory):
    path = tmp_path_factory.mktemp("batch") / "model.npz"
    default_model.save(path)
    return path


@pytest.fixture
def folder(tmp_path):
    """Three recordings of the default corpus (s001 with its TextGrid beside it, the others
    bare: recognized) and a truncated FLAC."""
    src = tmp_path / "in"
    src.mkdir()
    for name in ("s001", "s002", "s003"):
        shutil.copy(DEFAULT_CORPUS / f"{name}.flac", src)
    shutil.copy(DEFAULT_CORPUS / "s001.TextGrid", src)
    (src / "broken.flac").write_bytes((DEFAULT_CORPUS / "s004.flac").read_bytes()[:3000])
    return src


def _summary(out):
    return json.loads((out / SUMMARY_NAME).read_text())


def test_a_folder_with_a_corrupt_file_finishes_the_others_and_names_it(model_path, folder,
                                                                      tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["-q", "synth", str(model_path), str(folder), "-o", str(out), "--format", "tsv",
                 "-j", "2"])
    captured = capsys.readouterr()
    assert code == 2                                       # an input failed
    assert sorted(p.name for p in out.iterdir()) == ["s001.tsv", "s002.tsv", "s003.tsv",
                                                     SUMMARY_NAME]
    assert "3 done, 0 skipped (output exists), 1 failed" in captured.out
    err = [ln for ln in captured.err.splitlines() if "broken.flac" in ln]
    assert len(err) == 1 and "Traceback" not in captured.err
    assert err[0].startswith("facetraj: failed: ") and "broken.flac: the audio file is cut short " \
        "or damaged: its header says" in err[0]
    summary = _summary(out)
    assert (summary["done"], summary["skipped"], summary["failed"]) == (3, 0, 1)
    by_name = {r["input"].rsplit("/", 1)[-1]: r for r in summary["inputs"]}
    assert by_name["broken.flac"]["status"] == "failed"
    assert "broken.flac: the audio file is cut short or damaged" in by_name["broken.flac"]["reason"]
    # every input's labels by the rule for one file: beside it, else recognized
    assert by_name["s001.flac"]["details"]["labels"].startswith("hand-checked")
    assert by_name["s001.flac"]["details"]["mode"] == "phonetic"
    assert by_name["s002.flac"]["details"]["labels"].startswith("recognized")
    assert by_name["s002.flac"]["details"]["mode"] == "robust"
    for name in ("s001", "s002", "s003"):
        table = read_marker_table(out / f"{name}.tsv")
        assert table.markers.shape[1:] == (54, 3) and np.isfinite(table.markers).all()


def test_one_files_npz_is_the_batchs_to_the_bit(model_path, folder, tmp_path):
    """``synth`` on one file in a new process writes the bytes a batch's worker (one BLAS thread)
    writes for that file: full float64, not a rounded table."""
    single = tmp_path / "single.npz"
    subprocess.run([sys.executable, "-m", "facetraj", "-q", "synth", str(model_path),
                    str(folder / "s001.flac"), "-o", str(single)], check=True, cwd=tmp_path)
    out = tmp_path / "out"
    assert main(["-q", "synth", str(model_path), str(folder / "s00[12].flac"), "-o", str(out),
                 "--format", "npz", "-j", "2"]) == 0
    assert (out / "s001.npz").read_bytes() == single.read_bytes()


def test_each_output_is_the_one_file_commands_and_a_run_resumes(model_path, folder, tmp_path,
                                                                capsys):
    out = tmp_path / "out"
    assert main(["-q", "synth", str(model_path), str(folder / "s00*.flac"), "-o", str(out),
                 "--format", "tsv", "-j", "1"]) == 0
    single = tmp_path / "single.tsv"
    assert main(["-q", "synth", str(model_path), str(folder / "s002.flac"), "-o",
                 str(single)]) == 0
    assert (out / "s002.tsv").read_bytes() == single.read_bytes()
    in_pool = tmp_path / "pool"
    assert main(["-q", "synth", str(model_path), str(folder / "s00*.flac"), "-o",
                 str(in_pool), "--format", "tsv", "-j", "2"]) == 0
    for name in ("s001", "s002", "s003"):                  # two processes: the same files
        assert (in_pool / f"{name}.tsv").read_bytes() == (out / f"{name}.tsv").read_bytes()
    # interrupted or run again: what exists is skipped, the rest done
    (out / "s003.tsv").unlink()
    stamp = (out / "s001.tsv").stat().st_mtime_ns
    capsys.readouterr()
    assert main(["-q", "synth", str(model_path), str(folder), "-o", str(out), "--format",
                 "tsv"]) == 2                              # broken.flac still fails
    assert "1 done, 2 skipped (output exists), 1 failed" in capsys.readouterr().out
    assert (out / "s001.tsv").stat().st_mtime_ns == stamp and (out / "s003.tsv").exists()
    assert main(["-q", "synth", str(model_path), str(folder / "s001.flac"),
                 str(folder / "s002.flac"), "-o", str(out), "--format", "tsv",
                 "--overwrite"]) == 0
    assert _summary(out)["done"] == 2 and (out / "s001.tsv").stat().st_mtime_ns != stamp


def test_inputs_from_a_list_file_and_refused_options(model_path, folder, tmp_path, capsys):
    listing = tmp_path / "inputs.lst"
    listing.write_text("# two recordings\nin/s002.flac\n\nin/s003.flac  # the second\n")
    assert collect_inputs([str(listing)]) == [folder / "s002.flac", folder / "s003.flac"]
    assert main(["-q", "synth", str(model_path), str(listing), "-o", str(tmp_path / "o"),
                 "--format", "npz", "--mode", "acoustic"]) == 0
    with np.load(tmp_path / "o" / "s003.npz") as z:
        assert z["markers"].shape[1:] == (54, 3)
    assert main(["-q", "synth", str(model_path), str(folder), "-o", str(tmp_path / "p"),
                 "--text", "a sentence"]) == 2
    assert "--text names the labels of one recording" in capsys.readouterr().err


def test_batch_or_one_file_and_output_names(tmp_path):
    (tmp_path / "a").mkdir()
    assert not is_batch(["x.wav"], tmp_path / "face.c3d")
    assert is_batch(["x.wav"], tmp_path / "a") and is_batch(["x.wav"], tmp_path / "new")
    assert is_batch(["x.wav", "y.wav"], tmp_path / "o") and is_batch(["d/*.wav"], tmp_path / "o")
    assert output_paths([tmp_path / "x.wav"], tmp_path / "o", "c3d") == [tmp_path / "o" / "x.c3d"]
    with pytest.raises(Exception, match="two inputs would both be written here"):
        output_paths([tmp_path / "a" / "x.wav", tmp_path / "x.flac"], tmp_path / "o", "tsv")
