"""The Live window in a real window (Xvfb): a file played through live mode, its take saved and
reopened; no input device gives the documented message, not a crash."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

from screens import colour_of, image_array, on_screen, place_in

from facetraj.cli import main
from facetraj_app import live, style
from facetraj_app.main import build_window
from facetraj_app.plotter_widget import grab_with_3d
from facetraj_engine.config import SynthConfig
from facetraj_engine.errors import FacetrajError
from facetraj_engine.io.audio import read_audio
from facetraj_engine.io.markerfiles import read_c3d
from facetraj_engine.method.pipeline import synthesize


@pytest.fixture
def utterance(default_corpus):
    utt = default_corpus.utterance(default_corpus.info.test[0])
    return utt.audio[: utt.sample_rate * 2], utt.sample_rate          # 2 s


def _image_std(image) -> float:
    ptr = image.constBits()
    ptr.setsize(image.sizeInBytes())
    return float(np.frombuffer(ptr, np.uint8).std())


def test_live_window_plays_a_file_and_its_take_reopens(qtbot, default_model, utterance, tmp_path):
    audio, rate = utterance
    window = live.LiveWindow(default_model, SynthConfig(closure=False), (audio, rate),
                             block_s=0.05, fast=True, phones=False)  # the search: equal to offline
    qtbot.addWidget(window)
    window.resize(1200, 700)
    window.show()
    qtbot.waitExposed(window)
    with qtbot.waitSignal(window.takeFinished, timeout=120_000):
        window.start()
    offline = synthesize(default_model, audio, rate, None, SynthConfig(mode="acoustic", closure=False))
    take_audio, take_rate, markers = window.take()
    assert take_rate == rate and len(take_audio) == len(audio)
    np.testing.assert_allclose(markers, offline.markers, atol=1e-9)       # streamed = offline
    assert window.updates > 1 and len(window.speech) == len(markers)
    assert 0 < sum(window.speech) < len(markers)                        # speech and pauses
    assert window.save_action.isEnabled() and "take:" in window.message.text()
    # the face moved to the last frame and the window shows something
    np.testing.assert_allclose(window.face.synth.current, offline.markers[-1])
    window.face.rerender()
    assert np.asarray(window.face.plotter.screenshot()).std() > 10
    assert _image_std(window.grab().toImage()) > 10
    # the picture saved (facetraj live --screenshot's) shows the face as the screen does (it was
    # black), and the lip panels the main window's colours with a legend of the speech dots
    qtbot.wait(200)
    view = window.face.plotter.interactor
    saved = place_in(image_array(grab_with_3d(window).toImage()), view, window).astype(float)
    assert saved.std() > 20
    assert np.abs(saved - on_screen(view).astype(float)).mean() < 6
    assert window.lines[0].get_color() == style.TRIANGULAR_COLOR
    assert window.dots[0].get_color() == style.SPEECH_DOT_COLOR
    legend = [t.get_text() for t in window.legend.get_texts()]        # above the panels
    assert legend == ["synthesized, triangular", "speech frames (live energy)",
                      "closed (the talker's /p b m/)"]
    # the take: WAV + C3D, reopened like any utterance's files
    path, wav = window.save_take(tmp_path / "take.c3d")
    back, back_rate = read_audio(wav)
    assert back_rate == rate and len(back) == len(audio)
    np.testing.assert_allclose(back, audio, atol=1 / 32767 + 1e-9)
    c3d = read_c3d(path)
    assert c3d.markers.shape == offline.markers.shape and c3d.rate == default_model.marker_rate
    np.testing.assert_allclose(c3d.markers, offline.markers, atol=0.05)
    qtbot.wait(50)                                      # the panels' last draw


def test_no_input_device_gives_the_message(qtbot, default_model, monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(live, "input_devices", lambda: [])
    window = live.LiveWindow(default_model)
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    qtbot.wait(50)                                      # its first draw, before it is deleted
    assert window.message.text() == live.NO_INPUT_DEVICE
    assert not window.start_action.isEnabled()
    assert window.phones.open_action.isEnabled()        # a recording can be played instead
    window.start()                                      # nothing to start: still the message
    assert window.message.text() == live.NO_INPUT_DEVICE and window.stream is None
    with pytest.raises(FacetrajError, match="no audio input device"):
        live.run_live(lambda: default_model)
    model_file = default_model.save(tmp_path / "m.npz")
    assert main(["-q", "live", "--model", str(model_file)]) == 2
    assert live.NO_INPUT_DEVICE_COMMAND in capsys.readouterr().err


def test_live_toggle_in_the_main_window(qtbot, default_corpus, trained_cache, monkeypatch):
    monkeypatch.setattr(live, "input_devices", lambda: [])
    window = build_window(default_corpus.root, use_audio=False)     # as users get it
    qtbot.addWidget(window)
    window.show()
    qtbot.waitUntil(lambda: window.model is not None and not window.busy, timeout=240_000)
    window.extension("live").action.setChecked(True)
    opened = [w for w in window.findChildren(live.LiveWindow)] or \
        [w for w in live.QApplication.topLevelWidgets() if isinstance(w, live.LiveWindow)]
    assert opened and opened[-1].isVisible()
    window.extension("live").action.setChecked(False)
    assert not opened[-1].isVisible()


def test_live_screenshot_command_saves_the_face(default_model, tmp_path, default_corpus):
    """``facetraj live --from-file ... --screenshot``: the face in the PNG, not black."""
    import subprocess
    import sys

    from facetraj_engine.io.corpus import audio_path

    model = default_model.save(tmp_path / "m.npz")
    out = tmp_path / "live.png"
    proc = subprocess.run([sys.executable, "-m", "facetraj", "-q", "live", "--model", str(model),
                           "--from-file", str(audio_path(default_corpus.root, "s002")),
                           "--as-fast-as-possible", "--screenshot", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    from PyQt6.QtGui import QImage

    img = image_array(QImage(str(out))).astype(float)
    left = img[:, : img.shape[1] // 2]
    skin = colour_of(style.SURFACE_COLOR)
    near = np.linalg.norm(left - skin, axis=2) < 60
    assert near.mean() > 0.1, "the face surface is missing from the saved picture"
