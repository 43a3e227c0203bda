"""Articulograph folders in the app (run under Xvfb): the import dialog on MVIEW files (head-
corrected: no fixed markers) and on Carstens files (channels named in the dialog), and 2-D XRMB
data shown in the midsagittal plane."""

from __future__ import annotations

import os

import numpy as np
import pytest

pytest.importorskip("pytestqt")
if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from articulograph import write_folder
from conftest import shown_corpus_window
from toycorpus import FIXED, NAMES

from facetraj_app.own_data import ImportDialog
from facetraj_engine.io.corpus import load_corpus

pytestmark = pytest.mark.gui
WAIT_MS = 240_000   # a hang guard (a loaded machine is slow), not a speed limit


def test_import_dialog_on_mview_files(qtbot, toy_corpus_dir, tmp_path):
    folder = write_folder("mview", toy_corpus_dir, tmp_path / "mv", ["toy000", "toy001", "toy002"])
    dlg = ImportDialog(folder=folder)
    qtbot.addWidget(dlg)
    assert "3 utterances, 12 3-D markers at 100 Hz" in dlg.summary.text()
    assert "MVIEW files: head-corrected" in dlg.summary.text() and dlg.head_corrected.isChecked()
    for f in ("MVIEW (.mat)", "Carstens AG501 .pos (.pos)", "XRMB pellets (.txy)", "EST track"):
        assert f in dlg.findChildren(type(dlg.summary))[0].text()     # the intro lists the registry
    for i in range(dlg.fixed_list.count()):                           # none ticked: none needed
        dlg.fixed_list.item(i).setCheckState(dlg.fixed_list.item(i).checkState().Unchecked)
    dlg.upper_lip.setCurrentText("UL_C")
    dlg.lower_lip.setCurrentText("LL_C")
    dlg.output_edit.setText(str(tmp_path / "mv.json"))
    corpus = load_corpus(dlg.write_description())
    assert corpus.info.head_corrected and corpus.info.fixed_markers == []
    assert corpus.utterance("toy001").provenance.kind == "aligned"


def test_import_dialog_names_carstens_channels(qtbot, toy_corpus_dir, tmp_path):
    folder = write_folder("ag501", toy_corpus_dir, tmp_path / "pos", ["toy000", "toy001"])
    dlg = ImportDialog(folder=folder)
    qtbot.addWidget(dlg)
    assert dlg.upper_lip.itemText(0) == "Ch1" and not dlg.head_corrected.isChecked()
    dlg.channel_names.setText(" ".join(f"Ch{i + 1}={n}" for i, n in enumerate(NAMES)))
    dlg.set_folder(folder)
    assert [dlg.fixed_list.item(i).text() for i in range(dlg.fixed_list.count())] == NAMES
    assert dlg.upper_lip.currentText() == "UL_C" and dlg.fixed_markers() == ["FH_L", "FH_R", "NB"]
    nt = dlg.fixed_list.item(NAMES.index("NT"))                   # the user ticks the nose tip
    nt.setCheckState(nt.checkState().Checked)
    dlg.output_edit.setText(str(tmp_path / "pos.json"))
    corpus = load_corpus(dlg.write_description())
    assert corpus.info.marker_names == NAMES and corpus.info.fixed_markers == FIXED
    assert corpus.info.channel_names[0] == "Ch1=FH_L"


def test_two_d_xrmb_corpus_in_the_window(qtbot, toy_corpus_dir, tmp_path, monkeypatch):
    from facetraj_engine.io.corpus import init_corpus

    folder = write_folder("xrmb", toy_corpus_dir, tmp_path / "xrmb")
    path, _ = init_corpus(folder, upper_lip="UL", lower_lip="LL")
    win = shown_corpus_window(qtbot, path, monkeypatch, WAIT_MS)
    assert win.model.is_planar and win.face.preset == "profile"
    assert win.dimensions_label.isVisible() and not win.view_bar.surface.isEnabled()
    assert win.marker_panels[0].marker == "MNI"                    # XRMB's jaw beside the lips
    assert np.nanmax(np.abs(win.view.shown[..., 0])) < 1e-9       # no third axis invented
    assert "2-D: triangular synthesis" in win.title.text()
    win.close()
