"""The coarse LSF index for acoustic-only synthesis (engine/method/lsf_index.py): k-means by hand, the
probed search against a brute-force eq 5 search written here, and its place in the model."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import edited_model_file

from facetraj.cli import build_parser
from facetraj.options import synth_config
from facetraj_engine.config import SynthConfig
from facetraj_engine.method.codebook import Codebook
from facetraj_engine.method.lsf_index import build_index, kmeans
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.synthesis import perceptual_weights


def random_lsf(n: int, p: int = 6, seed: int = 0) -> np.ndarray:
    return np.sort(np.random.default_rng(seed).uniform(0.05, 3.0, (n, p)), axis=1)


def brute_nearest(w: np.ndarray, lsf: np.ndarray, count: int, among: np.ndarray | None = None) -> set:
    """Eq 5 written out: d_i = sum_k h_k |w_k - L_ik|, the ``count`` smallest among ``among``."""
    among = np.arange(len(lsf)) if among is None else among
    h = perceptual_weights(w)
    d = (np.abs(w - lsf[among]) * h).sum(axis=1)
    return set(among[np.argsort(d, kind="stable")[:count]].tolist())


def test_kmeans_by_hand():
    x = np.array([[0.0, 0.0], [0.0, 2.0], [10.0, 0.0], [10.0, 2.0], [10.0, 4.0]])
    c, labels = kmeans(x, 2, seed=3)
    by_size = sorted(np.bincount(labels))
    assert by_size == [2, 3]
    got = sorted(map(tuple, np.round(c, 9)))
    assert got == [(0.0, 1.0), (10.0, 2.0)]                      # the two group means
    assert labels[0] == labels[1] != labels[2] == labels[3] == labels[4]
    c, labels = kmeans(x, 5)
    assert sorted(labels.tolist()) == [0, 1, 2, 3, 4]            # one point per cell
    with pytest.raises(ValueError, match="between 1 and 5"):
        kmeans(x, 6)


def test_index_cells_partition_the_codebook():
    lsf = random_lsf(900)
    ix = build_index(lsf, iterations=100)
    assert ix.n_cells == 30                                        # round(sqrt(900))
    assert sorted(ix.order.tolist()) == list(range(900))
    assert ix.offsets[0] == 0 and ix.offsets[-1] == 900 and np.all(np.diff(ix.offsets) >= 0)
    # converged k-means: every codeword sits in the cell of its nearest centroid
    cell = np.repeat(np.arange(ix.n_cells), ix.sizes)
    d2 = ((lsf[ix.order][:, None, :] - ix.centroids[None]) ** 2).sum(axis=2)
    assert np.array_equal(d2.argmin(axis=1), cell)
    assert build_index(lsf, n_cells=7).n_cells == 7


def test_probing_every_cell_is_the_exact_search():
    lsf = random_lsf(600, seed=1)
    ix = build_index(lsf)
    w = random_lsf(40, seed=2)
    got = ix.nearest(w, lsf, count=12, probe=ix.n_cells)
    for t in range(len(w)):
        assert set(got[t].tolist()) == brute_nearest(w[t], lsf, 12)


def test_probed_search_is_exact_within_the_opened_cells():
    lsf = random_lsf(600, seed=4)
    ix = build_index(lsf)
    w = random_lsf(30, seed=5)
    probe = 3
    got = ix.nearest(w, lsf, count=10, probe=probe)
    for t in range(len(w)):
        h = perceptual_weights(w[t])
        dc = (np.abs(w[t] - ix.centroids) * h).sum(axis=1)          # eq 5 to each centroid
        cells = np.argsort(dc)[:probe]
        members = np.concatenate([ix.order[ix.offsets[c]:ix.offsets[c + 1]] for c in cells])
        assert set(got[t].tolist()) == brute_nearest(w[t], lsf, 10, members)


def test_probe_grows_when_the_cells_are_too_small():
    lsf = random_lsf(400, seed=6)
    ix = build_index(lsf, n_cells=40)                               # about 10 per cell
    w = random_lsf(20, seed=7)
    got = ix.nearest(w, lsf, count=60, probe=1)
    assert got.shape == (20, 60)
    assert all(len(set(row.tolist())) == 60 for row in got)         # no padding slipped in
    assert ix.min_probe(60) > 1
    with pytest.raises(ValueError, match="covers 400 codewords"):
        ix.nearest(w, lsf[:300], count=5, probe=2)


def test_empty_cells_are_harmless():
    """Repeated codewords can leave k-means cells empty (two equal starting centroids)."""
    lsf = np.repeat(random_lsf(30, seed=8), 10, axis=0)            # every codeword 10 times
    ix = build_index(lsf, n_cells=20, seed=1)
    assert (ix.sizes == 0).any()
    w = random_lsf(15, seed=9)
    got = ix.nearest(w, lsf, count=10, probe=ix.n_cells)
    for t in range(len(w)):
        h = perceptual_weights(w[t])
        d = (np.abs(w[t] - lsf) * h).sum(axis=1)
        np.testing.assert_allclose(np.sort(d[got[t]]), np.sort(d)[:10])   # ties: any of the copies


def test_model_keeps_its_index(toy_model, tmp_path):
    assert toy_model.index is not None
    assert toy_model.index.n_codewords == len(toy_model.codebook.lsf)
    # a model file written before the index existed loads, and builds it on first use
    old = edited_model_file(toy_model.save(tmp_path / "m.npz"), tmp_path / "old.npz",
                            ix_centroids=None, ix_order=None, ix_offsets=None)
    back = Model.load(old)
    assert back.index is None
    assert np.array_equal(back.lsf_index().order, toy_model.index.order)
    # a model given another codebook gets a new index, not the stale one
    cb = toy_model.codebook
    double = Codebook(np.tile(cb.contexts, (2, 1)), np.tile(cb.lsf, (2, 1)), np.tile(cb.pcs, (2, 1)),
                      np.tile(cb.token_utt, 2), np.tile(cb.token_start, 2), np.tile(cb.token_end, 2),
                      cb.n_per_phone)
    bigger = replace(toy_model, codebook=double)
    assert bigger.lsf_index().n_codewords == 2 * len(cb.lsf)
    assert toy_model.index.n_codewords == len(cb.lsf)


def test_default_acoustic_search_agrees_with_the_whole_codebook(default_model, default_corpus):
    """On the default corpus the indexed search (the default) gives nearly the face of the paper's
    whole-codebook search, and the exact K-nearest search sits in between."""
    utt = default_corpus.utterance(default_corpus.info.test[0])
    faces = {}
    for name, cfg in {"full": SynthConfig(mode="acoustic", acoustic_prefilter=None),
                      "exact": SynthConfig(mode="acoustic", acoustic_probe=None),
                      "indexed": SynthConfig(mode="acoustic")}.items():
        faces[name] = synthesize(default_model, utt.audio, utt.sample_rate, None, cfg,
                                 n_frames=utt.n_frames).markers
    lip = default_model.lower_lip

    def corr(a, b):
        return np.corrcoef(a[:, lip, 1], b[:, lip, 1])[0, 1]

    assert corr(faces["indexed"], faces["exact"]) > 0.99
    assert corr(faces["indexed"], faces["full"]) > 0.95


def test_cli_acoustic_search_options():
    parser = build_parser()
    base = ["synth", "m.npz", "a.wav", "-o", "o.c3d"]
    assert synth_config(parser.parse_args(base)) == SynthConfig()
    cfg = synth_config(parser.parse_args([*base, "--acoustic-prefilter", "all"]))
    assert cfg.acoustic_prefilter is None
    cfg = synth_config(parser.parse_args([*base, "--acoustic-prefilter", "64", "--acoustic-probe", "ALL"]))
    assert cfg.acoustic_prefilter == 64 and cfg.acoustic_probe is None
    with pytest.raises(SystemExit):
        parser.parse_args([*base, "--acoustic-probe", "0"])


def test_the_nearest_alone_is_the_first_of_the_nearest_few():
    """count=1 (the voice match) by argmin: the codeword the general search ranks first."""
    lsf = random_lsf(600, seed=6)
    ix = build_index(lsf)
    w = random_lsf(50, seed=7)
    one = ix.nearest(w, lsf, count=1, probe=4)[:, 0]
    few = ix.nearest(w, lsf, count=5, probe=4)
    h = perceptual_weights(w)
    d = (np.abs(w[:, None, :] - lsf[few]) * h[:, None, :]).sum(axis=2)
    np.testing.assert_array_equal(one, few[np.arange(len(w)), d.argmin(axis=1)])


def test_the_layout_is_the_grouped_codebook_transposed_in_float32():
    lsf = np.sort(np.random.default_rng(6).uniform(0.1, 3.0, (300, 8)), axis=1)
    ix = build_index(lsf, 10)
    want = np.ascontiguousarray(ix.grouped(lsf).astype(np.float32).T)
    got = ix.layout(lsf)
    assert got.dtype == np.float32 and got.flags.c_contiguous and np.array_equal(got, want)


def test_the_search_finds_the_nearest_alone_on_its_way():
    """``first``: each frame's nearest codeword as count=1 finds it when it opens as many cells
    (``probes``), from the search of the nearest 128 (the voice match reads it, issue 48); with
    duplicated codewords (ties: the first) and frames far from every cell."""
    lsf = random_lsf(3000, seed=8)
    lsf[1500:1600] = lsf[100:200]                        # equal distances: the first wins
    ix = build_index(lsf)
    w = np.concatenate([random_lsf(400, seed=9), lsf[100:140] + 1e-4])
    for count, probe in ((128, 8), (40, 3), (5, 1)):
        first = np.full(len(w), -1)
        few = ix.nearest(w, lsf, count, probe, first=first)
        assert ix.probes(count, probe) == ix.probes(1, ix.probes(count, probe))
        one = ix.nearest(w, lsf, 1, ix.probes(count, probe))[:, 0]
        np.testing.assert_array_equal(first, one)
        assert all(f in row for f, row in zip(first, few, strict=True))        # the nearest kept
        np.testing.assert_array_equal(few, ix.nearest(w, lsf, count, probe))   # as without it


def test_probes_grow_with_the_count():
    """A cell-poor index opens more cells for more codewords (the voice match's nearest then
    comes from its own search)."""
    lsf = random_lsf(500, seed=10)
    ix = build_index(lsf, 50)
    assert ix.probes(1, 8) == 8 and ix.probes(10_000, 8) == ix.n_cells
    assert ix.probes(200, 8) == max(8, ix.min_probe(200)) > 8


@pytest.mark.parametrize("seed", range(6))
def test_rows_grouped_by_width_select_what_the_whole_rows_select(seed):
    """The partition by groups of like widths (inf past each row's width) gives the columns of
    the whole rows', ties at the edge to the first columns."""
    from facetraj_engine.method.lsf_index import _smallest

    rng = np.random.default_rng(seed)
    rows, count = int(rng.integers(8, 300)), int(rng.integers(2, 40))
    widths = rng.integers(count, count + 200, rows)
    d = np.full((rows, int(widths.max())), np.inf, dtype=np.float32)
    for t, n in enumerate(widths):
        d[t, :n] = rng.integers(0, 30, n)                  # many equal values
    np.testing.assert_array_equal(_smallest(d, count, widths), _smallest(d, count))
    want = np.array([np.sort(np.argsort(row, kind="stable")[:count]) for row in d])
    np.testing.assert_array_equal(_smallest(d, count), want)
