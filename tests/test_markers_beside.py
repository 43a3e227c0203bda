"""The marker file beside a recording (facetraj_engine.io.markers_beside): read as its original
when it holds the model's marker set, fitted to the audio like a corpus utterance's; otherwise
what it holds is said; a damaged one is an error naming it."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from facetraj.paths import shared_path
from facetraj_engine.errors import InputError
from facetraj_engine.io.markerfiles import write_marker_tsv
from facetraj_engine.io.markers_beside import marker_file_beside, read_markers_beside


def test_the_corpus_markers_beside_its_audio(default_corpus, default_model):
    utt = default_corpus.utterance("s002")
    audio = default_corpus.root / "s002.flac"
    assert marker_file_beside(audio).name == "s002.c3d"
    got = read_markers_beside(audio, default_model.marker_names, default_model.marker_rate,
                              utt.duration)
    assert got.usable and got.names == list(default_model.marker_names)
    assert got.markers.shape == utt.markers.shape
    np.testing.assert_allclose(got.markers, utt.markers, equal_nan=True)


def test_other_markers_are_named_and_a_damaged_file_is_an_error(default_corpus, default_model,
                                                               tmp_path):
    audio = tmp_path / "take.flac"
    shutil.copy(default_corpus.root / "s002.flac", audio)
    assert read_markers_beside(audio, default_model.marker_names, 60.0, 2.0) is None
    write_marker_tsv(tmp_path / "take.tsv", np.zeros((30, 2, 3)), 60.0, ["JAW", "TT"])
    got = read_markers_beside(audio, default_model.marker_names, 60.0, 2.0)
    assert not got.usable and got.names == ["JAW", "TT"]
    assert "JAW" in got.hint("take.flac") and "Import your own recordings" in got.hint("take.flac")
    (tmp_path / "take.tsv").unlink()
    (tmp_path / "take.c3d").write_bytes(b"\x02P not a c3d file at all")
    with pytest.raises(InputError, match="take.c3d"):
        read_markers_beside(audio, default_model.marker_names, 60.0, 2.0)


def test_mocha_ema_beside_its_wav_is_not_the_face_models(default_model):
    wav = shared_path("data/mocha_fsew0_001/fsew0_001.wav")
    if not wav.exists():
        pytest.skip("the MOCHA-TIMIT sample is not in ../shared")
    got = read_markers_beside(wav, default_model.marker_names, default_model.marker_rate, 2.2)
    assert got.path.name == "fsew0_001.ema" and not got.usable
    assert {"UL", "LL", "LI"} <= set(got.names)
    again = read_markers_beside(wav, got.names, 60.0, 2.2)          # a MOCHA model's marker set
    assert again.usable and again.markers.shape[0] == int(2.2 * 60) + 1
    assert np.isnan(again.markers[-1]).all()                      # the .ema ends at 1.93 s
