"""Opening a recording in the app (real window under Xvfb): the sentence is aligned in a worker and
the phone tier shows the aligned labels; the label source switches to recognized and to none; a
missing word is asked for; a wrong sentence is refused with a message."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from PyQt6.QtWidgets import QDialog, QFileDialog, QMessageBox
from screens import opened_window

from facetraj.paths import default_corpus
from facetraj_app.main import build_window
from facetraj_app.open_audio import MissingWordsDialog, SentenceDialog

pytestmark = pytest.mark.gui

ROOT = Path(__file__).resolve().parent.parent
CLIP = ROOT / "data_samples" / "s002.flac"          # "The boy enjoyed the noisy toy."
SENTENCE = "The boy enjoyed the noisy toy."
WAIT_MS = 240_000   # a hang guard (a loaded machine is slow), not a speed limit


@pytest.fixture
def window(qtbot, trained_cache):
    yield from opened_window(qtbot, wait_ms=WAIT_MS)


@pytest.fixture
def clip(tmp_path) -> Path:
    """The sentence's audio alone in a folder (no labels, no transcript beside it)."""
    path = tmp_path / "recording.flac"
    shutil.copy(CLIP, path)
    return path


def _phone_axis(win):
    return win.timeline.axes_of(next(p for p in win.timeline.panels if p.title == "phones"))


def test_open_audio_with_a_sentence_shows_aligned_phones(window, qtbot, clip, tmp_path):
    win = window
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.open_audio(clip, text=SENTENCE)
    view = win.view
    utt = view.utterance
    assert view.split == "external" and utt.name == "recording" and view.original is None
    assert utt.label_source == "aligned" and view.synthesis.config.mode == "robust"
    assert [w.label for w in utt.words] == ["the", "boy", "enjoyed", "the", "noisy", "toy"]
    assert [p.label for p in utt.phones if p.label != "sil"][:4] == ["dh", "ah", "b", "oy"]
    ax = _phone_axis(win)
    assert [t.get_text() for t in ax.get_yticklabels()] == ["phones (aligned)", "words"]
    assert "labels: aligned from the sentence typed" in win.title.text()
    win.timeline.canvas.finish()                # the labels are drawn where they fit
    tier = next(p for p in win.timeline.shown if p.title == "phones")
    drawn = [d[0] for row in tier.labels for d in row.drawn]
    assert "boy" in drawn and "oy" in drawn
    assert win.audio_opener.box.combo.currentData() == "aligned"
    assert win.audio_opener.box.combo.isEnabled()
    first = win.audio_opener.box.combo.model().item(0)            # no label file beside it: why
    assert not first.isEnabled() and "no label file for recording.flac" in first.toolTip()
    shot = win.save_screenshot(tmp_path / "aligned.png")
    assert shot.stat().st_size > 10_000
    aligned_lips = view.shown.copy()

    # the same audio with recognized labels, then with none: the lips change
    box = win.audio_opener.box
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        box.combo.setCurrentIndex(box.combo.findData("recognized"))
        box.combo.activated.emit(box.combo.currentIndex())
    assert win.view.utterance.label_source == "recognized" and win.view.utterance.words == []
    ax = _phone_axis(win)
    assert [t.get_text() for t in ax.get_yticklabels()] == ["phones (recognized)"]
    assert SENTENCE not in win.title.text()     # not what recognized labels say
    assert not np.allclose(win.view.shown, aligned_lips)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        box.combo.setCurrentIndex(box.combo.findData("none"))
        box.combo.activated.emit(box.combo.currentIndex())
    assert win.view.synthesis.config.mode == "acoustic" and not win.view.utterance.phones
    # back to a corpus utterance: the box shows its own labels (the label file), every source
    # of it available (issue 49: it was greyed on the corpus with no hint why)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.set_utterance(win.corpus.info.test[0])
    assert box.combo.isEnabled() and box.combo.currentData() == "file"
    assert all(box.combo.model().item(i).isEnabled() for i in range(box.combo.count()))
    label_file = f"{win.view.utterance.name}.TextGrid"
    assert [t.get_text() for t in _phone_axis(win).get_yticklabels()] == ["phones (label file)", "words"]
    assert f"labels: label file {label_file}" in win.title.text()


def test_menu_asks_the_sentence_and_a_missing_word(window, qtbot, clip, monkeypatch):
    win = window
    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(lambda *a, **k: (str(clip), "")))

    def sentence(self):
        self.text.setText("The boy enjoyed the noizee toy")
        return QDialog.DialogCode.Accepted

    def missing(self):
        assert list(self.edits) == ["noizee"]
        ok = self.buttons.button(self.buttons.StandardButton.Ok)
        self.edits["noizee"].setText("N OY Q")                 # not ARPAbet: OK stays off
        assert not ok.isEnabled() and "not ARPAbet: q" in self.message.text()
        self.edits["noizee"].setText("N OY1 Z IY0")
        assert ok.isEnabled()
        return QDialog.DialogCode.Accepted

    monkeypatch.setattr(SentenceDialog, "exec", sentence)
    monkeypatch.setattr(MissingWordsDialog, "exec", missing)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.action_open_audio.trigger()
    utt = win.view.utterance
    assert utt.label_source == "aligned" and "noizee" in [w.label for w in utt.words]


def test_empty_sentence_recognizes_and_wrong_sentence_is_refused(window, qtbot, clip, monkeypatch):
    win = window
    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(lambda *a, **k: (str(clip), "")))
    monkeypatch.setattr(SentenceDialog, "exec", lambda self: QDialog.DialogCode.Accepted)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.action_open_audio.trigger()
    assert win.view.utterance.label_source == "recognized"
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "critical", staticmethod(
        lambda parent, title, text, *a, **k: shown.append(text)))
    name = win.view.utterance.name
    win.open_audio(clip, text="Tornadoes often destroy acres of farm land")
    qtbot.waitUntil(lambda: bool(shown), timeout=WAIT_MS)
    assert "recording.flac" in shown[0] and "does not match the audio" in shown[0]
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    assert win.view.utterance.name == name and win.view.utterance.label_source == "recognized"
    # a transcript beside the audio is used without asking
    clip.with_suffix(".txt").write_text(SENTENCE)
    monkeypatch.setattr(SentenceDialog, "exec", lambda self: pytest.fail("asked"))
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.action_open_audio.trigger()
    assert win.view.utterance.label_source == "aligned"


def test_recordings_from_the_command_line_open_one_after_another(qtbot, trained_cache, tmp_path):
    """``facetraj gui FOLDER`` (a folder of recordings without face data): each recording is
    opened with the default corpus's model, its phones recognized (nothing beside it), the one
    after the other, the first shown and the others listed under "opened"; an unreadable file
    is reported and skipped."""
    from facetraj_app.recordings import RecordingQueue, recordings_in
    from facetraj_engine.errors import InputError

    folder = tmp_path / "talker"
    folder.mkdir()
    shutil.copy(CLIP, folder / "a.flac")
    shutil.copy(ROOT / "data_samples" / "s001.flac", folder / "c.flac")
    (folder / "b.wav").write_bytes(b"RIFF....WAVEjunk" * 9)         # corrupt: skipped, reported
    assert [p.name for p in recordings_in(folder)] == ["a.flac", "b.wav", "c.flac"]
    assert recordings_in(default_corpus()) == []                       # a corpus opens as one
    with pytest.raises(InputError, match="neither a corpus"):
        recordings_in(tmp_path / "talker" / "..")
    errors = []
    win = build_window(default_corpus(), use_audio=False)
    qtbot.addWidget(win)
    win.set_error_handler(errors.append)
    shown = []
    win.utteranceChanged.connect(shown.append)
    win.add_extension("recordings", RecordingQueue(win, recordings_in(folder)))
    win.resize(1600, 1000)
    win.show()
    qtbot.waitUntil(lambda: "c" in win.browser.items and not win.busy, timeout=WAIT_MS)
    assert shown == ["a"]                    # the first shown (no corpus utterance first), the
    assert win.view.utterance.name == "a"    # others listed: it landed on the last (issue 49)
    assert "a" in win.browser.items and "b" not in win.browser.items
    assert len(errors) == 1 and "b.wav" in errors[0]
    view = win.view
    assert view.split == "external" and view.original is None
    assert view.utterance.provenance.kind == "recognized"
    assert view.synthesis.config.mode == "robust" and "voice match" in win.status_label.text()
    win.close()


def test_the_search_shown_is_the_search_used_for_each_label_choice(window, qtbot, tmp_path):
    """A recording with a label file and a transcript beside it, switched through its label
    choices: the settings panel shows the search the synthesis used (``Synthesis.config``) and
    the title names it and where the labels came from; choosing the search shown does nothing,
    choosing another is obeyed (the panel read "phonetic" for aligned labels while the synthesis
    was robust, and "robust" for no labels while it was acoustic-only)."""
    from facetraj_app.provenance import search_key, search_title

    win = window
    stem = tmp_path / "boy"
    for suffix in (".flac", ".TextGrid", ".txt"):
        shutil.copy(CLIP.with_suffix(suffix), stem.with_suffix(suffix))
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.open_audio(stem.with_suffix(".flac"))
    box, mode = win.audio_opener.box, win.settings.mode
    origins = {"file": "label file boy.TextGrid", "aligned": "aligned from boy.txt",
               "recognized": "recognized from the speech (no text)",
               "none": "none: acoustic-only synthesis"}
    used = {}
    for source in ("file", "aligned", "recognized", "none"):
        if source != "file":
            with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
                box.combo.setCurrentIndex(box.combo.findData(source))
                box.combo.activated.emit(box.combo.currentIndex())
        qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
        config = win.view.synthesis.config
        used[source] = search_key(config)
        assert win.settings.shown_search() == used[source], source
        assert f"3-D: triangular synthesis, {search_title(config)}" in win.title.text(), source
        assert f"labels: {origins[source]}" in win.title.text(), source
        assert win.settings.mode_reason.isVisible() == (used[source] != "phonetic"), source
    assert used == {"file": "phonetic", "aligned": "robust", "recognized": "robust",
                    "none": "acoustic"}
    # aligned labels (robust shown): choosing robust, the search shown, synthesizes nothing;
    # choosing phonetic is obeyed
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        box.combo.setCurrentIndex(box.combo.findData("aligned"))
        box.combo.activated.emit(box.combo.currentIndex())
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    assert win.settings.shown_search() == "robust"
    generation = win.state.generation
    mode.activated.emit(mode.findData("robust"))
    assert win.state.generation == generation
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        mode.setCurrentIndex(mode.findData("phonetic"))
        mode.activated.emit(mode.currentIndex())
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    assert win.view.synthesis.config.mode == "phonetic" and win.settings.shown_search() == "phonetic"
    assert "phonetic (the paper), N=3" in win.title.text()
    assert not win.settings.mode_reason.isVisible()


def test_a_damaged_marker_file_beside_the_recording_does_not_stop_it(window, qtbot, clip):
    """A recording whose marker file beside it cannot be read opens without original markers,
    and a note over the panels names the file and says why."""
    win = window
    (clip.parent / "recording.c3d").write_bytes(b"\x02P not a c3d file")
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        assert win.open_audio(clip, acoustic_only=True)
    qtbot.waitUntil(lambda: win.view.split == "external" and win.notice.isVisible(), timeout=WAIT_MS)
    assert win.view.original is None
    assert "recording.c3d" in win.notice.text.text() and "without original markers" in win.notice.text.text()
