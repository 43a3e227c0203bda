"""The Live window's phones (issue 27) in a real window (Xvfb): a recording opened from the window
plays with phones recognized as they are spoken (the tier, the voice match, the latency), its take
keeps them as a TextGrid; a device that disappears ends the take with a message and keeps it; a
bad file is a message."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")
pytest.importorskip("pocketsphinx")

from facetraj_app import live
from facetraj_app.live_input import InputLost, decode_pcm
from facetraj_app.live_phones import ACOUSTIC, PHONES
from facetraj_engine.io.audio import read_audio, write_audio
from facetraj_engine.io.labelfiles import read_label_file


@pytest.fixture
def recording(default_corpus, tmp_path):
    utt = default_corpus.utterance(default_corpus.info.test[1])
    path = tmp_path / "speech.wav"
    write_audio(path, utt.audio, utt.sample_rate)
    return path


def _window(qtbot, model, monkeypatch, **kw):
    monkeypatch.setattr(live, "input_devices", lambda: [])
    window = live.LiveWindow(model, block_s=0.05, fast=True, **kw)
    qtbot.addWidget(window)
    window.resize(1200, 700)
    window.show()
    qtbot.waitExposed(window)
    return window


def test_a_recording_opened_in_the_window_plays_with_its_phones(qtbot, default_model, recording,
                                                                monkeypatch, tmp_path):
    window = _window(qtbot, default_model, monkeypatch)
    assert window.phones.switch.currentText() == PHONES
    with qtbot.waitSignal(window.takeFinished, timeout=180_000):
        assert window.open_recording(recording)
        assert not window.phones.switch.isEnabled()          # the mode is the take's
    assert window.phones.switch.isEnabled()
    audio, rate = read_audio(recording)
    _, take_rate, markers = window.take()
    assert take_rate == rate and len(markers) == int(np.floor(len(audio) / rate * 60)) + 1
    # the tier shows the last phones, the status bar the voice and the latency
    boxes = window.phones.tier.view.boxes
    assert len(boxes) > 5 and all(0 <= b[0] < b[1] <= 1 for b in boxes)
    assert "voice match" in window.phones.voice_label.text()
    assert "latency" in window.phones.latency_label.text()
    assert window.grab().toImage().width() > 0
    # the take: WAV, C3D and the phones as a TextGrid with their provenance
    out, wav = window.save_take(tmp_path / "take.c3d")
    assert out.exists() and wav.exists()
    grid = tmp_path / "take.TextGrid"
    labels = read_label_file(grid, rate, len(audio) / rate)
    assert labels.provenance.kind == "recognized" and labels.trust() is not None
    assert sum(p.label != "sil" for p in labels.phones) > 10
    assert "TextGrid" in window.message.text()
    qtbot.wait(50)


def test_acoustic_only_take_has_no_phones(qtbot, default_model, recording, monkeypatch, tmp_path):
    window = _window(qtbot, default_model, monkeypatch, phones=False)
    assert window.phones.switch.currentText() == ACOUSTIC
    with qtbot.waitSignal(window.takeFinished, timeout=180_000):
        window.open_recording(recording)
    window.save_take(tmp_path / "take.tsv")
    assert not (tmp_path / "take.TextGrid").exists()
    assert "acoustic-only" in window.phones.voice_label.text()
    qtbot.wait(50)


def test_a_device_that_disappears_ends_the_take_and_keeps_it(qtbot, default_model, recording,
                                                             monkeypatch):
    window = _window(qtbot, default_model, monkeypatch)

    class Vanishing(live.FileFeeder):
        """A file that plays for 0.6 s, then its device is gone."""

        def poll(self):
            if self.pos >= int(0.6 * self.rate):
                raise InputLost("USB microphone was disconnected")
            return super().poll()

    monkeypatch.setattr(live, "FileFeeder", Vanishing)
    with qtbot.waitSignal(window.takeFinished, timeout=120_000):
        window.open_recording(recording)
    text = window.message.text()
    assert "disconnected" in text and "kept" in text and "take:" in text
    assert window.n_frames >= 30 and window.save_action.isEnabled()
    qtbot.wait(50)


def test_a_bad_recording_is_a_message(qtbot, default_model, monkeypatch, tmp_path):
    window = _window(qtbot, default_model, monkeypatch)
    bad = tmp_path / "noise.wav"
    bad.write_bytes(b"RIFF not really a wave file")
    assert not window.open_recording(bad)
    assert "could not open the recording" in window.message.text() and "noise.wav" in \
        window.message.text()
    assert window.stream is None
    qtbot.wait(50)


def test_any_device_format_becomes_mono_floats():
    stereo = np.array([[1000, -1000], [32767, 32767]], "<i2").tobytes()
    np.testing.assert_allclose(decode_pcm(stereo, "Int16", 2), [0.0, 32767 / 32768])
    x = np.array([0.5, -2.0, np.nan], "<f4").tobytes()                  # out of range, NaN
    assert decode_pcm(x, "Float", 1).tolist() == [0.5, -1.0, 0.0]
    assert decode_pcm(np.array([2 ** 30], "<i4").tobytes() + b"\x01", "Int32", 1).tolist() == [0.5]


class _Device:
    """A device that records only in its own format: 48 kHz stereo float."""

    def isFormatSupported(self, fmt):
        return False

    def preferredFormat(self):
        from PyQt6.QtMultimedia import QAudioFormat

        fmt = QAudioFormat()
        fmt.setSampleRate(48000)
        fmt.setChannelCount(2)
        fmt.setSampleFormat(QAudioFormat.SampleFormat.Float)
        return fmt

    def description(self):
        return "USB headset"

    def id(self):
        return b"usb"


def test_a_device_with_another_rate_records_in_its_own_format():
    from facetraj_app.live_input import capture_format

    fmt = capture_format(_Device())
    assert (fmt.sampleRate(), fmt.channelCount(), fmt.sampleFormat().name) == (48000, 2, "Float")


def test_a_source_that_stops_with_an_error_is_a_lost_input():
    from PyQt6.QtMultimedia import QtAudio

    from facetraj_app.live_input import MicFeeder

    class Source:
        def __init__(self):
            self.err, self.st = QtAudio.Error.NoError, QtAudio.State.ActiveState

        def error(self):
            return self.err

        def state(self):
            return self.st

    class Io:
        def readAll(self):
            return np.array([0.5, -0.5, 0.25, 0.25], "<f4").tobytes()

    feeder = object.__new__(MicFeeder)          # as MicFeeder(device) makes it, without a device
    feeder.device, feeder.source, feeder.io = _Device(), Source(), Io()
    feeder.rate, feeder.channels, feeder.sample_format, feeder._quiet_polls = 48000, 2, "Float", 0
    assert feeder.poll().tolist() == [0.0, 0.25]
    feeder.source.err = QtAudio.Error.IOError
    with pytest.raises(InputLost, match="USB headset stopped delivering audio"):
        feeder.poll()


def test_clipped_input_is_said_and_the_take_goes_on(qtbot, default_model, monkeypatch, tmp_path):
    window = _window(qtbot, default_model, monkeypatch)
    rate = 16000
    t = np.arange(4 * rate) / rate
    path = tmp_path / "clipped.wav"
    write_audio(path, np.clip(3 * np.sin(2 * np.pi * 200 * t), -1, 1), rate)
    window.open_recording(path)
    qtbot.waitUntil(lambda: "clipping" in window.message.text(), timeout=60_000)
    with qtbot.waitSignal(window.takeFinished, timeout=120_000):
        pass
    assert window.n_frames == 4 * 60 + 1
    qtbot.wait(50)
