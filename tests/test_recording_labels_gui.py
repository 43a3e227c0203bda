"""The app under the one label rule (issue 38, real window under Xvfb): a recording with its
``.txt`` beside it gets the labels and mode ``synth`` gives it; ``facetraj gui FOLDER
--utterance NAME`` opens that recording of the folder; the status line's tooltip says what the
voice match means and what it changed."""

from __future__ import annotations

import logging
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from screens import opened_window

from facetraj.cli import main

pytestmark = pytest.mark.gui

ROOT = Path(__file__).resolve().parent.parent
CLIP = ROOT / "data_samples" / "s002.flac"          # "The boy enjoyed the noisy toy."
WAIT_MS = 240_000   # a hang guard (a loaded machine is slow), not a speed limit


@pytest.fixture
def window(qtbot, trained_cache):
    yield from opened_window(qtbot, wait_ms=WAIT_MS)


def _folder(tmp_path: Path) -> Path:
    """Two recordings: ``other`` alone, ``rec`` with its sentence beside it."""
    folder = tmp_path / "recordings"
    folder.mkdir()
    shutil.copy(ROOT / "data_samples" / "s005.flac", folder / "other.flac")
    shutil.copy(CLIP, folder / "rec.flac")
    shutil.copy(CLIP.with_suffix(".txt"), folder / "rec.txt")
    return folder


def test_the_app_gets_the_labels_and_mode_synth_gets(window, qtbot, tmp_path, default_model,
                                                     caplog):
    rec = _folder(tmp_path) / "rec.flac"
    model = default_model.save(tmp_path / "model.npz")
    with caplog.at_level(logging.INFO):
        assert main(["synth", str(model), str(rec), "-o", str(tmp_path / "s.tsv")]) == 0
    synth_line = next(m for m in caplog.messages if m.startswith("rec.flac: labels "))
    with qtbot.waitSignal(window.synthesisChanged, timeout=WAIT_MS):
        window.open_audio(rec)
    view = window.view
    utt = view.utterance
    assert utt.label_source == "aligned" and view.synthesis.config.mode == "robust"
    assert view.mode_reason == "robust mode: aligned labels are not hand-checked"
    assert synth_line.startswith(f"rec.flac: labels {utt.provenance.describe()} [rec.txt beside "
                                 f"the audio]; {view.mode_reason}")
    # the voice match in words, where it is shown
    status = window.status_label
    assert f"voice match {view.voice_match:.2f}" in status.text()
    tip = status.toolTip()
    assert tip.startswith(f"voice match {view.voice_match:.2f} (D/D0 ")
    assert "1 = the training voice's (D/D0 up to 1.5), 0 = a voice the codebook does not know" in tip
    assert "In this synthesis: label confidences" in tip and "the label weight x" in tip
    assert np.isfinite(view.synthesis.voice_ratio)


def test_gui_folder_utterance_opens_that_recording(trained_cache, tmp_path):
    folder = _folder(tmp_path)
    out = tmp_path / "rec.png"
    env = {**os.environ, "FACETRAJ_CACHE_DIR": str(trained_cache)}
    proc = subprocess.run([sys.executable, "-m", "facetraj", "gui", str(folder), "--utterance",
                           "rec", "--screenshot", str(out)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert out.stat().st_size > 10_000
    opened = proc.stderr.index("rec.flac: labels aligned from rec.txt (PocketSphinx ")
    assert opened < proc.stderr.index("screenshot written")      # the one named, shown first
    proc = subprocess.run([sys.executable, "-m", "facetraj", "gui", str(folder), "--utterance",
                           "nosuch", "--screenshot", str(tmp_path / "x.png")], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2
    assert f"facetraj: error: {folder}: no recording named 'nosuch' here (recordings: other, rec)" \
        in proc.stderr
