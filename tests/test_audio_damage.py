"""Audio files checked against their own headers (issue 38): a file cut short, or whose header
does not match its data, is refused naming the audio file -- not the labels beside it -- unless
``--read-damaged-audio`` is given; a batch counts it as failed."""

from __future__ import annotations

import json
import logging
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from facetraj.cli import main
from facetraj_engine.errors import FILE_WARNINGS, InputError
from facetraj_engine.io.audio import DamagedAudioError, check_wav_header, read_audio

ROOT = Path(__file__).resolve().parent.parent
S001 = ROOT / "data_samples" / "s001.flac"     # 3.40 s, its TextGrid beside it


@pytest.fixture(scope="module")
def model_file(default_model, tmp_path_factory):
    return default_model.save(tmp_path_factory.mktemp("damage") / "model.npz")


@pytest.fixture
def wav(tmp_path) -> Path:
    """s001 as a 16-bit WAV with its TextGrid beside it."""
    x, rate = sf.read(S001)
    path = tmp_path / "s001.wav"
    sf.write(path, x, rate, subtype="PCM_16")
    shutil.copy(S001.with_suffix(".TextGrid"), tmp_path / "s001.TextGrid")
    return path


def test_a_wav_cut_short_is_refused_naming_the_audio(wav, model_file, tmp_path, capsys):
    wav.write_bytes(wav.read_bytes()[:3000])
    code = main(["synth", str(model_file), str(wav), "-o", str(tmp_path / "o.tsv")])
    err = capsys.readouterr().err
    assert code == 2 and not (tmp_path / "o.tsv").exists()
    assert err.splitlines() == [
        f"facetraj: error: {wav}: the audio file is cut short: its header says 3.400 s (54397 "
        f"samples), the file holds 0.092 s (1478 samples); read what it holds anyway with "
        f"--read-damaged-audio"]
    assert "TextGrid" not in err                  # the labels beside it are not blamed


def test_read_damaged_audio_reads_what_there_is(wav, tmp_path, caplog):
    wav.write_bytes(wav.read_bytes()[:20000])
    FILE_WARNINGS.clear()
    with caplog.at_level(logging.WARNING):
        audio, rate = read_audio(wav, allow_damaged=True)
    assert len(audio) == (20000 - 44) // 2 and rate == 16000
    assert "its 0.624 s read as they are (--read-damaged-audio)" in caplog.text
    full, _ = sf.read(S001)
    assert np.allclose(audio, full[:len(audio)], atol=1 / 32768)


def test_a_flac_cut_short_says_where_decoding_stopped(tmp_path):
    flac = tmp_path / "cut.flac"
    flac.write_bytes(S001.read_bytes()[:40000])
    with pytest.raises(DamagedAudioError) as err:
        read_audio(flac)
    assert str(err.value).startswith(f"{flac}: the audio file is cut short: its header says "
                                     "3.400 s (54397 samples), the file holds ")
    assert "decoding stopped" in str(err.value)


@pytest.mark.parametrize("offset, value, phrase", [
    (40, 10 ** 9, "the audio file is cut short: its header says 31250.000 s"),       # data size
    (40, 1000, "the bytes at offset 1044 are not a chunk"),              # data size, smaller
    (4, 100, "its 'data' chunk ends at byte"),                           # RIFF size, smaller
    (28, 1, "but a block of 2 bytes and 1 bytes per second"),            # byte rate
    (22, 3, "says 3 channel(s) of 16 bits"),                             # channels
])
def test_a_header_that_does_not_match_the_data_is_named(wav, offset, value, phrase):
    data = bytearray(wav.read_bytes())
    data[offset:offset + (2 if offset == 22 else 4)] = struct.pack("<H" if offset == 22 else "<I",
                                                                     value)
    wav.write_bytes(bytes(data))
    problem = check_wav_header(wav)
    assert problem is not None and phrase in problem, problem
    with pytest.raises(InputError, match=str(wav)):
        read_audio(wav)


def test_healthy_files_are_read_as_before(tmp_path):
    x, rate = sf.read(S001)
    for subtype in ("PCM_16", "PCM_24", "FLOAT", "DOUBLE", "ULAW", "ALAW", "PCM_U8"):
        path = tmp_path / f"{subtype}.wav"
        sf.write(path, x, rate, subtype=subtype)
        assert check_wav_header(path) is None, subtype
        assert np.array_equal(read_audio(path)[0], sf.read(path)[0]), subtype
    assert check_wav_header(S001) is None and len(read_audio(S001)[0]) == len(x)


def test_a_batch_counts_damaged_audio_as_failed(wav, model_file, tmp_path, capsys):
    folder = wav.parent
    good = folder / "good.wav"
    shutil.copy(wav, good)
    shutil.copy(S001.with_suffix(".TextGrid"), folder / "good.TextGrid")
    wav.write_bytes(wav.read_bytes()[:3000])                      # the case issue 38 found
    out = tmp_path / "out"
    code = main(["synth", str(model_file), str(folder), "-o", str(out), "--format", "tsv",
                 "-j", "2"])
    err = capsys.readouterr().err
    assert code == 2
    summary = json.loads((out / "synth-summary.json").read_text())
    assert (summary["done"], summary["failed"]) == (1, 1)
    failed = next(o for o in summary["inputs"] if o["status"] == "failed")
    assert failed["input"] == str(wav) and failed["reason"].startswith(
        f"{wav}: the audio file is cut short")
    assert f"facetraj: failed: {wav}: the audio file is cut short" in err
    assert not (out / "s001.tsv").exists() and (out / "good.tsv").is_file()


@pytest.mark.parametrize("kind", ["wav", "flac"])
def test_a_header_with_the_wrong_rate_is_named_beside_the_labels(wav, model_file, tmp_path, kind,
                                                                 capsys):
    """A header that is consistent in itself but gives half the rate (the audio lasts twice as
    long as its labels, issue 46): the message blames the audio, with the rate and samples its
    header gives, names its labels, and the rate at which they would fit; labels that fit no
    common rate are blamed themselves, naming the audio."""
    if kind == "wav":
        data = bytearray(wav.read_bytes())
        data[24:32] = struct.pack("<II", 8000, 16000)      # rate and byte rate, consistently
        wav.write_bytes(bytes(data))
        audio = wav
    else:
        audio = wav.with_suffix(".flac")
        sf.write(audio, sf.read(S001)[0], 8000)
        wav.unlink()
    code = main(["synth", str(model_file), str(audio), "-o", str(tmp_path / "o.tsv")])
    err = capsys.readouterr().err
    assert code == 2 and not (tmp_path / "o.tsv").exists()
    assert err.splitlines() == [
        f"facetraj: error: {audio}: lasts 6.800 s by its header (54397 samples at 8000 Hz) but its "
        f"labels s001.TextGrid end at 3.400 s; at 16000 Hz it would last 3.400 s, as the labels "
        f"do: is the rate in its header wrong?"]
    lab = tmp_path / "other.lab"                       # labels of another length: blamed
    lab.write_text("0.0 2.0 sil\n2.0 5.1 aa\n")
    assert main(["synth", str(model_file), str(audio), "--labels", str(lab), "-o",
                 str(tmp_path / "o.tsv")]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [
        f"facetraj: error: {lab}: labels end at 5.100 s but the audio {audio.name} lasts 6.800 s "
        f"by its header (54397 samples at 8000 Hz)"]
