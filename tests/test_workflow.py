"""The documented workflow for a talker without label files, through the command line only
(issue 24): ``corpus align --recognize``, ``corpus init``, ``train``, ``eval``; each step says
which labels it sees and which mode it chose."""

from __future__ import annotations

import logging
import shutil

from facetraj_engine.io.labelfiles import recorded_provenance
from facetraj_engine.method.model import Model
from facetraj.cli import main


def said(caplog, start: int = 0) -> list[str]:
    return [r.getMessage() for r in caplog.records[start:] if r.name == "facetraj"]


def test_documented_workflow_with_recognized_labels(tmp_path, default_corpus, caplog):
    data = tmp_path / "talker"
    data.mkdir()
    info = default_corpus.info
    ids = [*info.train[:6], *info.test[:3]]
    for utt_id in ids:             # what a user downloads: speech, markers, transcripts; no labels
        for ext in ("flac", "c3d", "txt"):
            shutil.copy(default_corpus.data_root / f"{utt_id}.{ext}", data)
    caplog.set_level(logging.INFO)

    assert main(["corpus", "align", str(data), "--recognize"]) == 0
    assert recorded_provenance(data / f"{ids[0]}.TextGrid").kind == "recognized"

    n = len(caplog.records)
    assert main(["corpus", "init", str(data), "--fixed", *info.fixed_markers, "--upper-lip",
                 info.upper_lip, "--lower-lip", info.lower_lip, "--test", *ids[6:]]) == 0
    assert any(m.startswith("labels: 9 recognized") for m in said(caplog, n))

    n = len(caplog.records)
    assert main(["train", str(data), "-o", str(tmp_path / "model.npz")]) == 0
    assert any("6 recognized, not all hand-checked: cross-validating" in m for m in said(caplog, n))
    model = Model.load(tmp_path / "model.npz")
    assert model.trained_labels == {"recognized": 6}
    assert model.tuned["settings"] and model.tuned["split"] == "train"

    n = len(caplog.records)
    assert main(["eval", str(tmp_path / "model.npz"), str(data), "--split", "test", "-j", "1"]) == 0
    messages = said(caplog, n)
    assert any(m.startswith("robust mode: recognized labels are not hand-checked, settings "
                            "cross-validated at training") for m in messages), messages
    assert "synthesized in robust mode (3 utterances)" in messages

    # a mode the user chooses is kept, and said so
    n = len(caplog.records)
    assert main(["eval", str(tmp_path / "model.npz"), str(data), "--split", "test", "-j", "1",
                 "--mode", "acoustic"]) == 0
    assert "acoustic-only (indexed) mode: chosen (s001)" in said(caplog, n)
    assert "synthesized in acoustic mode (3 utterances)" in said(caplog, n)
