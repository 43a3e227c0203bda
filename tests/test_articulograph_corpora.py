"""Folders of articulograph recordings as corpora: ``facetraj corpus init`` on a folder of any one
format (with the audio and labels beside the files, or inside them: MVIEW), then the corpus's
utterances, training, evaluation and synthesis; 2-D data through the whole method."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest
from articulograph import PELLETS, write_folder
from toycorpus import FIXED, NAMES

from facetraj.cli import main
from facetraj_engine.io.corpus import load_corpus

IDS = ["toy000", "toy001", "toy002", "toy003", "toy004", "toy005"]


def run(argv, capsys) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


#: per format: corpus init's options beyond the folder (naming the lips; the channels where the
#: files do not name them; the fixed markers where the files do not say they are head-corrected)
INIT = {
    "ag501": ["--channel-names", *NAMES, "--fixed", *FIXED],
    "ndi": ["--channel-names", *NAMES, "--fixed", *FIXED],
    "est": ["--fixed", *FIXED],
    "xrmb": [],
    "mview": [],
}


@pytest.mark.parametrize("kind", ["ag501", "ndi", "est", "xrmb", "mview"])
def test_corpus_init_on_a_folder_of_each_format(kind, toy_corpus_dir, tmp_path, capsys):
    folder = write_folder(kind, toy_corpus_dir, tmp_path / kind)
    upper, lower = ("UL", "LL") if kind == "xrmb" else ("UL_C", "LL_C")
    code, out, err = run(["corpus", "init", folder, "--upper-lip", upper, "--lower-lip", lower,
                          *INIT[kind]], capsys)
    assert code == 0, err
    assert out.strip() == str(folder / "corpus.json")
    info = json.loads((folder / "corpus.json").read_text())
    assert info["head_corrected"] is (kind in ("xrmb", "mview"))
    assert info["dimensions"] == (2 if kind == "xrmb" else 3)
    assert len(info["train"]) == 4 and len(info["test"]) == 2
    utt = load_corpus(folder).utterance("toy001")
    toy = load_corpus(toy_corpus_dir).utterance("toy001")
    assert utt.marker_rate == 60.0 and abs(utt.n_frames - toy.n_frames) <= 1
    assert [p.label for p in utt.phones] == [p.label for p in toy.phones]
    np.testing.assert_array_equal(utt.audio, toy.audio)
    if kind != "xrmb":                           # the same positions, through the file's rate
        assert utt.marker_names == NAMES
        diff = np.abs(utt.markers[5:-5] - toy.markers[5:len(utt.markers) - 5])
        assert np.nanmedian(diff) < 0.05 and np.nanpercentile(diff, 99) < 1.5
    if kind == "mview":
        assert utt.text == "toy sentence" and utt.provenance.kind == "aligned"


def test_unnamed_channels_need_names_and_fixed_markers(toy_corpus_dir, tmp_path, capsys, caplog):
    folder = write_folder("ag501", toy_corpus_dir, tmp_path / "pos", IDS[:2])
    code, _, err = run(["corpus", "init", folder, "--upper-lip", "UL_C", "--lower-lip", "LL_C"],
                       capsys)
    assert code == 2 and "no marker named 'UL_C'; markers: Ch1 Ch2" in err
    (folder / "channel-names.txt").write_text("# the sockets\n" + "".join(
        f"Ch{i + 1} {n}\n" for i, n in enumerate(NAMES)))
    code, _, err = run(["corpus", "init", folder, "--upper-lip", "UL_C", "--lower-lip", "LL_C"],
                       capsys)
    assert code == 2 and err.count("\n") == 1
    assert "toy000.pos: no fixed markers: name 3 or more sensors that move only with the head " \
           "(--fixed, among FH_L FH_R" in err and "Carstens AG501 .pos files do not say" in err
    with caplog.at_level(logging.INFO):
        code, _, err = run(["corpus", "init", folder, "--upper-lip", "UL_C", "--lower-lip", "LL_C",
                            "--head-corrected"], capsys)
    assert code == 0, err
    info = json.loads((folder / "corpus.json").read_text())
    assert info["head_corrected"] and info["fixed_markers"] == [] and info["channel_names"][0] == "Ch1=FH_L"
    assert "already head-corrected (as declared): no fixed markers needed" in caplog.text


def test_two_d_data_runs_the_whole_method(toy_corpus_dir, tmp_path, capsys):
    """XRMB pellets (x, y): trained, evaluated and synthesized in the midsagittal plane."""
    from facetraj_engine.method.model import Model

    folder = write_folder("xrmb", toy_corpus_dir, tmp_path / "xrmb")
    assert run(["corpus", "init", folder, "--upper-lip", "UL", "--lower-lip", "LL"], capsys)[0] == 0
    code, _, err = run(["train", folder, "-o", tmp_path / "m.npz", "--no-tune"], capsys)
    assert code == 0, err
    model = Model.load(tmp_path / "m.npz")
    assert model.is_planar and model.marker_names == list(PELLETS) and len(model.fixed) == 0
    code, out, err = run(["eval", tmp_path / "m.npz", folder], capsys)
    assert code == 0, err
    rows = [ln.split() for ln in out.splitlines() if ln.startswith(("Train (", "Test ("))]
    assert len(rows) == 4 and all(-1 <= float(r[-3]) <= 1 for r in rows)      # upper lip r
    assert all(np.isnan(float(r[-1])) or 0 <= float(r[-1]) <= 1 for r in rows)   # closed recall
    code, _, err = run(["synth", tmp_path / "m.npz", folder / "toy004.wav", "-o", tmp_path / "o.tsv"],
                       capsys)
    assert code == 0, err
    table = np.loadtxt(tmp_path / "o.tsv", skiprows=1)
    assert not table[:, 1::3].any() and np.isfinite(table).all()     # x = 0: nothing invented


def test_two_mview_files_need_only_the_lips(toy_corpus_dir, tmp_path, capsys, caplog):
    """The aim: a folder of two MVIEW files (audio, phones, words inside): corpus init, train,
    eval and synth with no other file and no option but the lip sensors' names."""
    folder = write_folder("mview", toy_corpus_dir, tmp_path / "mv", ["toy000", "toy001"])
    assert sorted(p.name for p in folder.iterdir()) == ["toy000.mat", "toy001.mat"]
    with caplog.at_level(logging.INFO):
        code, _, err = run(["corpus", "init", folder, "--upper-lip", "UL_C", "--lower-lip", "LL_C"],
                           capsys)
    assert code == 0, err
    assert "its MVIEW files say so" in caplog.text and "labels: 2 aligned" in caplog.text
    info = json.loads((folder / "corpus.json").read_text())
    assert (info["train"], info["test"]) == (["toy000"], ["toy001"])
    assert run(["train", folder, "-o", tmp_path / "m.npz"], capsys)[0] == 0
    code, out, err = run(["eval", tmp_path / "m.npz", folder], capsys)
    assert code == 0, err
    assert "Test (triangular" in out
    with caplog.at_level(logging.INFO):
        code, _, err = run(["synth", tmp_path / "m.npz", folder / "toy001.mat", "-o",
                            tmp_path / "o.c3d"], capsys)
    assert code == 0, err
    assert "toy001.mat's PHONES" in caplog.text and "labels aligned" in caplog.text


def test_bad_marker_file_in_a_corpus_is_one_line_exit_2(toy_corpus_dir, tmp_path, capsys):
    folder = write_folder("ag501", toy_corpus_dir, tmp_path / "pos", IDS[:3])
    assert run(["corpus", "init", folder, "--upper-lip", "UL_C", "--lower-lip", "LL_C",
                *INIT["ag501"]], capsys)[0] == 0
    data = (folder / "toy002.pos").read_bytes()
    (folder / "toy002.pos").write_bytes(data[:-3])
    code, _, err = run(["corpus", "show", folder], capsys)
    errors = [ln for ln in err.splitlines() if ": error: " in ln]
    assert code == 2 and len(errors) == 1 and "Traceback" not in err
    assert "toy002.pos: after its 70-byte header it holds" in errors[0]
