"""``facetraj live`` without a window: a file through the streaming path, written as a take."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from facetraj.cli import main
from facetraj_engine.config import SynthConfig
from facetraj_engine.io.audio import read_audio
from facetraj_engine.io.markerfiles import read_marker_table
from facetraj_engine.method.pipeline import synthesize


@pytest.fixture(scope="module")
def model_file(default_model, tmp_path_factory):
    return default_model.save(tmp_path_factory.mktemp("live") / "model.npz")


def test_live_from_file_writes_the_offline_synthesis(model_file, default_model, default_corpus,
                                                     tmp_path, capsys):
    wav = default_corpus.root / f"{default_corpus.info.test[0]}.flac"
    out = tmp_path / "take.tsv"
    assert main(["-q", "live", "--model", str(model_file), "--from-file", str(wav),
                 "--as-fast-as-possible", "--acoustic-only", "--no-closure", "-o", str(out)]) == 0
    assert capsys.readouterr().out.strip() == str(out)
    take = read_marker_table(out)
    audio, rate = read_audio(wav)
    offline = synthesize(default_model, audio, rate, None, SynthConfig(mode="acoustic", closure=False))
    assert take.markers.shape == offline.markers.shape
    np.testing.assert_allclose(take.markers, offline.markers, atol=0.006)   # TSV: 3 decimals
    assert not out.with_suffix(".TextGrid").exists()                      # no phones
    # the take exists: not replaced without --overwrite
    assert main(["-q", "live", "--model", str(model_file), "--from-file", str(wav),
                 "--as-fast-as-possible", "--acoustic-only", "-o", str(out)]) != 0


def test_live_acoustic_only_closes_the_lips_where_the_detector_finds_closures(
        model_file, default_model, default_corpus, tmp_path):
    """With --closure-detector the acoustic-only take closes the lips at the closures the model's
    detector finds, as ``facetraj synth --mode acoustic --closure-detector`` does: the take is
    the offline face (issue 46: both close and rest as a stream can); without it, the lips close
    nowhere and the face only rests in pauses, as offline."""
    from facetraj_engine.evaluation.closure import lip_aperture

    wav = default_corpus.root / f"{default_corpus.info.test[0]}.flac"
    audio, rate = read_audio(wav)
    for extra, cfg in ((["--closure-detector"], SynthConfig(mode="acoustic", closure_detector=True)),
                       ([], SynthConfig(mode="acoustic"))):
        out = tmp_path / f"take{len(extra)}.tsv"
        assert main(["-q", "live", "--model", str(model_file), "--from-file", str(wav),
                     "--as-fast-as-possible", "--acoustic-only", *extra, "-o", str(out)]) == 0
        take = read_marker_table(out)
        offline = synthesize(default_model, audio, rate, None, cfg)
        assert (len(offline.closure.intervals) >= 1) == bool(extra)
        a = lip_aperture(take.markers, default_model.upper_lip, default_model.lower_lip)
        b = lip_aperture(offline.markers, default_model.upper_lip, default_model.lower_lip)
        assert np.corrcoef(a, b)[0, 1] >= 0.99
        times = np.arange(len(a)) / default_model.marker_rate
        for t0, t1 in offline.closure.intervals:
            inside = (times >= t0) & (times < t1)
            assert a[inside].min() <= default_model.closure.closed + 0.5


def test_live_from_file_with_phones_writes_them_beside_the_take(model_file, default_model,
                                                                default_corpus, tmp_path, capsys):
    from facetraj_engine.io.labelfiles import read_label_file
    from facetraj_engine.streaming.live import stream_file

    wav = tmp_path / "u.flac"                # nothing beside it: phones recognized as spoken
    shutil.copy(default_corpus.root / f"{default_corpus.info.test[1]}.flac", wav)
    out = tmp_path / "take.tsv"
    assert main(["-q", "live", "--model", str(model_file), "--from-file", str(wav),
                 "--as-fast-as-possible", "--block-ms", "100", "-o", str(out)]) == 0
    audio, rate = read_audio(wav)
    take = read_marker_table(out)
    streamed = stream_file(default_model, audio, rate, 0.01)           # blocks do not matter
    np.testing.assert_allclose(take.markers, streamed.frames.markers, atol=0.006)
    labels = read_label_file(out.with_suffix(".TextGrid"), rate, len(audio) / rate)
    assert labels.provenance.kind == "recognized"
    assert [p.label for p in labels.phones] == [p.label for p in streamed.labels.phones]
    # the TextGrid is a take's file too: not replaced without --overwrite
    out.unlink()
    assert main(["-q", "live", "--model", str(model_file), "--from-file", str(wav),
                 "--as-fast-as-possible", "-o", str(out)]) == 2
    assert "take.TextGrid: already exists" in capsys.readouterr().err


@pytest.mark.parametrize("args, message", [
    (["-o", "x.tsv"], "add --from-file"),
    (["--from-file", "nothing.wav", "-o", "x.tsv"], "nothing.wav: no such audio file"),
    (["--smoothing", "none", "--from-file", "nothing.wav", "-o", "x.tsv"], "no such audio file"),
    (["--warp", "0.9", "--from-file", "nothing.wav", "-o", "x.tsv"], "add --acoustic-only"),
])
def test_live_bad_input_exit_2(args, message, model_file, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["-q", "live", "--model", str(model_file), *args]) == 2
    assert message in capsys.readouterr().err


def test_live_window_without_a_display_is_an_error_not_an_abort(model_file, default_corpus,
                                                                capsys, monkeypatch):
    for var in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"):
        monkeypatch.delenv(var, raising=False)
    wav = default_corpus.root / f"{default_corpus.info.test[0]}.flac"
    assert main(["-q", "live", "--model", str(model_file), "--from-file", str(wav)]) == 2
    assert "needs a display" in capsys.readouterr().err
    # the options are read first: a bad model is named before the display is looked for
    assert main(["-q", "live", "--model", "missing.npz", "--from-file", str(wav)]) == 2
    assert "missing.npz: no such model file" in capsys.readouterr().err


def test_live_benchmark_rows_and_section(toy_corpus_dir, tmp_path, monkeypatch):
    from benchmarks import live as bench
    from benchmarks.common import load_context

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    rows = bench.run(load_context(toy_corpus_dir, smoke=True))
    names = [r.name for r in rows]
    for mode in ("acoustic-only", "phones + acoustics"):
        k = names.index(f"latency sample -> face frame, {mode}, median")
        assert names[k + 1] == f"latency sample -> face frame, {mode}, 95th percentile"
        assert 0 < rows[k].value <= rows[k + 1].value
        assert all(r.value > 0 for r in rows[k + 2:k + 5]) and "speed" in names[k + 2]
    lat = {r.name: r.value for r in rows}
    assert lat["latency sample -> face frame, phones + acoustics, median"] > \
        lat["latency sample -> face frame, acoustic-only, median"]        # the phones' wait
    assert "skipped" in rows[-1].note                    # no display: no Live window
    doc = tmp_path / "bench.md"
    doc.write_text("# Benchmarks\n\ntable\n")
    bench.write_section(doc, rows)
    bench.write_section(doc, rows)                       # replaced, not appended twice
    text = doc.read_text()
    assert text.startswith("# Benchmarks\n\ntable\n") and text.count("## Live mode") == 1
