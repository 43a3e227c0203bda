"""``facetraj_engine.method.recording``: a recording's input LSFs analysed early (``EarlyLsf``), beside
the reading of the model's arrays and the labels, give the synthesis of the line-by-line path."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from facetraj_engine.io.audio import read_audio
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import frame_count
from facetraj_engine.method.recording import EarlyLsf, LabelRequest, synthesize_recording


@pytest.fixture(scope="module")
def model_file(toy_model, tmp_path_factory):
    return toy_model.save(tmp_path_factory.mktemp("rec") / "model.npz")


def test_the_early_lsfs_are_the_models_own(model_file, toy_corpus_dir):
    wav = toy_corpus_dir / "toy030.wav"
    early, (samples, rate) = EarlyLsf.start(model_file, wav)
    model = Model.load(model_file)
    times = np.arange(frame_count(len(samples), rate, model.marker_rate)) / model.marker_rate
    got = early.for_model(model)
    assert got is not None and got.shape == (len(times), model.config.lpc_order)
    np.testing.assert_array_equal(got, model.input_lsf(samples, rate, times))


def test_a_synthesis_with_them_equals_one_without(model_file, toy_corpus_dir):
    wav = toy_corpus_dir / "toy030.wav"
    model = Model.load(model_file)
    request = LabelRequest(labels=toy_corpus_dir / "toy030.TextGrid")
    early, samples = EarlyLsf.start(model_file, wav)
    with_early = synthesize_recording(model, wav, request=request, audio=samples, early=early)
    without = synthesize_recording(model, wav, request=request)
    for name, value in without.synthesis.arrays().items():
        np.testing.assert_array_equal(with_early.synthesis.arrays()[name], value, err_msg=name)
    np.testing.assert_array_equal(with_early.synthesis.markers, without.synthesis.markers)


def test_a_model_of_other_settings_gets_none(model_file, toy_corpus_dir):
    """The settings read first and the model's differ (the file was replaced between the two
    reads): the synthesis analyses the input itself, as without the early analysis."""
    early, _ = EarlyLsf.start(model_file, toy_corpus_dir / "toy030.wav")
    model = Model.load(model_file)
    other = dataclasses.replace(model, config=dataclasses.replace(model.config, window_s=0.03))
    assert early.for_model(other) is None
    assert early.for_model(model) is not None


def test_an_analysis_that_fails_gives_none(model_file, toy_corpus_dir, monkeypatch):
    import facetraj_engine.method.recording as recording

    def broken(*args, **kwargs):
        raise MemoryError("no room")

    monkeypatch.setattr(recording, "analysed_lsf", broken)
    samples, rate = read_audio(toy_corpus_dir / "toy030.wav")
    config, marker_rate = Model.read_settings(model_file)
    early = EarlyLsf(config, marker_rate, samples, rate)
    assert early.for_model(Model.load(model_file)) is None


def test_settings_of_a_bad_model_file_are_refused_naming_it(model_file, tmp_path):
    from facetraj_engine.errors import ModelFileError

    cut = tmp_path / "cut.npz"
    cut.write_bytes(model_file.read_bytes()[:5000])
    text = tmp_path / "text.npz"
    text.write_text("not a model")
    for bad in (cut, text, tmp_path / "missing.npz", tmp_path):
        with pytest.raises(ModelFileError) as err:
            Model.read_settings(bad)
        assert str(err.value).startswith(str(bad))
