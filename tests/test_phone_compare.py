"""The per-phone comparison of results across a corpus (facetraj_engine.analysis.phone_compare):
each result made again from its recipe (settings and label source), its least aperture over each
of the utterance's own phone segments, as the window's table measures it; means per phone; the
CSV; and the label sources of an utterance on screen (app/label_sources.py)."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from facetraj_engine.analysis.apertures import phone_apertures
from facetraj_engine.analysis.phone_compare import (
    COMPARISON_COLUMNS,
    Recipe,
    compare_utterance,
    corpus_comparison,
    phone_means,
    write_comparison_csv,
)
from facetraj_engine.config import SynthConfig
from facetraj_engine.io.corpus import audio_path


@pytest.fixture(scope="module")
def recipes():
    return [Recipe("this", SynthConfig(), "file", "phonetic; labels: label file"),
            Recipe("pin 1", SynthConfig(mode="robust"), "aligned", "robust; labels: aligned"),
            Recipe("pin 2", SynthConfig(mode="acoustic"), "none", "acoustic only")]


def test_a_result_made_again_measures_as_the_window_does(default_model, default_corpus, recipes):
    """On s002: the "this" column (its own labels, phonetic) is the window's table's minimum for
    each segment; the aligned result's phone at each segment is the aligner's; acoustic-only has
    no phone; the original's minimum is the table's original one."""
    from facetraj_app.state import build_view

    utt = default_corpus.utterance("s002")
    rows = compare_utterance(default_model, utt, "train", recipes, audio_path(default_corpus.data_root,
                                                                              "s002"))
    view = build_view(default_model, utt, "train", SynthConfig())
    table = phone_apertures(view.times, view.shown, default_model.upper_lip, default_model.lower_lip,
                            utt.phones, utt.words, view.original)
    assert [(r.phone, r.start) for r in rows] == [(t.phone, t.start) for t in table]
    assert [r.results[0].min_mm for r in rows] == pytest.approx([t.min_synthesized for t in table])
    assert [r.min_original for r in rows] == pytest.approx([t.min_original for t in table])
    boy = next(r for r in rows if r.word == "boy" and r.phone == "b")
    assert [x.name for x in boy.results] == ["this", "pin 1", "pin 2"]
    assert boy.results[1].phone == "b" and boy.results[2].phone == ""
    assert all(np.isfinite(x.min_mm) for r in rows for x in r.results)


def test_across_the_corpus_means_per_phone_and_a_csv(default_model, default_corpus, recipes, tmp_path):
    ids = [("test", u) for u in default_corpus.info.test[:2]] + [("test", "no-such")]
    rows = list(corpus_comparison(default_model, default_corpus, recipes[::2], ids))
    assert {r.utterance for r in rows} == set(default_corpus.info.test[:2])    # "no-such" left out
    means = phone_means(rows, ["m", "b"])
    assert [m.phone for m in means] == [p for p in ("m", "b") if any(r.phone == p for r in rows)]
    m = means[0]
    mine = [r for r in rows if r.phone == m.phone]
    assert m.segments == len(mine)
    assert m.original == pytest.approx(np.mean([r.min_original for r in mine]))
    assert m.results[1] == pytest.approx(np.mean([r.results[1].min_mm for r in mine]))
    out = write_comparison_csv(tmp_path / "c.csv", rows, recipes[::2])
    back = list(csv.DictReader(out.open()))
    assert tuple(back[0]) == COMPARISON_COLUMNS and len(back) == 2 * len(rows)
    first = back[1]
    assert first["result"] == "pin 2" and first["settings"] == "acoustic only"
    difference = float(first["min_mm"]) - float(first["min_original_mm"])
    assert float(first["difference_mm"]) == pytest.approx(difference, abs=1e-4)


def test_label_sources_of_a_corpus_utterance(default_corpus, tmp_path):
    """A corpus utterance's own labels are its "file" choice (as read), aligned and recognized
    made from its audio; a recording with no label file and no sentence says why those two are
    not available."""
    from facetraj_app.label_sources import LabelSources, corpus_sources
    from facetraj_app.provenance import LabelOrigin

    utt = default_corpus.utterance("s002")
    own = LabelOrigin("file", file="s002.TextGrid")
    sources = corpus_sources(utt, audio_path(default_corpus.data_root, "s002"), own,
                             "The boy enjoyed the noisy toy.", "s002.txt")
    assert all(sources.unavailable(s) == "" for s in ("file", "aligned", "recognized", "none"))
    assert sources.utterance("file") is utt and sources.origin("file") == own
    aligned = sources.utterance("aligned")
    assert aligned.label_source == "aligned" and aligned.markers is utt.markers
    assert [w.label for w in aligned.words][:2] == ["the", "boy"]
    assert sources.origin("aligned").text() == "aligned from s002.txt"
    none = sources.utterance("none")
    assert none.phones == [] and none.label_source == "none"
    bare = LabelSources(utt.__class__(name="x", audio=utt.audio, sample_rate=utt.sample_rate, phones=[],
                                      markers=None, marker_rate=utt.marker_rate,
                                      marker_names=utt.marker_names), tmp_path / "x.wav")
    assert "no label file for x.wav" in bare.unavailable("file")
    assert "no sentence to align" in bare.unavailable("aligned") and bare.unavailable("recognized") == ""
