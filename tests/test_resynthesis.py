"""A recording synthesized again as its labels are edited (engine/method/resynthesis.py): with the
memo of its last synthesis the result is the same to the bit as without it, and only the frames
an edit changed are weighted again."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment, Provenance
from facetraj_engine.labels.editing import PHONES, LabelDocument
from facetraj_engine.labels.provenance import Labels
from facetraj_engine.method.chain import chain_marginals
from facetraj_engine.method.modes import choose_mode
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.resynthesis import SynthesisMemo


def same(a, b) -> None:
    for name in ("raw_pcs", "pcs", "markers"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(a.frames.weights, b.frames.weights)
    assert a.voice_ratio == b.voice_ratio or (np.isnan(a.voice_ratio) and np.isnan(b.voice_ratio))


def edits(doc: LabelDocument):
    """A phonetician's edits of the document's phones, one after another (the labels after each)."""
    n = len(doc.phones)
    steps = [("rename", n // 3, "m"), ("move", n // 2), ("split", 2 * n // 3), ("delete", n // 4),
             ("undo",), ("silence", n - 2), ("rename", 1, "b")]
    for step in steps:
        if step[0] == "rename":
            doc.select(PHONES, step[1])
            doc.rename(step[2] if doc.phones[step[1]].label != step[2] else "n")
        elif step[0] == "move":
            p = doc.phones[step[1]]
            doc.move_boundary(step[1], p.start + 0.3 * (p.end - p.start))
        elif step[0] == "split":
            p = doc.phones[step[1]]
            doc.select(PHONES, step[1])
            doc.split(0.5 * (p.start + p.end))
        elif step[0] == "delete":
            doc.select(PHONES, step[1])
            doc.delete()
        elif step[0] == "silence":
            doc.select(PHONES, step[1])
            doc.mark_silence()
        else:
            doc.undo()
        yield doc.labels_now()


@pytest.mark.parametrize("kind", ["recognized", "hand-checked"])
def test_every_edit_synthesized_with_the_memo_equals_the_synthesis_without_it(default_model,
                                                                              default_corpus, kind):
    model = default_model
    utt = default_corpus.utterance(default_corpus.info.test[0])
    rng = np.random.default_rng(5)
    conf = rng.uniform(0.05, 0.9, len(utt.phones))
    made = Labels(list(utt.phones), list(utt.words), "recognized" if kind == "recognized" else "file",
                  scores=10 * np.log(conf) if kind == "recognized" else None,
                  provenance=Provenance(kind, "test"))
    doc = LabelDocument(made, utt.duration, model.marker_rate, model.phones)
    memo = SynthesisMemo()
    config = choose_mode(SynthConfig(), made.phones, made.provenance, tuned=model.tuned).config
    assert config.mode == ("robust" if kind == "recognized" else "phonetic")

    def both(labels: Labels):
        kw = dict(config=config, confidence=labels.trust(), provenance=labels.provenance, voice=True)
        return (synthesize(model, utt.audio, utt.sample_rate, labels.phones, memo=memo, **kw),
                synthesize(model, utt.audio, utt.sample_rate, labels.phones, **kw))

    same(*both(made))
    n = len(both(made)[0].times)
    searched = []
    for labels in edits(doc):
        same(*both(labels))
        searched.append(memo.searched)
    if kind == "recognized":            # each edit weighted a few frames again, not all of them
        assert 0 < max(searched) < n // 3


def test_the_memo_starts_again_for_other_settings_or_audio(default_model, default_corpus):
    model = default_model
    a, b = (default_corpus.utterance(u) for u in default_corpus.info.test[:2])
    memo = SynthesisMemo()
    prov = Provenance("recognized", "test")
    conf = np.full(len(a.phones), 0.5)
    first = synthesize(model, a.audio, a.sample_rate, a.phones, SynthConfig(mode="robust"),
                       confidence=conf, provenance=prov, memo=memo)
    assert memo.searched == len(first.times)
    other = synthesize(model, b.audio, b.sample_rate, b.phones, SynthConfig(mode="robust"),
                       confidence=np.full(len(b.phones), 0.5), provenance=prov, memo=memo)
    same(other, synthesize(model, b.audio, b.sample_rate, b.phones, SynthConfig(mode="robust"),
                           confidence=np.full(len(b.phones), 0.5), provenance=prov))
    assert memo.searched == len(other.times)
    n3 = SynthConfig(mode="robust", n_context_phones=5)
    same(synthesize(model, b.audio, b.sample_rate, b.phones, n3, confidence=np.full(len(b.phones), 0.5),
                    provenance=prov, memo=memo),
         synthesize(model, b.audio, b.sample_rate, b.phones, n3, confidence=np.full(len(b.phones), 0.5),
                    provenance=prov))
    assert memo.searched == len(other.times)


def test_the_chain_summed_again_only_where_its_terms_changed_is_the_same_to_the_bit():
    rng = np.random.default_rng(3)
    n, m = 400, 12
    lt = np.log(rng.dirichlet(np.ones(m), n))
    lt[7, 3] = -np.inf                                       # an entry that does not count
    lj = -rng.uniform(0, 4, (n - 1, m, m))
    keep: list = []
    chain_marginals(lt, lj, keep=keep)
    for a, b in ((200, 203), (0, 2), (397, 400), (50, 51)):
        lt2, lj2 = lt.copy(), lj.copy()
        lt2[a:b] = np.log(rng.dirichlet(np.ones(m), b - a))
        lj2[max(a - 1, 0):min(b, n - 1)] *= 1.5
        assert np.array_equal(chain_marginals(lt2, lj2, keep[0]), chain_marginals(lt2, lj2))
    assert np.array_equal(chain_marginals(lt, lj, keep[0]), chain_marginals(lt, lj))


def test_a_label_file_without_changes_is_not_searched_again(default_model, default_corpus):
    model = default_model
    utt = default_corpus.utterance(default_corpus.info.test[0])
    memo = SynthesisMemo()
    prov = Provenance("aligned", "test")
    conf = np.full(len(utt.phones), 0.7)
    synthesize(model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(mode="robust"),
               confidence=conf, provenance=prov, memo=memo)
    moved = list(utt.phones)
    k = len(moved) // 2
    moved[k] = replace(moved[k], label="m" if moved[k].label != "m" else "n")
    again = synthesize(model, utt.audio, utt.sample_rate, moved, SynthConfig(mode="robust"),
                       confidence=conf, provenance=prov, memo=memo)
    assert 0 < memo.searched < len(again.times) // 4
    synthesize(model, utt.audio, utt.sample_rate, moved, SynthConfig(mode="robust"),
               confidence=conf, provenance=prov, memo=memo)
    assert memo.searched == 0
    assert isinstance(moved[k], PhoneSegment)


def test_a_synthesis_that_fails_half_way_leaves_nothing_kept(default_model, default_corpus,
                                                            monkeypatch):
    import facetraj_engine.method.resynthesis as resynthesis

    model = default_model
    utt = default_corpus.utterance(default_corpus.info.test[0])
    prov, conf = Provenance("recognized", "test"), np.full(len(utt.phones), 0.5)
    memo = SynthesisMemo()
    synthesize(model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(mode="robust"),
               confidence=conf, provenance=prov, memo=memo)
    moved = list(utt.phones)
    moved[3] = replace(moved[3], label="m")

    def broken(*args, **kwargs):
        raise MemoryError("the chain")

    monkeypatch.setattr(resynthesis, "chained_pcs", broken)
    with pytest.raises(MemoryError):
        synthesize(model, utt.audio, utt.sample_rate, moved, SynthConfig(mode="robust"),
                   confidence=conf, provenance=prov, memo=memo)
    assert memo.bound == () and memo.robust is None
    monkeypatch.undo()
    same(synthesize(model, utt.audio, utt.sample_rate, moved, SynthConfig(mode="robust"),
                    confidence=conf, provenance=prov, memo=memo),
         synthesize(model, utt.audio, utt.sample_rate, moved, SynthConfig(mode="robust"),
                    confidence=conf, provenance=prov))


def test_a_bilabial_corrected_by_hand_closes_on_the_training_voice(default_model, default_corpus):
    """Recognized /p b m/ are not trusted on the voice the model was trained on (its voice
    match 1: the codebook knows its sounds); a /b/ a person corrected is, whatever the voice."""
    from facetraj_engine.evaluation.closure import lip_aperture, segment_values

    model = default_model
    utt = default_corpus.utterance(default_corpus.info.test[0])
    phones = list(utt.phones)
    k = next(i for i, p in enumerate(phones) if p.label in ("t", "d", "k", "g") and i > 1)
    phones[k] = replace(phones[k], label="b")
    conf = np.full(len(phones), 0.5)
    conf[k] = 1.0
    checked = np.zeros(len(phones), dtype=bool)
    checked[k] = True
    prov = Provenance("recognized", "test", corrected=1)

    def least(flags):
        res = synthesize(model, utt.audio, utt.sample_rate, phones, SynthConfig(mode="robust"),
                         confidence=conf, provenance=prov, voice=True, checked=flags)
        assert res.voice_match > 0.9
        ap = lip_aperture(res.markers, model.upper_lip, model.lower_lip)
        return segment_values(ap, res.times, [phones[k]], "min")[0]

    closed = model.closure.closed
    assert least(None) - closed > 1.0                 # the recognizer's word: not trusted here
    assert abs(least(checked) - closed) <= 1.0        # the phonetician's: the lips close
