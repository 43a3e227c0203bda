"""The app opening each kind of bad file (issue 26): an error dialog naming the file appears and
the window keeps running. The same probe as the fuzz run's app cases (tests/fuzz_app.py), in a
real window under Xvfb with pytest-qt."""

from __future__ import annotations

import random
import shutil
from collections import Counter

import pytest
from fuzz_app import AppProbe
from fuzzing import _judge_app, app_cases

pytestmark = pytest.mark.gui

WAIT_MS = 60_000


@pytest.fixture(scope="module")
def workspace(fuzz_workspace):
    return fuzz_workspace


@pytest.fixture
def probe(qtbot, workspace):
    from facetraj_app.main import build_window

    win = build_window(workspace.corpus, model=workspace.model, use_audio=False)
    qtbot.addWidget(win)
    win.set_correlation_sweep(False)
    win.resize(1280, 800)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.show()
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    yield AppProbe(win)
    win.close()


#: the kinds of app cases (tests/fuzzing.py) by the file they damage
GROUPS = {"audio": "audio", "labels": "labels", "beside": "labels", "alphabet": "labels",
          "transcript": "transcript", "model": "model", "corpus": "corpus", "c3d": "markers",
          "markers": "markers"}


def test_each_kind_of_bad_file_gives_a_dialog_and_the_window_runs_on(probe, workspace, qtbot):
    """App cases of the fuzz run, until each kind of file has given at least one error dialog
    naming it (at most 120): none may end otherwise than in such a dialog or the file opened."""
    gen = app_cases(workspace, random.Random(26))
    outcomes, refused = [], Counter()
    while len(outcomes) < 120 and set(refused) != set(GROUPS.values()):
        case = next(gen)
        report = probe.run(case.app)
        outcome = _judge_app(case, report, 0)
        outcomes.append((case, report, outcome))
        if outcome.status == "refused":
            refused[GROUPS[case.name.split(":")[0]]] += 1
    failures = [(c.name, c.app, r) for c, r, o in outcomes if o.failed]
    assert not failures, failures
    assert set(refused) == set(GROUPS.values()), refused
    # and the window still plays
    win = probe.win
    win.open_corpus(workspace.corpus, workspace.model)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    win.seek(0.0)
    start = win.displayed_frame
    win.play()
    qtbot.waitUntil(lambda: win.displayed_frame >= start + 5, timeout=10_000)
    win.pause()


def test_transcript_that_is_not_utf8_beside_the_audio(probe, workspace, tmp_path):
    """It ended the app (an exception escaping into Qt), found by the fuzz run; now a dialog."""
    shutil.copy(workspace.wav, tmp_path / "speech.wav")
    (tmp_path / "speech.txt").write_bytes(b"caf\xe9 \xff")
    report = probe.run(["audio", str(tmp_path / "speech.wav"), ""])
    assert report["status"] == "dialog"
    assert report["message"] == f"{tmp_path / 'speech.txt'}: the transcript is not UTF-8 text"
    assert probe.alive()


def test_audio_too_short_names_the_file(probe, workspace, tmp_path):
    import soundfile as sf

    x, rate = sf.read(workspace.wav)
    sf.write(tmp_path / "blip.wav", x[:100], rate)
    report = probe.run(["audio", str(tmp_path / "blip.wav"), ""])
    assert report["status"] == "dialog"
    assert report["message"].startswith(f"{tmp_path / 'blip.wav'}: the audio is too short")


def test_label_file_in_another_alphabet_opens(probe, workspace, tmp_path):
    from fuzzing import SPELLINGS, _write_label_file

    from facetraj_engine.data import PhoneSegment
    from facetraj_engine.io.labelfiles import read_labels

    segs = [PhoneSegment(s.start, s.end, SPELLINGS["IPA"][s.label][0])
            for s in read_labels(workspace.textgrid)]
    _write_label_file(tmp_path / "ipa.lab", segs)
    report = probe.run(["audio", str(workspace.wav), str(tmp_path / "ipa.lab")])
    assert report["status"] == "opened", report
    utt = probe.win.view.utterance
    assert [p.label for p in utt.phones] == [s.label for s in read_labels(workspace.textgrid)]
