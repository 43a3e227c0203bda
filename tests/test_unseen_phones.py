"""A phone the model has never seen (issue 38): its frames are filled by the acoustic-only
search, in the paper's phonetic mode too, with one warning naming the phone and its frames; a
whole file is no longer refused for one phone. Labels whose phones the model all knows go the
paper's way, as before."""

from __future__ import annotations

import logging

import numpy as np

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment
from facetraj_engine.errors import FILE_WARNINGS
from facetraj_engine.method.context import segment_index
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.search import acoustic_candidates, eq4, weighted


def _relabelled(utt, index: int, label: str) -> list[PhoneSegment]:
    """The utterance's phones with the ``index``-th given another label."""
    phones = list(utt.phones)
    seg = phones[index]
    phones[index] = PhoneSegment(seg.start, seg.end, label)
    return phones


def test_an_unseen_phone_is_filled_by_the_acoustic_search_with_one_warning(toy_model, toy_corpus,
                                                                          caplog):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    assert "zh" not in toy_model.phones
    phones = _relabelled(utt, 2, "zh")
    FILE_WARNINGS.clear()
    cfg = SynthConfig(mode="phonetic")
    with caplog.at_level(logging.WARNING):
        res = synthesize(toy_model, utt.audio, utt.sample_rate, phones, cfg, source="u.lab")
    times = res.times
    unseen = segment_index(phones, times) == 2
    assert unseen.sum() > 0 and np.isfinite(res.markers).all()
    warnings = [r.getMessage() for r in caplog.records if "never seen" in r.getMessage()]
    assert warnings == [f"u.lab: phones the model has never seen, their frames filled by the "
                        f"acoustic search: 'zh' ({unseen.sum()} frames)"]
    # those frames' candidates are the acoustic-only search's; the others eq 4's, as the paper
    acoustic = acoustic_candidates(toy_model, res.lsf[unseen], cfg)
    assert np.array_equal(res.frames.candidates[unseen][:, :acoustic.shape[1]], acoustic)
    known = [PhoneSegment(s.start, s.end, "sil" if s.label == "zh" else s.label) for s in phones]
    _, _, eq4_candidates = eq4(toy_model, known, times, cfg)
    n = eq4_candidates.shape[1]
    assert np.array_equal(res.frames.candidates[~unseen][:, :n], eq4_candidates[~unseen])
    assert np.all(res.frames.weights[~unseen][:, n:] == 0)


def test_labels_the_model_knows_are_synthesized_as_the_paper_does(toy_model, toy_corpus, caplog):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    cfg = SynthConfig(mode="phonetic")
    with caplog.at_level(logging.WARNING):
        res = synthesize(toy_model, utt.audio, utt.sample_rate, utt.phones, cfg)
    assert "never seen" not in caplog.text
    _, _, candidates = eq4(toy_model, list(utt.phones), res.times, cfg)
    paper = weighted(toy_model, res.lsf, lambda a, b: candidates[a:b], cfg)
    assert np.array_equal(res.raw_pcs, paper.pcs)
    assert np.array_equal(res.frames.candidates, candidates)


def test_synth_of_a_file_with_an_unseen_phone_succeeds(toy_model, toy_corpus_dir, tmp_path, caplog):
    from facetraj.cli import main

    model = toy_model.save(tmp_path / "model.npz")
    labels = tmp_path / "unseen.lab"
    labels.write_text("0 0.5 sil\n0.5 1.5 zh\n1.5 1.8333 sil\n")
    out = tmp_path / "o.tsv"
    FILE_WARNINGS.clear()
    with caplog.at_level(logging.WARNING):
        code = main(["synth", str(model), str(toy_corpus_dir / "toy030.wav"), "--labels",
                     str(labels), "-o", str(out)])
    assert code == 0 and out.is_file()
    assert f"{labels}: phones the model has never seen, their frames filled by the acoustic " \
           "search: 'zh' (60 frames)" in caplog.text
