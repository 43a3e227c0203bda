"""``facetraj_engine.method.modes``: every mode's one home. The command line, the rule, the synthesis, the
app's selector and the docs read the registry; a mode added there (a test's own, below) is
synthesized, chosen and offered without a change anywhere else."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment, Provenance
from facetraj_engine.method import modes
from facetraj_engine.method.modes import (
    MODES,
    SEARCHES,
    TUNED_FIELDS,
    Mode,
    choose_mode,
    mode_of,
    modes_table,
)
from facetraj_engine.method.pipeline import synthesize

ROOT = Path(__file__).resolve().parent.parent
FIELDS = {f.name for f in dataclasses.fields(SynthConfig)}


def test_every_setting_a_mode_names_is_a_synth_config_field():
    for mode in MODES.values():
        assert set(mode.settings) <= FIELDS, mode.name
        for search in mode.searches:
            assert search.mode == mode.name and set(search.settings) <= FIELDS
    assert set(TUNED_FIELDS) <= FIELDS
    assert set(SEARCHES) == {"robust", "phonetic", "acoustic", "acoustic-full"}


def test_an_unknown_mode_is_refused_naming_the_modes():
    with pytest.raises(ValueError, match="unknown mode 'visemes' \\(phonetic, robust, acoustic\\)"):
        mode_of(SynthConfig(mode="visemes"))


def test_the_docs_table_is_the_registrys():
    text = (ROOT / "docs" / "labels.md").read_text()
    block = re.search(r"<!-- modes: .*?-->\n(.*?)\n<!-- end of modes -->", text, re.S)
    assert block is not None and block.group(1) == modes_table()


def test_the_command_line_offers_the_registrys_modes():
    from facetraj.cli import build_parser

    parser = build_parser()
    for name in MODES:
        args = parser.parse_args(["synth", "m.npz", "a.wav", "-o", "x.c3d", "--mode", name])
        assert args.mode == name
    with pytest.raises(SystemExit):
        parser.parse_args(["synth", "m.npz", "a.wav", "-o", "x.c3d", "--mode", "visemes"])


class Nearest(Mode):
    """A test's own mode: each frame takes the single codeword nearest by eq 5 (no labels)."""

    name = "nearest"
    title = "nearest codeword"
    help = "each frame the nearest codeword"

    def search(self, job):
        from facetraj_engine.method.search import SearchResult, weighted
        from facetraj_engine.method.synthesis import nearest_codewords

        model, w = job.model, job.w
        return SearchResult(weighted(model, w, lambda a, b: nearest_codewords(w[a:b], model.codebook.lsf, 1),
                                     job.config))


@pytest.fixture
def with_nearest(monkeypatch):
    monkeypatch.setattr(modes, "MODES", {**MODES, "nearest": Nearest()})


def test_a_mode_added_to_the_registry_is_synthesized_and_kept_by_the_rule(with_nearest, toy_model,
                                                                           toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    config = SynthConfig(mode="nearest", closure=False)
    res = synthesize(toy_model, utt.audio, utt.sample_rate, None, config)
    assert res.frames.candidates.shape[1] == 1
    # each frame is exactly its nearest codeword's PCs (one weight of 1), before smoothing
    np.testing.assert_allclose(res.raw_pcs, toy_model.codebook.pcs[res.frames.candidates[:, 0]])
    phones = [PhoneSegment(0.0, 0.1, "sil")]
    assert choose_mode(config, phones, Provenance("aligned"), explicit=True).mode == "nearest"
    assert choose_mode(config, None).describe() == "nearest mode: no phone labels"


def test_the_rule_picks_by_the_modes_needs():
    segs = [PhoneSegment(0.0, 0.1, "sil")]
    picks = {kind: choose_mode(SynthConfig(), segs, Provenance(kind)).mode
             for kind in ("hand-checked", "aligned", "recognized")}
    assert picks == {"hand-checked": "phonetic", "aligned": "robust", "recognized": "robust"}
    assert not MODES[choose_mode(SynthConfig(), None).mode].needs_labels
    for name, mode in MODES.items():        # a mode that needs labels, without any: none needed
        got = choose_mode(SynthConfig(mode=name), None, explicit=True).mode
        assert got == name if not mode.needs_labels else not MODES[got].needs_labels
