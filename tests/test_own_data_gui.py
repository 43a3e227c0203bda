"""Own data in the app (run under Xvfb): the import dialog on the real MOCHA sample (marker roles,
an editable label map), a midsagittal corpus shown as such, and every export."""

from __future__ import annotations

import os

import numpy as np
import pytest
from conftest import MOCHA, shown_corpus_window

pytest.importorskip("pytestqt")
if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)
if not (MOCHA / "fsew0_001.ema").exists():
    pytest.skip("the MOCHA sample ../shared/data/mocha_fsew0_001 is absent", allow_module_level=True)

from PyQt6.QtWidgets import QMessageBox

from facetraj_app.own_data import (
    ImportDialog,
    default_label_map,
    export_figure,
    export_trajectories,
    guess_roles,
)
from facetraj_engine.io.corpus import load_corpus
from facetraj_engine.io.markerfiles import read_c3d, read_marker_table

pytestmark = pytest.mark.gui
WAIT_MS = 240_000   # a hang guard (a loaded machine is slow), not a speed limit


def test_role_guess_and_label_map():
    assert guess_roles(["UI", "LI", "UL", "LL", "TT", "BN"]) == (["UI", "BN"], "UL", "LL")
    assert guess_roles(["FH_L", "NB", "UL_C", "UL_R", "LL_C"])[1:] == ("UL_C", "LL_C")
    m = default_label_map(["@", "ii", "breath", "dh", "zz"], "mocha")
    assert m == {"@": "ah", "ii": "iy", "breath": "sil", "dh": "dh", "zz": ""}


def test_import_dialog_writes_a_description(qtbot, tmp_path):
    dlg = ImportDialog(folder=MOCHA)
    qtbot.addWidget(dlg)
    assert "1 utterances, 9 midsagittal (2-D) markers" in dlg.summary.text()
    assert dlg.fixed_markers() == ["UI", "BN"]
    assert dlg.upper_lip.currentText() == "UL" and dlg.lower_lip.currentText() == "LL"
    assert dlg.preset.currentIndex() == 1                          # MOCHA labels recognised
    table = dlg.label_map()
    assert table["@"] == "ah" and table["breath"] == "sil"
    # the user edits a cell: schwa as "ah" -> "er"
    row = next(r for r in range(dlg.map_table.rowCount()) if dlg.map_table.item(r, 0).text() == "@")
    dlg.map_table.item(row, 1).setText("er")
    dlg.output_edit.setText(str(tmp_path / "mocha.json"))
    path = dlg.write_description()
    corpus = load_corpus(path)
    utt = corpus.utterance("fsew0_001")
    at = {round(p.start, 2): p.label for p in utt.phones}
    assert at[0.64] == "er" and at[1.18] == "er"          # the two schwas of "was" and "for"
    assert at[1.35] == "ah"                                # MOCHA "uh" is still ARPAbet "ah"
    assert (tmp_path / "mocha.labelmap.tsv").exists()
    assert not list(MOCHA.glob("*.json")) and not list(MOCHA.glob("*.tsv"))   # shared/ untouched
    # a label without an ARPAbet entry is refused with a message naming it
    dlg.map_table.item(row, 1).setText("")
    with pytest.raises(Exception, match="labels without an ARPAbet entry: @"):
        dlg.write_description()


@pytest.fixture
def mocha_window(qtbot, tmp_path, monkeypatch):
    dlg = ImportDialog(folder=MOCHA)
    qtbot.addWidget(dlg)
    dlg.output_edit.setText(str(tmp_path / "mocha.json"))
    win = shown_corpus_window(qtbot, dlg.write_description(), monkeypatch, WAIT_MS)
    yield win
    win.close()


def test_midsagittal_corpus_shown_and_exported(mocha_window, tmp_path, qtbot):
    win = mocha_window
    assert win.view.utterance.name == "fsew0_001" and win.model.n_markers == 9
    assert win.face.preset == "profile" and win.camera_buttons["profile"].isChecked()
    assert win.dimensions_label.isVisible() and "midsagittal" in win.dimensions_label.text()
    assert not win.view_bar.surface.isEnabled()        # no face surface through 2-D points
    # lips and jaw in the time-aligned panels: the real trajectories against the speech
    jaw = win.marker_panels[0]
    assert jaw.marker == "LI" and win.timeline.axes_of(jaw) is not None
    ax = win.timeline.axes_of(jaw)
    li = win.model.marker_names.index("LI")
    dashed = [ln for ln in ax.get_lines() if ln.get_linestyle() not in ("-", "None")]
    np.testing.assert_allclose(dashed[0].get_ydata()[:50], win.view.original[:50, li, 1])
    orig = win.view.original
    assert np.isfinite(orig[:100]).all() and np.isnan(orig[-10:]).all()
    for which, suffix in (("synthesized", ".c3d"), ("original", ".tsv"), ("synthesized", ".npz")):
        out = export_trajectories(win, tmp_path / f"x{suffix}", which)
        assert out.exists()
    c3d = read_c3d(tmp_path / "x.c3d")
    assert c3d.markers.shape == win.view.shown.shape
    tsv = read_marker_table(tmp_path / "x.tsv")
    np.testing.assert_allclose(tsv.markers[:50], orig[:50], atol=1e-3)
    with np.load(tmp_path / "x.npz", allow_pickle=False) as z:
        assert z["markers"].shape == win.view.shown.shape and str(z["which"]) == "synthesized"
    for suffix, magic in ((".png", b"\x89PNG"), (".svg", b"<?xml"), (".pdf", b"%PDF")):
        p = export_figure(win, tmp_path / f"fig{suffix}")
        assert p.read_bytes()[:5].startswith(magic)


def test_file_menu_entries_and_errors(mocha_window, monkeypatch, tmp_path):
    win = mocha_window
    acts = win.extension("own_data").actions
    assert {"Import your own recordings", "Export synthesized trajectories", "Export a video",
            "Export the panels as a figure", "Save the model"} <= set(acts)
    shown = []
    monkeypatch.setattr(QMessageBox, "critical", lambda *a, **k: shown.append(a[2]))
    from PyQt6.QtWidgets import QFileDialog

    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(tmp_path / "x.xyz"), ""))
    acts["Export synthesized trajectories"].trigger()
    assert shown and "x.xyz: unknown format" in shown[-1]
    assert win.isVisible() and win.view is not None                  # the app keeps working
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(tmp_path / "m.npz"), ""))
    acts["Save the model"].trigger()
    assert (tmp_path / "m.npz").exists()
