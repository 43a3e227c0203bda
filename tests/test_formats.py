"""Readers and writers, and the errors they give on bad input (each names the file)."""

import logging

import numpy as np
import pytest
import soundfile as sf

from facetraj_engine.data import PhoneSegment
from facetraj_engine.errors import InputError
from facetraj_engine.io.audio import read_audio, write_audio
from facetraj_engine.io.corpus import CorpusInfo, load_corpus, save_corpus_info
from facetraj_engine.io.files import atomic_write
from facetraj_engine.io.labelfiles import (
    read_lab,
    read_labels,
    read_phn,
    read_textgrid,
    validate_phones,
    write_textgrid,
)
from facetraj_engine.io.markerfiles import read_c3d, read_marker_table, write_c3d, write_marker_tsv


def test_audio_round_trip_and_stereo_mixdown(tmp_path, caplog):
    x = 0.5 * np.sin(np.arange(8000) / 7.0)
    write_audio(tmp_path / "a.flac", x, 16000)
    y, rate = read_audio(tmp_path / "a.flac")
    assert rate == 16000 and np.abs(y - x).max() < 1e-4
    sf.write(tmp_path / "st.wav", np.stack([x, -x * 0 + 0.2], axis=1), 16000)
    with caplog.at_level(logging.WARNING):
        y, _ = read_audio(tmp_path / "st.wav")
    assert "2 channels mixed down" in caplog.text and "st.wav" in caplog.text
    np.testing.assert_allclose(y, (x + 0.2) / 2, atol=1e-4)


@pytest.mark.parametrize("case, message", [
    ("missing", "no such audio file"),
    ("empty", "empty"),
    ("corrupt", "cannot read audio"),
    ("low_rate", "below the 8000 Hz minimum"),
    ("no_samples", "no samples"),
    ("nan_float", "NaN or infinite samples"),
    ("inf_double", "NaN or infinite samples"),
])
def test_bad_audio(tmp_path, case, message):
    p = tmp_path / f"{case}.wav"
    if case == "empty":
        p.write_bytes(b"")
    elif case == "corrupt":
        p.write_bytes(b"RIFF\x00\x00\x00\x00WAVEfmt garbage" * 3)
    elif case == "low_rate":
        sf.write(p, np.zeros(400), 4000)
    elif case == "no_samples":
        sf.write(p, np.zeros(0), 16000)
    elif case in ("nan_float", "inf_double"):       # float encodings are checked (whole: need not)
        x = np.zeros(1600)
        x[700] = np.nan if case == "nan_float" else np.inf
        sf.write(p, x, 16000, subtype="FLOAT" if case == "nan_float" else "DOUBLE")
    with pytest.raises(InputError, match=message) as err:
        read_audio(p)
    assert str(p) in str(err.value)


def test_textgrid_round_trip(tmp_path):
    phones = [PhoneSegment(0, 0.3, "sil"), PhoneSegment(0.3, 0.41, "t"), PhoneSegment(0.41, 1.0, "aa")]
    write_textgrid(tmp_path / "u.TextGrid", {"words": [PhoneSegment(0.3, 1.0, "ta")],
                                            "phones": phones}, 1.0)
    assert read_textgrid(tmp_path / "u.TextGrid") == phones
    with pytest.raises(InputError, match="no interval tier named 'segments'"):
        read_textgrid(tmp_path / "u.TextGrid", "segments")


def test_label_formats(tmp_path):
    (tmp_path / "h.lab").write_text("0 3000000 sil\n3000000 4100000 t\n4100000 10000000 aa\n")
    assert read_lab(tmp_path / "h.lab")[1] == PhoneSegment(0.3, 0.41, "t")
    (tmp_path / "m.lab").write_text("0 0.25 sil\n0.25 0.28 breath\n")
    assert read_lab(tmp_path / "m.lab")[1] == PhoneSegment(0.25, 0.28, "breath")
    (tmp_path / "t.phn").write_text("0 4800 h#\n4800 6560 t\n")
    assert read_phn(tmp_path / "t.phn") == [PhoneSegment(0, 0.3, "sil"), PhoneSegment(0.3, 0.41, "t")]
    (tmp_path / "x.phones").write_text("")
    with pytest.raises(InputError, match="unknown label format"):
        read_labels(tmp_path / "x.phones")
    (tmp_path / "bad.lab").write_bytes("0 1 \xe9\n".encode("latin-1") + b"\xff\xfe\xfa")
    with pytest.raises(InputError, match="not UTF-8"):
        read_lab(tmp_path / "bad.lab")


def test_validate_phones():
    ok = validate_phones([PhoneSegment(0.01, 0.5, "a"), PhoneSegment(0.6, 1.0, "b")], 1.0, "l.lab")
    assert [s.label for s in ok] == ["a", "sil", "b"] and ok[0].start == 0.0
    with pytest.raises(InputError, match="l.lab: segment 2 .* overlaps"):
        validate_phones([PhoneSegment(0, 0.5, "a"), PhoneSegment(0.4, 1.0, "b")], 1.0, "l.lab")
    with pytest.raises(InputError, match="labels end at 1.000 s but the audio lasts 2.000 s"):
        validate_phones([PhoneSegment(0, 1.0, "a")], 2.0, "l.lab")
    with pytest.raises(InputError, match="not after its start"):
        validate_phones([PhoneSegment(0, 0.0, "a"), PhoneSegment(0, 1, "b")], 1.0, "l.lab")
    with pytest.raises(InputError, match="no segments"):
        validate_phones([], 1.0, "l.lab")


def test_c3d_round_trip_with_gaps(tmp_path):
    rng = np.random.default_rng(0)
    m = rng.standard_normal((30, 5, 3)) * 50
    m[4:6, 2] = np.nan
    names = [f"M{i}" for i in range(5)]
    write_c3d(tmp_path / "a.c3d", m, 60.0, names)
    back = read_c3d(tmp_path / "a.c3d")
    assert back.names == names and back.rate == 60.0
    assert np.array_equal(np.isnan(back.markers), np.isnan(m))
    assert np.nanmax(np.abs(back.markers - m)) <= 0.0051        # integer C3D: 0.01 mm steps
    write_c3d(tmp_path / "b.c3d", m * 100, 60.0, names)          # beyond int16 range: float form
    assert np.nanmax(np.abs(read_c3d(tmp_path / "b.c3d").markers - m * 100)) < 1e-2
    (tmp_path / "bad.c3d").write_bytes(b"not a c3d file at all" * 10)
    with pytest.raises(InputError, match="bad.c3d"):
        read_c3d(tmp_path / "bad.c3d")


def test_marker_tsv_round_trip(tmp_path):
    m = np.arange(2 * 3 * 3, dtype=float).reshape(2, 3, 3)
    write_marker_tsv(tmp_path / "m.tsv", m, 60.0, ["a", "b", "c"])
    back = read_marker_table(tmp_path / "m.tsv")
    assert back.names == ["a", "b", "c"] and back.rate == pytest.approx(60.0)
    np.testing.assert_allclose(back.markers, m)
    (tmp_path / "two_d.csv").write_text("time,UL_x,UL_y\n0,1,2\n0.002,1,3\n")
    d2 = read_marker_table(tmp_path / "two_d.csv")
    assert d2.rate == pytest.approx(500) and d2.markers[1, 0].tolist() == [1, 3, 0]


def test_atomic_write_keeps_old_file_on_failure(tmp_path):
    target = tmp_path / "model.npz"
    target.write_text("precious")
    with pytest.raises(RuntimeError), atomic_write(target) as tmp:
        tmp.write_text("half-writ")
        raise RuntimeError("disk full")
    assert target.read_text() == "precious"
    assert list(tmp_path.iterdir()) == [target]
    with pytest.raises(FileExistsError, match="already exists"), atomic_write(target, overwrite=False):
        pass


def test_corpus_errors(tmp_path, toy_corpus_dir):
    with pytest.raises(InputError, match="no corpus.json"):
        load_corpus(tmp_path)
    (tmp_path / "corpus.json").write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        load_corpus(tmp_path)
    info = load_corpus(toy_corpus_dir).info
    bad = CorpusInfo(**{**info.__dict__, "upper_lip": "NOPE"})
    d = tmp_path / "c2"
    d.mkdir()
    save_corpus_info(d, bad)
    with pytest.raises(InputError, match="marker 'NOPE' is not among marker_names"):
        load_corpus(d)
