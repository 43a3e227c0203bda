"""Issue 49's review, the defects that do not depend on the screen's size, in a real window: the
MOCHA note goes with its recording and reads as words; the labels box on a corpus utterance
(each source available, or why not); Compare's and Measure's details (what the pins' list says
right after pinning, one pin per result, the pins' colours, an acoustic-only pin's labels, the
units, no "-0.0 mm", "wrote" after Export CSV, the PC score's unit, Ctrl+P in Help > Keys, an
opened s002.flac's name)."""

from __future__ import annotations

import os

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from conftest import DEFAULT_CORPUS
from screens import colour_of, opened_window, resynthesize

from facetraj.paths import shared_path

pytestmark = pytest.mark.gui

WAIT_MS = 240_000
ARCTIC = shared_path("data/arctic_samples/cmu_arctic_us_aew_a0001.wav")
MOCHA = shared_path("data/mocha_fsew0_001/fsew0_001.wav")


@pytest.fixture
def win(qtbot, trained_cache):
    yield from opened_window(qtbot, "s002", WAIT_MS)


def opened(w, qtbot, path, **kw) -> None:
    resynthesize(w, qtbot, lambda: w.open_audio(path, **kw), WAIT_MS)
    qtbot.waitUntil(lambda: w.view.split == "external" and w.settled, timeout=WAIT_MS)


@pytest.mark.skipif(not MOCHA.exists() or not ARCTIC.exists(), reason="../shared's samples are not here")
def test_the_mocha_note_goes_with_its_recording_and_reads_as_words(win, qtbot, tmp_path):
    """Opening fsew0_001.wav shows the note; choosing another utterance, opening an ARCTIC file
    or opening a corpus hides it (it stayed up until its own buttons were used); its text names
    the coils in words ("'FH2_R', 'FH1_R' ... missing" was list syntax)."""
    w = win
    for leave in ("another utterance", "an ARCTIC file", "a corpus"):
        opened(w, qtbot, MOCHA, acoustic_only=True)
        text = w.notice.text.text()
        assert w.notice.isVisible() and "fsew0_001.ema beside fsew0_001.wav holds 9 other markers" in text
        assert "(UI, LI, UL, LL, TT, TB, TD, V and BN) than the model's 54" in text
        assert "', '" not in text and "[" not in text and "..." not in text
        if leave == "another utterance":
            resynthesize(w, qtbot, lambda: w.set_utterance("s001"), WAIT_MS)
        elif leave == "an ARCTIC file":
            opened(w, qtbot, ARCTIC, acoustic_only=True)
        else:
            with qtbot.waitSignal(w.modelReady, timeout=WAIT_MS):
                w.open_corpus(DEFAULT_CORPUS)
            qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)
        assert not w.notice.isVisible(), leave


def test_the_labels_box_on_a_corpus_utterance(win, qtbot):
    """On s002 (a corpus utterance) the labels box is on, at its own labels; aligned then
    recognized synthesize the same utterance again with those labels (its split, its place in
    time and its name kept: pins of it are shown with it); its own labels again; every choice
    available, the box's tooltip says what it does; a recording opened without a label file or
    a sentence greys those two and says why in their tooltips."""
    w = win
    box = w.audio_opener.box
    assert box.combo.isEnabled() and box.combo.currentData() == "file"
    assert all(box.combo.model().item(i).isEnabled() for i in range(box.combo.count()))
    assert "switch to compare the lips" in box.combo.toolTip()
    w.seek(0.3)
    for source, origin in (("aligned", "aligned from s002.txt"),
                           ("recognized", "recognized from the speech (no text)"),
                           ("file", "label file s002.TextGrid")):
        with qtbot.waitSignal(w.synthesisChanged, timeout=WAIT_MS):
            box.combo.setCurrentIndex(box.combo.findData(source))
            box.combo.activated.emit(box.combo.currentIndex())
        qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)
        view = w.view
        assert (view.utterance.name, view.split) == ("s002", "train"), source
        assert view.original is not None and f"labels: {origin}" in w.title.text(), source
        assert box.combo.currentData() == source and w.current_time() == pytest.approx(0.3)
        assert w.state.relabelled == (source != "file")


def test_pins_and_measure_details(win, qtbot, tmp_path, monkeypatch):
    """Right after pinning the list says the pin is the result on screen (it said "1 pinned
    (another utterance)"); pinning it again keeps one pin; the pins' colours are apart from the
    original's blue and the loop range's; an acoustic-only pin's settings say its labels are
    not used (it said "labels: label file"); the readout gives its lip y in mm and a zero
    difference as 0.0 mm; Measure's Export CSV says where it wrote; the PC score has no unit of
    mm; Help > Keys lists Ctrl+P; an opened s002.flac is named so (it was "s002'")."""
    import facetraj_app.analysis.common as common
    from facetraj_app import style
    from facetraj_app.main_window import KEYS_HELP
    from facetraj_app.pins import PIN_COLORS

    w = win
    compare, measure = w.extension("compare"), w.extension("measure")
    compare.pin()
    assert len(w.pins) == 1 and "pin 1: the result on screen" in compare.label.text()
    compare.pin()
    assert len(w.pins) == 1 and "pinned already (pin 1)" in w.statusBar().currentMessage()
    for colour in PIN_COLORS:
        for other in (style.ORIGINAL_COLOR, style.LOOP_COLOR, style.CURSOR_COLOR):
            assert np.linalg.norm(colour_of(colour) - colour_of(other)) > 90, (colour, other)
    mode = w.settings.mode
    resynthesize(w, qtbot, lambda: (mode.setCurrentIndex(mode.findData("acoustic")),
                                    mode.activated.emit(mode.currentIndex())), WAIT_MS)
    compare.pin()
    assert "labels: not used" in w.pins.pins[-1].parts
    resynthesize(w, qtbot, lambda: (mode.setCurrentIndex(mode.findData("phonetic")),
                                    mode.activated.emit(mode.currentIndex())), WAIT_MS)
    w.seek(0.05)                                     # the first frames: silence, the same lips
    text = measure.readout.text()
    assert "upper lip y " in text and " mm, lower lip y " in text and "-0.0 mm" not in text
    table = measure.open_table()
    out = tmp_path / "b.csv"
    monkeypatch.setattr(common, "ask_save_path", lambda *a, **k: out)
    table.filter.setText("b")
    table.export_button.click()
    assert out.exists() and w.status_label.text() == f"wrote {out}"
    pc = w.extension("analysis")
    pc.view_actions["pc_modes"].trigger()
    from screens import view_settled

    qtbot.waitUntil(lambda: view_settled(w, "pc_modes"), timeout=WAIT_MS)
    readout = pc.widgets["pc_modes"].value_label.text()
    assert readout.startswith("PC1 score ") and "SD)" in readout
    assert "mm (" not in readout.split("·")[0]
    assert "ctrl+p" in KEYS_HELP.lower()
    opened(w, qtbot, DEFAULT_CORPUS / "s002.flac")
    assert w.view.utterance.name == "s002.flac" and "s002.flac" in w.browser.items
