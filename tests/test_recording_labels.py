"""One rule for a recording's labels (issue 38), through the commands a user runs: the same
recording with its ``.txt`` beside it gets the same labels and mode in ``synth``, its batch,
``video`` and ``live --from-file`` (the app: tests/test_recording_labels_gui.py); an aligner's
TextGrid counts as aligned, saying why, unless the user says otherwise."""

from __future__ import annotations

import json
import logging
import re
import shutil
from pathlib import Path

import pytest

from facetraj.cli import main
from facetraj.paths import shared_path
from facetraj_engine.io.audio import read_audio
from facetraj_engine.io.label_rule import LabelRequest, resolve_labels
from facetraj_engine.io.labelfiles import read_label_file, read_textgrid_tiers

ROOT = Path(__file__).resolve().parent.parent
ARCTIC = shared_path("data/arctic_samples") / "cmu_arctic_us_aew_a0001.wav"
RECORDINGS = [ROOT / "data_samples" / "s002.flac"] + ([ARCTIC] if ARCTIC.is_file() else [])
#: "<name>: labels <where they came from>; <mode> mode: <why>" in every command's log
LINE = re.compile(r"(?P<name>rec\.\w+): labels (?P<labels>[^;]+); (?P<mode>[a-z-]+(?: \([^)]*\))?)"
                  r" mode: (?P<why>[^;]+)")


@pytest.fixture(scope="module")
def model_file(default_model, tmp_path_factory):
    return default_model.save(tmp_path_factory.mktemp("labels") / "model.npz")


def _recording(src: Path, folder: Path) -> Path:
    """``src`` copied as ``folder/rec.*`` with its ``.txt`` beside it, and nothing else."""
    folder.mkdir()
    rec = folder / f"rec{src.suffix}"
    shutil.copy(src, rec)
    shutil.copy(src.with_suffix(".txt"), folder / "rec.txt")
    return rec


def _said(caplog) -> dict[str, str]:
    """What the command's log said of rec's labels and mode."""
    found = [m.groupdict() for m in map(LINE.search, caplog.messages) if m]
    assert found, caplog.text
    return found[-1]


def _run(argv: list, caplog) -> dict[str, str]:
    caplog.clear()
    with caplog.at_level(logging.INFO):
        assert main([str(a) for a in argv]) == 0, caplog.text
    return _said(caplog)


@pytest.mark.parametrize("src", RECORDINGS, ids=[p.stem for p in RECORDINGS])
def test_every_command_gets_the_same_labels_and_mode(src, model_file, tmp_path, caplog):
    rec = _recording(src, tmp_path / "in")
    said = {"synth": _run(["synth", model_file, rec, "-o", tmp_path / "s.tsv"], caplog)}
    said["live --from-file"] = _run(["live", "--model", model_file, "--from-file", rec,
                                     "--as-fast-as-possible", "-o", tmp_path / "take.tsv"], caplog)
    said["batch"] = _run(["synth", model_file, rec.parent, "-o", tmp_path / "batch", "-j", "1",
                          "--format", "tsv"], caplog)
    pytest.importorskip("facetraj_app")
    said["video"] = _run(["video", model_file, rec, "-o", tmp_path / "v.mp4", "--size", "640x320",
                          "--fps", "10"], caplog)
    first = said["synth"]
    assert first["labels"].startswith("aligned from rec.txt (PocketSphinx ")
    assert first["labels"].endswith("[rec.txt beside the audio]")
    assert first["mode"] == "robust" and first["why"] == "aligned labels are not hand-checked"
    for command, line in said.items():
        assert (line["labels"], line["mode"], line["why"]) == \
            (first["labels"], first["mode"], first["why"]), command
    summary = json.loads((tmp_path / "batch" / "synth-summary.json").read_text())
    assert summary["inputs"][0]["details"]["mode"] == "robust"
    # the phones themselves: the take's TextGrid holds those synth aligned
    audio, rate = read_audio(rec)
    aligned = resolve_labels(rec, audio, rate, LabelRequest()).labels
    take = read_label_file(tmp_path / "take.TextGrid", rate, len(audio) / rate)
    assert [(p.label, round(p.start, 3)) for p in take.phones] == \
        [(p.label, round(p.start, 3)) for p in aligned.phones]


MFA = """File type = "ooTextFile"
Object class = "TextGrid"

xmin = 0
xmax = {end}
tiers? <exists>
size = 1
item []:
    item [1]:
        class = "IntervalTier"
        name = "phones"
        xmin = 0
        xmax = {end}
        intervals: size = {n}
{intervals}"""


def _mfa_textgrid(path: Path, phones, end: float) -> Path:
    """The labels as the Montreal Forced Aligner writes them: upper case, stress digits on
    vowels, silences left empty, ``spn`` where a word was not in its dictionary."""
    vowels = {"aa", "ae", "ah", "ao", "aw", "ay", "eh", "er", "ey", "ih", "iy", "ow", "oy", "uh",
              "uw"}
    rows = []
    for k, p in enumerate(phones):
        label = "" if p.label == "sil" else p.label.upper() + ("1" if p.label in vowels else "")
        label = "spn" if k == 3 else label
        rows.append(f"        intervals [{k + 1}]:\n            xmin = {p.start}\n"
                    f"            xmax = {p.end}\n            text = \"{label}\"")
    path.write_text(MFA.format(end=end, n=len(rows), intervals="\n".join(rows)))
    return path


def test_an_aligners_textgrid_counts_as_aligned_saying_why(default_corpus, model_file, tmp_path,
                                                         caplog):
    utt = default_corpus.utterance("s002")
    rec = tmp_path / "rec.flac"
    shutil.copy(ROOT / "data_samples" / "s002.flac", rec)
    grid = _mfa_textgrid(tmp_path / "rec.TextGrid", utt.phones, utt.duration)
    assert "spn" in [s.label for s in read_textgrid_tiers(grid)["phones"]]
    labels = read_label_file(grid, utt.sample_rate, utt.duration)
    assert labels.provenance.kind == "aligned"
    assert labels.provenance.why.startswith("the Montreal Forced Aligner's conventions: "
                                            "upper-case phones with stress digits (")
    said = _run(["synth", model_file, rec, "-o", tmp_path / "a.tsv"], caplog)
    assert said["labels"].startswith("aligned (the Montreal Forced Aligner's conventions")
    assert said["labels"].endswith("[rec.TextGrid beside the audio]")
    assert said["mode"] == "robust"
    # the user knows better: they checked them by hand
    said = _run(["synth", model_file, rec, "-o", tmp_path / "h.tsv", "--label-provenance",
                 "hand-checked"], caplog)
    assert said["labels"] == "hand-checked [rec.TextGrid beside the audio]"
    assert said["mode"] == "phonetic"
    # the corpus's own labels (lower case, no stress digits) stay hand-checked
    assert utt.provenance.kind == "hand-checked" and not utt.provenance.why


def test_labelling_tells_its_progress_pass_by_pass(tmp_path):
    """Recognition of long audio took half a minute in silence (issue 38): each PocketSphinx pass
    is announced as it starts (a pass cannot report its own progress without changing its
    result), to the progress bar of synth and the app's status bar."""
    rec = tmp_path / "rec.flac"
    shutil.copy(ROOT / "data_samples" / "s002.flac", rec)
    audio, rate = read_audio(rec)
    seen: list[tuple[float, str]] = []
    resolve_labels(rec, audio, rate, LabelRequest(recognize=True), use_cache=False,
                   progress=lambda f, m: seen.append((round(f, 2), m)))
    assert seen == [(0.0, "recognizing rec.flac 1/3: phone loop"),
                    (0.33, "recognizing rec.flac 2/3: alignment"),
                    (0.67, "recognizing rec.flac 3/3: phone boundaries"),
                    (1.0, "recognizing rec.flac: done")]
