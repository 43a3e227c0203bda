"""End to end on the default corpus: train, synthesize held-out speech, and the paper's findings
that hold on any corpus (lips follow speech, phonetic beats acoustic-only, train beats test)."""

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.evaluation.scores import evaluate, speech_mask, trajectory_correlations
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import synthesize


def test_model_on_default_corpus(default_model, default_corpus):
    m = default_model
    assert m.n_markers == 54 and m.pca.n_components == 20
    assert m.pca.explained_ratio.sum() > 0.95
    assert len(m.phones) >= 40                          # 39 ARPAbet phones + sil
    assert m.codebook.n_contexts > 1000
    # PC1 is the jaw (the paper's Figure 2): chin and jaw-line markers carry most of its loading
    load = (m.pca.components[0].reshape(-1, 3) ** 2).sum(axis=1)
    top = [m.marker_names[i] for i in np.argsort(load)[::-1][:5]]
    assert sum(n.upper().startswith(("CH", "JAW", "LL", "LO")) for n in top) >= 3, top


def test_held_out_lips_follow_speech(default_model, default_corpus):
    utt = next(default_corpus.utterance(u) for u in default_corpus.info.test
               if "tornadoes" in default_corpus.utterance(u).text.lower())
    res = synthesize(default_model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(),
                     n_frames=utt.n_frames)
    mask = speech_mask(utt.audio, utt.sample_rate, res.times)
    assert 0.4 < mask.mean() < 0.95
    c = trajectory_correlations(default_model.normalise_markers(utt.markers), res.markers, mask,
                                default_model)
    assert c["lower_lip"] > 0.5 and c["upper_lip"] > 0.3 and c["whole_face"] > 0.4, c


@pytest.fixture(scope="module")
def scores(default_model, default_corpus):
    info = default_corpus.info
    # all of the test split; a third of the training split (resynthesis is the upper limit)
    sub = type(info)(**{**info.__dict__, "train": info.train[::3]})
    corpus = type(default_corpus)(default_corpus.root, sub)
    configs = [SynthConfig(), SynthConfig(mode="acoustic")]
    return evaluate(default_model, corpus, ("train", "test"), configs, ("triangular", "spline"))


def test_phonetic_beats_acoustic_only_on_test(scores):
    ph = scores.mean("test", "triangular", "phonetic")
    ac = scores.mean("test", "triangular", "acoustic")
    assert ph["whole_face"] > ac["whole_face"]
    assert ph["lower_lip"] > ac["lower_lip"]


def test_training_resynthesis_beats_test(scores):
    tr = scores.mean("train", "triangular")
    te = scores.mean("test", "triangular")
    for metric in ("whole_face", "lower_lip", "upper_lip"):
        assert tr[metric] > te[metric], metric
    assert te["lower_lip"] > 0.5


def test_save_load_default_model(default_model, tmp_path):
    back = Model.load(default_model.save(tmp_path / "m.npz"))
    assert np.array_equal(back.codebook.lsf, default_model.codebook.lsf)
    assert np.array_equal(back.pca.components, default_model.pca.components)
