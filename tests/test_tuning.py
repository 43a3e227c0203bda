"""Cross-validation of the robust mode's settings on the training split only (facetraj_engine.evaluation.tuning), and
the evaluation with automatic labels (facetraj_engine.evaluation.label_eval) on its own numbers."""

from __future__ import annotations

import functools
import operator
from dataclasses import replace

import numpy as np
import pytest

from facetraj_engine.config import SynthConfig
from facetraj_engine.errors import InputError
from facetraj_engine.evaluation.label_eval import LabelEval, evaluate_kind, format_markdown
from facetraj_engine.evaluation.scores import UtteranceScore
from facetraj_engine.evaluation.tuning import LIMITS, coordinate_search, cross_validate, fold_ids
from facetraj_engine.method.modes import tuned_config
from facetraj.cli import main


def test_fold_ids_cover_training_once():
    ids = [f"u{i}" for i in range(7)]
    folds = fold_ids(ids, 3)
    assert sorted(functools.reduce(operator.iadd, folds, [])) == sorted(ids)
    assert [len(f) for f in folds] == [3, 2, 2]


def test_cross_validate_uses_training_split_only(toy_corpus):
    """The test split is never read: the corpus is given test ids that do not exist."""
    corpus = replace(toy_corpus, info=replace(toy_corpus.info, test=["no-such-utterance"]))
    ladders = {"label_weight": (1.0, 4.0, 16.0), "context_weight": (0.0, 1.0)}
    tuning = cross_validate(corpus, ladders=ladders, start={"label_weight": 4.0, "context_weight": 1.0},
                            widths=(0.05, 0.1), folds=2, max_per_fold=2)
    assert tuning.utterances == 4
    best = max(tuning.scores, key=lambda s: s["score"])
    assert tuning.settings == {k: v for k, v in best.items() if k != "score"}
    assert all(np.isfinite(s["score"]) and -1 <= s["score"] <= 1 for s in tuning.scores)
    # the chosen value has a worse one on either side, or is the end of its ladder
    for name, curve in tuning.curves.items():
        values = [v for v, _ in curve]
        k = values.index(tuning.settings[name])
        assert name in tuning.at_end or 0 < k < len(values) - 1 or values[k] == LIMITS.get(name)
        assert max(s for _, s in curve) == curve[k][1]
    cfg = tuned_config(SynthConfig(mode="robust"), tuning.to_json())
    assert cfg.triangle_s == tuning.settings["triangle_s"]
    assert cfg.label_weight == tuning.settings["label_weight"]


def test_a_choice_at_its_settings_own_limit_is_not_at_the_end_of_its_range():
    """One context-phone or no chain is as far as those settings go; a ladder's other ends are
    where the search could have gone on."""
    def score(s):
        return -s["n_context_phones"] - s["chain_beta"] - (s["gamma_max"] - 0.5) ** 2

    ladders = {"n_context_phones": (1, 2, 3), "chain_beta": (0.0, 0.1, 0.2),
               "gamma_max": (0.5, 1.0, 2.0)}
    best, _, ends = coordinate_search(score, ladders, {"n_context_phones": 2,
                                                       "chain_beta": 0.1, "gamma_max": 1.0})
    assert best == {"n_context_phones": 1, "chain_beta": 0.0, "gamma_max": 0.5}
    assert ends == ["gamma_max"]
    assert coordinate_search(score, ladders, best, limits={})[2] == list(ladders)


def _score(method, value, utt="u"):
    return UtteranceScore(utterance=utt, split="test", mode=method, smoothing="triangular",
                          n_context_phones=3, whole_face=value, lower_lip=value, upper_lip=value,
                          speech_frames=100)


@pytest.mark.parametrize("folds", [1, 10**20])
def test_cross_validate_refuses_impossible_folds(toy_corpus, folds):
    # (found by the fuzz run: --tune=99999999999999999999 tried to allocate that many folds)
    with pytest.raises(InputError, match="fold cross-validation needs 2 to"):
        cross_validate(toy_corpus, folds=folds)
    with pytest.raises(SystemExit) as exit_:            # the option parser's range
        main(["-q", "train", str(toy_corpus.root), "-o", "x.npz", f"--tune={folds}"])
    assert exit_.value.code == 2


def test_label_eval_summary_and_recommendation():
    res = LabelEval(scores={"aligned": [_score("robust", 0.8, "a"), _score("robust", 0.6, "b"),
                                        _score("phonetic", 0.65), _score("acoustic", 0.5),
                                        _score("ridge", 0.55), _score("viseme", 0.4)]})
    mean, sd = res.summary("aligned", "robust")["whole_face"]
    assert (mean, sd) == (pytest.approx(0.7), pytest.approx(0.1))
    assert res.best("aligned") == "robust" and res.beats_all("aligned")
    text = format_markdown(res)
    assert "| robust (" in text and "0.7000 ± 0.10" in text
    assert "with aligned labels, **robust** (above every other method" in text
    assert "**Which mode to pick.** Use the default" in text
    res.scores["aligned"].append(_score("phonetic", 0.95))
    assert not res.beats_all("aligned")


def test_evaluate_kind_on_toy_corpus(toy_corpus, toy_model):
    scores, tuning = evaluate_kind(toy_corpus, "exact", model=toy_model, tune=False, max_test=2)
    assert tuning is None
    methods = {s.mode for s in scores}
    assert methods == {"default", "robust", "phonetic", "phonetic-tuned", "acoustic", "ridge", "viseme"}
    assert all(len([s for s in scores if s.mode == m]) == 2 for m in methods)
    assert all(-1 <= s.whole_face <= 1 for s in scores)


def test_label_eval_file_round_trip(tmp_path):
    from facetraj_engine.evaluation.label_eval import read_label_eval, write_label_eval

    assert read_label_eval(tmp_path / "absent.json") is None
    res = LabelEval(scores={"recognized": [_score("robust", 0.7), _score("phonetic", 0.5)]},
                    tunings={"recognized": {"settings": {"label_weight": 4.0}}})
    back = read_label_eval(write_label_eval(tmp_path / "label_eval.json", res))
    assert back.summary("recognized", "robust") == res.summary("recognized", "robust")
    assert back.tunings == res.tunings
    assert "label_weight = 4" in format_markdown(back)


def test_evaluate_kind_scores_the_second_voice_too(toy_corpus, toy_model):
    scores, _, voice2 = evaluate_kind(toy_corpus, "exact", model=toy_model, tune=False, max_test=2,
                                      second=True)
    assert {s.mode for s in voice2} == {"default", "robust", "phonetic", "acoustic"}
    assert [s.utterance for s in voice2 if s.mode == "default"] == \
        [s.utterance for s in scores if s.mode == "default"]
    by = {(s.mode, s.utterance): s.whole_face for s in scores}
    assert any(abs(by[("acoustic", s.utterance)] - s.whole_face) > 1e-6     # another voice: other sounds
               for s in voice2 if s.mode == "acoustic")
