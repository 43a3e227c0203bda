"""Label files in other phone alphabets (facetraj_engine.labels.alphabets): recognised and mapped onto
ARPAbet for synthesis and corpora; labels in no alphabet are an error naming them and the option
that fixes it (--label-map)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from conftest import MOCHA

from facetraj_engine.errors import InputError
from facetraj_engine.io.labelfiles import read_label_file, read_labels
from facetraj_engine.labels.alphabets import ALPHABETS, detect, to_arpabet
from facetraj_engine.labels.labelmap import read_label_map
from facetraj.cli import main

#: the toy corpus's phones written in each alphabet (silence as that alphabet writes it)
TOY_IN = {
    "ARPAbet": {"sil": "sp", "aa": "AA1", "iy": "IY0", "uw": "UW2", "m": "M", "f": "F", "s": "S",
                "t": "T"},
    "TIMIT": {"sil": "h#", "aa": "aa", "iy": "iy", "uw": "uw", "m": "m", "f": "f", "s": "s",
              "t": "tcl"},
    "MOCHA-TIMIT": {"sil": "breath", "aa": "aa", "iy": "ii", "uw": "uu", "m": "m", "f": "f",
                    "s": "s", "t": "t"},
    "SAMPA": {"sil": "sil", "aa": "A:", "iy": "i:", "uw": "u:", "m": "m", "f": "f", "s": "s",
              "t": "t"},
    "IPA": {"sil": "sil", "aa": "\u0251\u02d0", "iy": "i\u02d0", "uw": "\u02c8u\u02d0", "m": "m",
            "f": "f", "s": "s", "t": "t"},
}


@pytest.mark.parametrize("labels, name", [
    (["sil", "DH", "AH0", "B", "OY1", "IH0", "N", "JH", "OY1", "D"], "ARPAbet"),
    (["h#", "dh", "ax", "bcl", "b", "oy", "q", "epi", "dx"], "TIMIT"),
    (["sil", "breath", "dh", "i", "s", "w", "@", "z", "ii", "iy", "uh"], "MOCHA-TIMIT"),
    (["D", "@", "b", "OI", "I", "n", "dZ", "OI", "d", "{", "V"], "SAMPA"),
    (["D", "@", "b", "OI", "r\\", "@`", "4", "{"], "X-SAMPA"),
    (["\u00f0", "\u0259", "b", "\u02c8\u0254\u026a", "t\u0361\u0283", "\u00e6", "n\u0329",
      "\u0279"], "IPA"),
])
def test_each_alphabet_is_recognised(labels, name):
    found = detect(labels)
    assert found.alphabet.name == name and found.unknown == []


def test_every_alphabet_maps_onto_arpabet_phones():
    from facetraj_engine.labels.phoneset import ARPABET, FALLBACK, SILENCE

    allowed = set(ARPABET) | {SILENCE} | set(FALLBACK)   # extended symbols fall back per model
    for a in ALPHABETS:
        assert set(a.table.values()) <= allowed, a.name


def _toy_lab(src, path, alphabet: str) -> None:
    table = TOY_IN[alphabet]
    path.write_text("".join(f"{s.start:.4f} {s.end:.4f} {table[s.label]}\n"
                            for s in read_labels(src)), encoding="utf-8")


@pytest.mark.parametrize("alphabet", list(TOY_IN))
def test_label_files_in_other_alphabets_synthesize_as_arpabet(alphabet, toy_corpus_dir, toy_model,
                                                              tmp_path, capsys):
    """The same phones written in each alphabet: the same trajectories as the ARPAbet original,
    from the command line, with the label file given and beside the audio."""
    toy_model.save(tmp_path / "m.npz")
    tg = toy_corpus_dir / "toy030.TextGrid"
    ref = tmp_path / "ref.tsv"
    assert main(["synth", str(tmp_path / "m.npz"), str(toy_corpus_dir / "toy030.wav"), "--labels",
                 str(tg), "-o", str(ref), "--mode", "phonetic", "-q"]) == 0
    lab = tmp_path / f"{alphabet}.lab"
    _toy_lab(tg, lab, alphabet)
    got = read_label_file(lab, 16000, read_labels(tg)[-1].end)
    assert [s.label.lower().rstrip("012") for s in got.phones] == \
        [s.label if s.label != "sil" else got.phones[i].label.lower()
         for i, s in enumerate(read_labels(tg))]
    out = tmp_path / "out.tsv"
    code = main(["synth", str(tmp_path / "m.npz"), str(toy_corpus_dir / "toy030.wav"), "--labels",
                 str(lab), "-o", str(out), "--mode", "phonetic", "-q"])
    assert code == 0, capsys.readouterr().err
    assert out.read_text() == ref.read_text()
    beside = tmp_path / "beside"                    # the label file beside the audio
    beside.mkdir()
    shutil.copy(toy_corpus_dir / "toy030.wav", beside / "u.wav")
    shutil.copy(lab, beside / "u.lab")
    assert main(["synth", str(tmp_path / "m.npz"), str(beside / "u.wav"), "-o",
                 str(beside / "o.tsv"), "--mode", "phonetic", "-q"]) == 0
    assert (beside / "o.tsv").read_text() == ref.read_text()


def test_unknown_labels_are_an_error_naming_them_and_the_fix(toy_corpus_dir, toy_model, tmp_path,
                                                            capsys):
    """Unknown labels are refused (never synthesized as something else), naming each label, where
    it first appears and --label-map; with a label map for them the file synthesizes."""
    toy_model.save(tmp_path / "m.npz")
    segs = read_labels(toy_corpus_dir / "toy030.TextGrid")
    odd = {"aa": "vowel-A", "iy": "vowel-I"}
    lab = tmp_path / "own.lab"
    lab.write_text("".join(f"{s.start:.4f} {s.end:.4f} {odd.get(s.label, s.label)}\n"
                           for s in segs))
    out = tmp_path / "o.tsv"
    argv = ["synth", str(tmp_path / "m.npz"), str(toy_corpus_dir / "toy030.wav"), "--labels",
            str(lab), "-o", str(out), "--mode", "phonetic"]
    assert main([*argv, "-q"]) == 2
    err = capsys.readouterr().err
    first = next(s for s in read_labels(lab) if s.label in odd.values())
    assert f"facetraj: error: {lab}: labels in no phone alphabet facetraj knows: " \
           f"'{first.label}' (at {first.start:.3f} s)" in err
    assert "(the closest, ARPAbet, knows" in err and "--label-map FILE" in err
    assert not out.exists()
    (tmp_path / "map.tsv").write_text("vowel-A\taa\nvowel-I\tiy\n")
    assert main([*argv, "--label-map", str(tmp_path / "map.tsv"), "-q"]) == 0


def test_named_alphabet_as_label_map():
    m = read_label_map("sampa")
    assert m.get("{") == "ae" and m.get('"i:') == "iy" and "V" in m and "zz" not in m
    assert read_label_map("IPA").get("\u02c8\u028c") == "ah"


def test_corpus_labels_in_another_alphabet(toy_corpus_dir, tmp_path):
    from facetraj_engine.io.corpus import load_corpus

    root = tmp_path / "c"
    shutil.copytree(toy_corpus_dir, root)
    want = load_corpus(root).utterance("toy030").phones
    _toy_lab(root / "toy030.TextGrid", root / "toy030.lab", "SAMPA")
    (root / "toy030.TextGrid").unlink()
    got = load_corpus(root).utterance("toy030").phones
    assert [s.label for s in got] == [s.label for s in want]
    np.testing.assert_allclose([s.end for s in got], [s.end for s in want], atol=1e-4)
    (root / "toy030.lab").write_text((root / "toy030.lab").read_text().replace("A:", "zz"))
    with pytest.raises(InputError, match=r"toy030\.lab: labels in no phone alphabet .* 'zz'"):
        load_corpus(root).utterance("toy030")


def test_to_arpabet_leaves_arpabet_alone():
    from facetraj_engine.data import PhoneSegment

    segs = [PhoneSegment(0, 1, "sil"), PhoneSegment(1, 2, "AH0"), PhoneSegment(2, 3, "ax")]
    assert to_arpabet(segs, "x.lab") == segs


@pytest.mark.skipif(not (MOCHA / "fsew0_001.wav").is_file(),
                    reason="the MOCHA-TIMIT sample is not in ../shared")
def test_mocha_sample_synthesizes_with_the_lab_beside_it(default_model, tmp_path, capsys):
    """Issue 26: ``facetraj synth MODEL fsew0_001.wav -o out.tsv`` read the MOCHA .lab beside the
    audio and failed on its first MOCHA phone; now the phones are mapped, as --label-map mocha
    would map them (read from ../shared, never copied)."""
    model = default_model.save(tmp_path / "m.npz")
    out, forced = tmp_path / "out.tsv", tmp_path / "forced.tsv"
    argv = ["synth", str(model), str(MOCHA / "fsew0_001.wav"), "--mode", "phonetic", "-q"]
    assert main([*argv, "-o", str(out)]) == 0, capsys.readouterr().err
    assert main([*argv, "-o", str(forced), "--label-map", "mocha"]) == 0
    assert out.read_text() == forced.read_text()
    phones = read_label_file(MOCHA / "fsew0_001.lab", 16000, 2.2).phones
    assert [s.label for s in phones[3:7]] == ["dh", "ih", "s", "w"]     # dh i s w
