"""Labels a phonetician corrects in the window (issue 56), in a real window under Xvfb.

The six CMU ARCTIC recordings opened as ``facetraj gui FOLDER`` opens a folder of recordings
without transcripts (their phones recognized), the recognizer's errors corrected with the mouse
and the keys alone (what a phonetician does listening and looking at the spectrogram, not the
transcript typed in), saved with Ctrl+S; then ``facetraj synth`` on each recording reads the
saved TextGrid by the one label rule, says so, and the project's closure judge
(``facetraj_engine.evaluation.closure``, against the transcripts aligned) finds 13 of 13 /p b m/
within 1 mm of closed and no other consonant shut (11 of 13 and 5 of 81 shut as recognized).
"""

from __future__ import annotations

import logging
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from label_gui import click, drag, key, rename
from PyQt6.QtCore import Qt
from PyQt6.QtTest import QTest

pytestmark = pytest.mark.gui

ARCTIC = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "arctic_samples"
WAIT_MS = 240_000       # a hang guard on a loaded machine, not a speed limit

#: the recognizer's errors in each recording (what it gives here: deterministic) and a
#: phonetician's corrections, as the steps she takes: ("click", t) a phone of the phones row
#: (selected, the cursor there), ("rename", phone) F2 + typed + Enter, ("split",) S at the
#: cursor, ("merge",) M, ("delete",) Delete, ("previous",) Ctrl+Left, ("drag", from, to) a
#: boundary with the mouse
CORRECTIONS = {
    # "Author of the danger trail, Philip Steels": its one /p/ recognized where it is
    "cmu_arctic_us_aew_a0001": [],
    # "Not at this": /t dh/ heard as one /b/ (0.49-0.57): split at the /dh/ (0.53), the first
    # half /t/, the second /dh/; "Tom, apologized": a /p/ of 40 ms between /m/ and /ah/ deleted
    "cmu_arctic_us_aew_a0002": [("click", 0.53), ("split",), ("rename", "dh"), ("previous",),
                                ("rename", "t"), ("click", 2.42), ("delete",)],
    # "time that": the /m/ of "time" heard as /n/, the /dh/ of "that" as /b/
    "cmu_arctic_us_aew_a0003": [("click", 1.27), ("rename", "m"), ("click", 1.35),
                                ("rename", "dh")],
    # "Lord, but": the /b/ begun 50 ms early (its boundary dragged from 0.68 to 0.73 s) and a
    # /m/ of 30 ms after it deleted; "I'm": /m/ heard as /n/; "glad to": /t/ heard as /p/
    "cmu_arctic_us_axb_a0004": [("drag", 0.68, 0.73), ("click", 0.815), ("delete",),
                                ("click", 1.17), ("rename", "m"), ("click", 1.5), ("rename", "t")],
    # "Will": its /w/ heard as /m/
    "cmu_arctic_us_axb_a0005": [("click", 0.2), ("rename", "w")],
    # "God bless": the /b/ dropped (/d/ heard as /n l/): the two merged into one /d/, the /b/
    # where the waveform dips before the /l/ (0.55-0.60), the /l/ after it; "hope": /p/ heard
    # as /b/
    "cmu_arctic_us_axb_a0006": [("click", 0.47), ("rename", "d"), ("merge",), ("click", 0.60),
                                ("split",), ("previous",), ("rename", "b"),
                                ("drag", 0.5667, 0.55), ("click", 0.65), ("split",),
                                ("previous",), ("rename", "l"), ("click", 1.8), ("rename", "p")],
}


@pytest.fixture
def recordings(tmp_path) -> list[Path]:
    """The six recordings alone in a folder (no transcript beside them: recognized)."""
    if not ARCTIC.is_dir():
        pytest.skip(f"{ARCTIC} is not here")
    out = []
    for stem in CORRECTIONS:
        shutil.copy(ARCTIC / f"{stem}.wav", tmp_path / f"{stem}.wav")
        out.append(tmp_path / f"{stem}.wav")
    return out


def folder_window(qtbot, paths: list[Path], wait_ms: int = WAIT_MS):
    """The window as ``facetraj gui FOLDER`` opens a folder of recordings: each labelled in
    turn, the first shown."""
    from facetraj.paths import default_corpus
    from facetraj_app.main import WINDOW_SIZE, build_window
    from facetraj_app.recordings import RecordingQueue

    w = build_window(default_corpus(), use_audio=False)
    w.set_correlation_sweep(False)
    w.add_extension("recordings", RecordingQueue(w, paths))
    qtbot.addWidget(w)
    w.place_on_screen(WINDOW_SIZE)
    w.show()
    qtbot.waitExposed(w)
    w.place_on_screen(WINDOW_SIZE)
    names = {p.stem for p in paths}
    qtbot.waitUntil(lambda: names <= set(w.state.external) and w.settled, timeout=wait_ms)
    w.activateWindow()
    qtbot.waitActive(w)
    return w


def close_without_asking(w) -> None:
    editor = w.extension("labels")
    editor.discard()
    w.extension("analysis").close()
    w.close()


def show(w, qtbot, name: str) -> None:
    """Click ``name`` in the browser's "opened" group; wait for its face (shown already: as is)."""
    if w.view is not None and w.view.utterance.name == name:
        return
    item = w.browser.items[name]
    tree = w.browser.tree
    tree.scrollToItem(item)
    rect = tree.visualItemRect(item)
    with qtbot.waitSignal(w.synthesisChanged, timeout=WAIT_MS):
        QTest.mouseClick(tree.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                         rect.center())
    qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)


def correct(w, qtbot, steps) -> None:
    """A phonetician's steps, each edit waited for until its face is on screen."""
    editor = w.extension("labels")
    for step in steps:
        kind = step[0]
        if kind == "click":
            click(w, step[1])
            continue
        if kind == "previous":
            key(w, "Ctrl+Left")
            continue
        with qtbot.waitSignal(editor.followed, timeout=WAIT_MS):
            if kind == "rename":
                rename(w, step[1])
            elif kind == "drag":
                drag(w, step[1], step[2])
            else:
                key(w, {"split": "S", "merge": "M", "delete": "Delete"}[kind])
        qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)
        assert editor.bar.message.styleSheet() == "", editor.bar.message.text()   # not refused


def judge(model, wav: Path, markers: np.ndarray, times: np.ndarray):
    """The closure judge against the transcript aligned (issue 46's reference)."""
    from facetraj_engine.evaluation.closure import closure_score, lip_aperture
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.io.label_rule import label_audio, read_transcript

    audio, rate = read_audio(wav)
    ref = label_audio(audio, rate, "aligned", read_transcript(ARCTIC / f"{wav.stem}.txt"),
                      source=wav).phones
    return closure_score(lip_aperture(markers, model.upper_lip, model.lower_lip), times, ref,
                         model.closure.closed)


@pytest.mark.parametrize("screen", ["1920x1200"], indirect=True)
def test_six_arctic_recordings_corrected_in_the_window_close_every_bilabial(
        screen, qtbot, recordings, tmp_path, caplog):
    from facetraj.cli import main
    from facetraj_engine.evaluation.closure import ClosureScore

    w = folder_window(qtbot, recordings)
    model = w.model
    editor = w.extension("labels")
    try:
        for wav in recordings:
            show(w, qtbot, wav.stem)
            assert w.view.utterance.label_source == "recognized"
            correct(w, qtbot, CORRECTIONS[wav.stem])
            assert (w.windowTitle().endswith("labels edited, not saved[*]")
                    == bool(CORRECTIONS[wav.stem]))
            key(w, "Ctrl+S")
            assert wav.with_suffix(".TextGrid").is_file()
            assert not editor.session.doc.dirty and "not saved" not in w.windowTitle()
    finally:
        close_without_asking(w)
    model_file = model.save(tmp_path / "model.npz")
    before, after = [], []
    for wav in recordings:
        out = tmp_path / f"{wav.stem}.npz"
        recognized = tmp_path / f"{wav.stem}-recognized.npz"
        assert main(["synth", str(model_file), str(wav), "--recognize", "-o", str(recognized)]) == 0
        with np.load(recognized) as z:                                 # as recognized, not corrected
            before.append(judge(model, wav, z["markers"], z["times"]))
        caplog.clear()
        with caplog.at_level(logging.INFO):
            assert main(["synth", str(model_file), str(wav), "-o", str(out)]) == 0
        said = " ".join(r.getMessage() for r in caplog.records)
        assert f"[{wav.stem}.TextGrid beside the audio]" in said       # the one label rule
        assert ("corrected by hand" in said) == bool(CORRECTIONS[wav.stem])
        with np.load(out) as z:
            after.append(judge(model, wav, z["markers"], z["times"]))
    was = ClosureScore.pooled(before)
    assert np.sum(np.abs(was.minima - was.closed) <= 1.0) == 11
    assert np.sum(was.consonant_minima <= was.closed + 1.0) == 5
    pooled = ClosureScore.pooled(after)
    assert pooled.n == 13
    assert np.sum(np.abs(pooled.minima - pooled.closed) <= 1.0) == 13
    assert pooled.consonants_shut == 0.0
    assert len(pooled.consonant_minima) == 81 and pooled.vowels_shut == 0.0
