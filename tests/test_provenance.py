"""Label provenance (issue 24): label files facetraj writes say how they were made and how sure
their maker was, survive Praat (opened, saved, a few phones corrected), and the one mode rule
follows them through the command line."""

from __future__ import annotations

import logging
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from facetraj_engine.data import PhoneSegment, Provenance
from facetraj_engine.io.labelfiles import read_label_file, read_textgrid_tiers, recorded_provenance
from facetraj_engine.io.labelling import write_labels
from facetraj_engine.labels.provenance import Labels, labels_from_tiers, parse_provenance, provenance_text

PRAAT = shutil.which("praat")
PHONES = [PhoneSegment(0.0, 0.2, "sil"), PhoneSegment(0.2, 0.31, "b"),
          PhoneSegment(0.31, 0.52, "oy"), PhoneSegment(0.52, 0.8, "sil")]


def aligned_labels() -> Labels:
    scores = np.array([-2.0, -12.0, -5.0, np.nan])
    return Labels(list(PHONES), [PhoneSegment(0.2, 0.52, "boy")], "aligned", scores, "boy",
                  Provenance("aligned", "PocketSphinx 5.1.1", "boy.txt"))


def test_provenance_text_round_trip():
    p = Provenance("recognized", "PocketSphinx 5.1.1", "a.wav")
    assert parse_provenance(provenance_text(p)) == p
    assert parse_provenance("source=aligned") == Provenance("aligned")
    assert parse_provenance("source=guessed; tool=x") is None


def test_written_labels_keep_their_provenance_and_confidence(tmp_path):
    lab = aligned_labels()
    write_labels(tmp_path / "a.TextGrid", lab, 0.8)
    tiers = read_textgrid_tiers(tmp_path / "a.TextGrid")
    assert list(tiers) == ["words", "phones", "provenance", "confidence"]
    assert [s.label for s in tiers["confidence"]] == ["sil 0.819", "b 0.301", "oy 0.607", "sil -"]
    back = read_label_file(tmp_path / "a.TextGrid", 16000, 0.8)
    assert back.source == "file" and back.phones == lab.phones
    assert back.provenance == Provenance("aligned", "PocketSphinx 5.1.1", "boy.txt", 0)
    np.testing.assert_allclose(back.confidence[:3], lab.confidence[:3], atol=5e-4)
    assert np.isnan(back.confidence[3])
    np.testing.assert_allclose(back.trust()[:3], [0.819, 0.301, 0.607], atol=1e-9)
    assert recorded_provenance(tmp_path / "a.TextGrid").kind == "aligned"


def test_hand_checked_labels_are_written_as_before_and_files_from_elsewhere_count_as_checked(tmp_path):
    write_labels(tmp_path / "h.TextGrid", Labels(list(PHONES)), 0.8)
    assert list(read_textgrid_tiers(tmp_path / "h.TextGrid")) == ["phones"]
    back = read_label_file(tmp_path / "h.TextGrid", 16000, 0.8)
    assert back.provenance == Provenance() and back.trust() is None
    declared = read_label_file(tmp_path / "h.TextGrid", 16000, 0.8, declared="recognized")
    assert declared.provenance.kind == "recognized"
    assert np.isnan(declared.trust()).all()               # no scores: the robust mode counts 1/2
    assert recorded_provenance(tmp_path / "h.TextGrid") is None


def test_a_phone_corrected_by_hand_counts_as_checked_the_others_keep_their_confidence():
    lab = aligned_labels()
    tiers = lab.tiers()
    edited = list(PHONES)
    edited[1] = PhoneSegment(0.2, 0.33, "p")                  # label and boundary corrected
    edited[2] = PhoneSegment(0.33, 0.52, "oy")                # its left boundary moved with it
    got = labels_from_tiers(edited, [], tiers)
    assert got.provenance.corrected == 2 and got.provenance.kind == "aligned"
    np.testing.assert_allclose(got.confidence[:3], [0.819, 1.0, 1.0], atol=5e-4)
    assert "2 phones corrected by hand" in got.provenance.describe()
    # a file whose provenance tier was deleted counts as hand-checked
    assert labels_from_tiers(edited, [], {"confidence": tiers["confidence"]}).trust() is None


def _praat(script: str, *args: str, tmp: Path) -> None:
    (tmp / "s.praat").write_text(script)
    subprocess.run([PRAAT, "--run", str(tmp / "s.praat"), *args], check=True, timeout=60,
                   capture_output=True)


@pytest.mark.skipif(PRAAT is None, reason="Praat is not installed (apt-get install praat)")
@pytest.mark.parametrize("save", ["Save as text file", "Save as short text file"])
def test_the_record_survives_praat_and_so_do_corrections_made_in_it(tmp_path, save):
    write_labels(tmp_path / "a.TextGrid", aligned_labels(), 0.8)
    _praat(f'tg = Read from file: "{tmp_path}/a.TextGrid"\n{save}: "{tmp_path}/b.TextGrid"\n',
           tmp=tmp_path)
    same = read_label_file(tmp_path / "b.TextGrid", 16000, 0.8)
    assert same.provenance == Provenance("aligned", "PocketSphinx 5.1.1", "boy.txt", 0)
    np.testing.assert_allclose(same.confidence[:3], [0.819, 0.301, 0.607], atol=1e-9)
    # a phonetician corrects /b/ to /p/ in Praat (the phones tier is tier 2)
    _praat(f'tg = Read from file: "{tmp_path}/a.TextGrid"\nSet interval text: 2, 2, "p"\n'
           f'{save}: "{tmp_path}/c.TextGrid"\n', tmp=tmp_path)
    fixed = read_label_file(tmp_path / "c.TextGrid", 16000, 0.8)
    assert [s.label for s in fixed.phones] == ["sil", "p", "oy", "sil"]
    assert fixed.provenance.corrected == 1
    np.testing.assert_allclose(fixed.confidence[:3], [0.819, 1.0, 0.607], atol=1e-9)


def test_synth_says_which_mode_and_why(tmp_path, default_corpus, default_model, caplog):
    from facetraj.cli import main

    utt_id = default_corpus.info.test[0]
    utt = default_corpus.utterance(utt_id)
    audio = default_corpus.data_root / f"{utt_id}.flac"
    lab = Labels(list(utt.phones), [], "aligned", np.full(len(utt.phones), -4.0),
                 provenance=Provenance("aligned", "PocketSphinx 5.1.1"))
    write_labels(tmp_path / "aligned.TextGrid", lab, utt.duration)
    write_labels(tmp_path / "hand.TextGrid", Labels(list(utt.phones)), utt.duration)
    model = default_model.save(tmp_path / "model.npz")
    with caplog.at_level(logging.INFO, logger="facetraj"):
        for name in ("aligned", "hand"):
            assert main(["synth", str(model), str(audio), "--labels",
                         str(tmp_path / f"{name}.TextGrid"), "-o", str(tmp_path / f"{name}.tsv")]) == 0
            assert main(["synth", str(model), str(audio), "--labels",
                         str(tmp_path / f"{name}.TextGrid"), "--mode", "phonetic",
                         "-o", str(tmp_path / f"{name}-p.tsv")]) == 0
    said = [r.getMessage().split("; ")[1] for r in caplog.records if " mode: " in r.getMessage()]
    assert said[0] == "robust mode: aligned labels are not hand-checked"
    assert said[1] == "phonetic mode: chosen, although the labels are aligned"
    assert said[2] == "phonetic mode: hand-checked labels (the paper)"
    assert said[3] == "phonetic mode: chosen"
    robust = np.loadtxt(tmp_path / "aligned.tsv", skiprows=1)
    phonetic = np.loadtxt(tmp_path / "aligned-p.tsv", skiprows=1)
    assert np.abs(robust - phonetic).max() > 0.1                 # the mode made a difference
    np.testing.assert_allclose(phonetic, np.loadtxt(tmp_path / "hand-p.tsv", skiprows=1))
