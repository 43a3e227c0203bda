"""Corrected labels in a corpus (issue 56): saved into the corpus folder they are the labels
``train`` and ``eval`` read, and the commands and ``report`` count the phones hand-checked,
aligned and recognized."""

from __future__ import annotations

import logging
import shutil

import numpy as np

from facetraj.cli import main
from facetraj_engine.data import Provenance
from facetraj_engine.io.corpus import label_path, load_corpus
from facetraj_engine.io.label_census import label_census
from facetraj_engine.io.labelfiles import read_label_file
from facetraj_engine.io.labelling import write_labels
from facetraj_engine.labels.editing import PHONES, LabelDocument
from facetraj_engine.labels.provenance import Labels


def recognized_then_corrected(corpus, utt_id: str, fixes: int) -> tuple[int, list[str]]:
    """The utterance's labels written as recognized ones, ``fixes`` phones then corrected by hand
    and saved over them (as the app's label editor saves a corpus utterance); its phones
    (silence left out) and their labels after the corrections."""
    utt = corpus.utterance(utt_id)
    rng = np.random.default_rng(0)
    made = Labels(list(utt.phones), list(utt.words), "recognized",
                  scores=10 * np.log(rng.uniform(0.1, 0.9, len(utt.phones))),
                  provenance=Provenance("recognized", "PocketSphinx 5.1.1"))
    doc = LabelDocument(made, utt.duration, 60.0)
    speech = [i for i, p in enumerate(utt.phones) if p.label != "sil"]
    for i in speech[:fixes]:
        doc.select(PHONES, i)
        doc.rename("m" if doc.phones[i].label != "m" else "aa")
    write_labels(label_path(corpus.data_root, utt_id), doc.labels_now(), utt.duration, overwrite=True)
    return len(speech), [p.label for p in doc.phones]


def test_the_census_counts_the_phones_corrected_by_hand(toy_corpus_dir, tmp_path, caplog):
    root = tmp_path / "toy"
    shutil.copytree(toy_corpus_dir, root)
    corpus = load_corpus(root)
    before = label_census(corpus)
    assert before.phones["recognized"] == 0 and before.corrected == {}
    first = corpus.info.train[0]
    n, now = recognized_then_corrected(corpus, first, 2)
    after = label_census(load_corpus(root))
    assert after.phones == {"hand-checked": before.total - n + 2, "aligned": 0, "recognized": n - 2}
    assert after.corrected == {first: 2} and after.utterances["recognized"] == 1
    assert after.describe() == (f"{after.total} phones: {before.total - n + 2} hand-checked (2 "
                                f"corrected by hand in 1 utterance), {n - 2} recognized")
    # train and eval read the corrected file and say so
    read = load_corpus(root).utterance(first)
    assert [p.label for p in read.phones] == now
    assert read.provenance.describe() == "recognized (PocketSphinx 5.1.1), 2 phones corrected by hand"
    with caplog.at_level(logging.INFO):
        assert main(["train", str(root), "-o", str(tmp_path / "m.npz"), "--no-tune"]) == 0
        trained = " ".join(r.getMessage() for r in caplog.records)
        caplog.clear()
        assert main(["eval", str(tmp_path / "m.npz"), str(root), "--no-baselines"]) == 0
        evaluated = " ".join(r.getMessage() for r in caplog.records)
    said = "(2 corrected by hand in 1 utterance)"
    assert said in trained and said in evaluated


def test_the_report_says_how_the_labels_were_made(toy_corpus_dir, tmp_path):
    from facetraj_engine.report.compute import corpus_summary
    from facetraj_engine.report.markdown import _labels

    root = tmp_path / "toy"
    shutil.copytree(toy_corpus_dir, root)
    corpus = load_corpus(root)
    n, _ = recognized_then_corrected(corpus, corpus.info.test[0], 3)
    summary = corpus_summary(load_corpus(root))
    assert summary.labels["phones"]["recognized"] == n - 3
    assert summary.labels["corrected"] == {corpus.info.test[0]: 3}
    assert "3 corrected by hand in 1 utterance" in _labels(summary.labels)
    back = read_label_file(label_path(corpus.data_root, corpus.info.test[0]), 16000,
                           corpus.utterance(corpus.info.test[0]).duration)
    assert int(back.hand_checked.sum()) == 3
