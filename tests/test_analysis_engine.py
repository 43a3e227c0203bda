"""Analysis helpers (the engine/analysis/ package): clustering, CSV export, Table 2 / N sweep rows, errors,
the codebook inspector and PC modes; hand-checked where possible, else against the engine."""

from __future__ import annotations

import csv
from types import SimpleNamespace

import numpy as np
import pytest

from facetraj_engine.analysis.errors import (
    SegmentError,
    analyse_utterance,
    error_report,
    lip_error,
    phone_errors,
    segment_errors,
    worst_segments,
    write_error_csv,
)
from facetraj_engine.analysis.inspector import inspect_frame
from facetraj_engine.analysis.metrics import (
    condition_name,
    sweep_curves,
    table2_rows,
    write_sweep_csv,
    write_table2_csv,
)
from facetraj_engine.analysis.pc_modes import describe_mode, mode_displacement, mode_sd
from facetraj_engine.analysis.similarity import (
    cluster_phones,
    dendrogram,
    similarity_in_order,
    write_similarity_csv,
)
from facetraj_engine.data import PhoneSegment
from facetraj_engine.evaluation.scores import EvalResult, UtteranceScore, evaluate_utterance
from facetraj_engine.method.pipeline import synthesize


def score(split, smoothing, n, wf, lo, up, mode="phonetic", utt="u"):
    return UtteranceScore(split=split, mode=mode, smoothing=smoothing, n_context_phones=n,
                          whole_face=wf, lower_lip=lo, upper_lip=up, utterance=utt, speech_frames=10)


def test_cluster_groups_visemes():
    # two tight groups {p, b, m} and {s, z} far apart, plus a phone without tokens (NaN)
    pts = {"p": 0.0, "b": 0.1, "m": 0.2, "s": 5.0, "z": 5.1}
    phones = ["b", "m", "p", "s", "x", "z"]
    x = np.array([pts.get(p, np.nan) for p in phones])
    d = np.abs(x[:, None] - x[None, :])
    c = cluster_phones(SimpleNamespace(distances=d, phones=phones))
    assert sorted(c.order) == list(range(6))
    assert c.labels[-1] == "x"                              # no tokens: last
    for group in ({"p", "b", "m"}, {"s", "z"}):
        pos = sorted(c.labels.index(g) for g in group)
        assert pos == list(range(pos[0], pos[0] + len(group)))   # members sit together
    dg = dendrogram(c)
    assert len(dg.icoord) == 4                              # 5 leaves, 4 merges
    assert max(max(h) for h in dg.dcoord) == pytest.approx(c.linkage[:, 2].max())


def test_similarity_csv_round_trip(toy_model, tmp_path):
    c = cluster_phones(toy_model)
    path = write_similarity_csv(tmp_path / "s.csv", toy_model, 5.0, c.order)
    rows = list(csv.reader(path.open()))
    assert rows[0] == ["phone", *c.labels]
    got = np.array([[float(x) for x in r[1:]] for r in rows[1:]])
    want = toy_model.similarity(5.0)[np.ix_(c.order, c.order)]
    assert got == pytest.approx(want, abs=1e-5)
    assert similarity_in_order(toy_model, 5.0, c.order) == pytest.approx(want)
    assert np.diag(got) == pytest.approx(1.0)


def test_table2_rows_and_csv(tmp_path):
    res = EvalResult([
        score("test", "spline", 3, 0.5, 0.6, 0.7), score("train", "triangular", 3, 0.9, 0.8, 0.7),
        score("train", "triangular", 3, 0.7, 0.6, 0.5, utt="v"),
        score("test", "triangular", 3, 0.2, 0.3, 0.4, mode="acoustic"),
    ])
    rows = table2_rows(res)
    assert [r.name for r in rows] == ["Train (Triang.)", "Test (Spline)", "Test (Triang., acoustic only)"]
    assert rows[0].whole_face == pytest.approx(0.8) and rows[0].utterances == 2
    assert condition_name("train", "triangular") == "Train (Triang.)"
    path = write_table2_csv(tmp_path / "t2.csv", res)
    lines = list(csv.DictReader(path.open()))
    assert lines[0]["condition"] == "Train (Triang.)" and float(lines[0]["lower_lip"]) == pytest.approx(0.7)


def test_sweep_curves_and_csv(tmp_path):
    res = EvalResult([score(sp, "triangular", n, v, v, v) for sp, n, v in
                      [("train", 1, 0.95), ("train", 3, 0.9), ("test", 1, 0.6), ("test", 3, 0.7),
                       ("test", 3, 0.8)]])
    curves = {c.split: c for c in sweep_curves(res)}
    assert curves["train"].ns.tolist() == [1, 3]
    assert curves["test"].whole_face == pytest.approx([0.6, 0.75])
    rows = list(csv.DictReader(write_sweep_csv(tmp_path / "n.csv", res).open()))
    assert len(rows) == 4 and rows[-1] == {"split": "test", "N": "3", "whole_face": "0.75",
                                           "lower_lip": "0.75", "upper_lip": "0.75"}


def test_lip_error_segments_and_worst():
    m = SimpleNamespace(upper_lip=0, lower_lip=1)
    o = np.zeros((6, 2, 3))
    s = o.copy()
    s[3:, 1, 1] = 2.0                   # lower lip 2 mm off in frames 3-5
    e = lip_error(m, o, s)
    assert e[:, 1].tolist() == [0, 0, 0, 2, 2, 2] and e[:, 0].tolist() == [0] * 6
    phones = [PhoneSegment(0, 0.05, "sil"), PhoneSegment(0.05, 0.1, "m")]
    times = np.arange(6) / 60
    segs = segment_errors(phones, times, e, "u")
    assert [(x.label, x.error) for x in segs] == [("sil", pytest.approx(0.0)), ("m", pytest.approx(1.0))]
    assert worst_segments([*segs, SegmentError("v", "sil", 0, 1, 9.0)], 5)[0].label == "m"


def test_analyse_utterance_matches_evaluation(toy_model, toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    a = analyse_utterance(toy_model, utt, "test")
    ev = evaluate_utterance(toy_model, utt, "test", smoothings=("triangular",))[0]
    assert a.summary.whole_face == pytest.approx(ev.whole_face)
    assert a.summary.lower_lip == pytest.approx(ev.lower_lip)
    assert a.summary.upper_lip == pytest.approx(ev.upper_lip)
    assert a.lip_error.shape == (len(a.times), 2)
    assert a.summary.worst_label != "sil"
    seg = [s for s in a.segments if s.label == a.summary.worst_label and
           abs(0.5 * (s.start + s.end) - a.summary.worst_time) < 1e-9]
    assert seg and seg[0].error == pytest.approx(max(s.error for s in a.segments if s.label != "sil"))


def test_phone_errors_pooled(toy_model, toy_corpus, tmp_path):
    rep = error_report(toy_model, toy_corpus, ("test",))
    assert len(rep.utterances) == len(toy_corpus.info.test)
    labels = {p.phone for p in rep.phones}
    assert "m" in labels and "sil" in labels
    corr = [p.correlation for p in rep.phones if np.isfinite(p.correlation)]
    assert corr == sorted(corr)                               # worst first
    assert all(p.rms >= 0 for p in rep.phones)
    assert rep.worst == sorted(rep.worst, key=lambda s: -s.error)
    # one phone recomputed by hand from an analysis
    a = analyse_utterance(toy_model, toy_corpus.utterance(toy_corpus.info.test[0]), "test")
    pe = {p.phone: p for p in phone_errors([a])}
    sel = np.array(a.frame_phone) == "aa"
    e = a.lip_error[sel]
    assert pe["aa"].rms == pytest.approx(np.sqrt(np.mean(e**2)))
    assert pe["aa"].frames == int(sel.sum())
    rows = list(csv.DictReader(write_error_csv(tmp_path / "e.csv", rep).open()))
    assert len(rows) == len(rep.utterances)


def test_inspect_frame(toy_model, toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    res = synthesize(toy_model, utt.audio, utt.sample_rate, utt.phones, n_frames=utt.n_frames)
    f = 40
    ins = inspect_frame(toy_model, res, f)
    seg = res.segments[res.frame_segment[f]]
    assert ins.phone == seg.segment.label
    assert f"[{seg.segment.label}]" in ins.context
    assert [c[2] for c in ins.chosen] == seg.chosen.tolist()
    assert [c[1] for c in ins.chosen] == pytest.approx(seg.scores.tolist())
    assert len(ins.codewords) == 5 * len(seg.chosen)
    assert ins.weight_sum == pytest.approx(1.0)
    assert ins.gamma == res.frames.gamma[f]
    what = sum(c.weight * toy_model.codebook.lsf[c.index] for c in ins.codewords)
    assert ins.lsf_hat == pytest.approx(what)                 # eq 7
    w = [c.weight for c in ins.codewords]
    assert w == sorted(w, reverse=True)
    assert all(c.utterance in toy_model.train_utterances for c in ins.codewords)


def test_pc_modes(toy_model):
    sd = mode_sd(toy_model)
    assert sd == pytest.approx(np.sqrt(toy_model.pca.variances))
    d = mode_displacement(toy_model, 0, 2 * sd[0])
    assert d.ravel() == pytest.approx(2 * sd[0] * toy_model.pca.components[0])
    s = describe_mode(toy_model, 0)
    assert s.axis == "vertical"                               # the toy jaw moves vertically
    assert s.markers[0][0] in {"CHIN", "LL_C"}
    assert "PC1" in s.text()


def test_inspect_frame_acoustic_only(toy_model, toy_corpus):
    from facetraj_engine.config import SynthConfig

    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    res = synthesize(toy_model, utt.audio, utt.sample_rate, None, SynthConfig(mode="acoustic"),
                     n_frames=utt.n_frames)
    ins = inspect_frame(toy_model, res, 30, top=10)
    assert ins.phone == "" and ins.chosen == [] and len(ins.codewords) == 10
    assert sum(res.frames.weights[30]) == pytest.approx(1.0)
    assert ins.lsf_hz == pytest.approx(ins.lsf * toy_model.config.audio_rate / (2 * np.pi))


def test_inspect_frame_robust(toy_model, toy_corpus):
    """Robust mode: each candidate's target cost, label cost and origin, and the frame's label
    confidence, as the synthesis computed them (repeats of eq 4's codewords left out)."""
    from facetraj_engine.config import SynthConfig

    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    conf = np.full(len(utt.phones), 0.5)
    res = synthesize(toy_model, utt.audio, utt.sample_rate, utt.phones,
                     SynthConfig(mode="robust", robust_candidates=16, label_weight=2.0),
                     n_frames=utt.n_frames, confidence=conf)
    f = 40
    ins = inspect_frame(toy_model, res, f)
    assert ins.mode == "robust" and ins.confidence == 0.5
    fw = res.frames
    valid = np.isfinite(fw.acoustic_cost[f])
    assert len(ins.codewords) == int(valid.sum())
    assert ins.weight_sum == pytest.approx(1.0)
    for c in ins.codewords:
        assert c.label_cost == (0.0 if c.from_labels else pytest.approx(2.0 * 0.5))
        i = int(np.flatnonzero((fw.candidates[f] == c.index) & valid)[0])
        assert c.target_cost == pytest.approx(fw.acoustic_cost[f, i])
    assert any(not c.from_labels for c in ins.codewords)
    assert sum(c.from_labels for c in ins.codewords) == 15
