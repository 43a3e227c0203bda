"""Training streams the corpus (issue 41): each utterance read, analysed and let go in turn, the
steps that need every frame (the PCA, the closure statistics) from sufficient statistics merged an
utterance at a time; the result equals the computation on every frame at once to rounding."""

from __future__ import annotations

import itertools
import weakref
from dataclasses import dataclass, field

import numpy as np
import pytest

from facetraj_engine.data import PhoneSegment
from facetraj_engine.io.corpus import Corpus
from facetraj_engine.method.closure import ClosureGather, closure_part
from facetraj_engine.method.moments import Moments
from facetraj_engine.method.pca import fit_pca, pca_of
from facetraj_engine.method.training import DETECTOR_UTTERANCES, train


def _every_frame(model, corpus) -> np.ndarray:
    """The complete head-normalised marker vectors of every training utterance, all at once."""
    rows = []
    for utt_id in model.train_utterances:
        normed = model.normalise_markers(corpus.utterance(utt_id).markers)
        flat = normed.reshape(len(normed), -1)
        rows.append(flat[np.isfinite(flat).all(axis=1)])
    return np.concatenate(rows)


def test_the_streamed_pca_equals_the_pca_of_every_frame_at_once(default_model, default_corpus):
    """On the default corpus (186 utterances, 25,000 frames of 162 coordinates): the PCA from the
    moments merged an utterance at a time against the eigen-decomposition of the scatter matrix of
    every frame at once (what training computed before it streamed)."""
    x = _every_frame(default_model, default_corpus)
    mean = x.mean(axis=0)
    centred = x - mean
    ev, vec = np.linalg.eigh(centred.T @ centred)
    ev, vec = ev[::-1], vec[:, ::-1]
    pca = default_model.pca
    k = pca.n_components
    batch = vec[:, :k].T * np.sign(vec[np.abs(vec[:, :k]).argmax(axis=0), np.arange(k)])[:, None]
    np.testing.assert_allclose(pca.mean, mean, rtol=0, atol=1e-9)
    np.testing.assert_allclose(pca.components, batch, rtol=0, atol=1e-9)
    np.testing.assert_allclose(pca.variances, ev[:k] / (len(x) - 1), rtol=1e-12)
    assert pca.total_variance == pytest.approx(ev.clip(0).sum() / (len(x) - 1), rel=1e-12)
    np.testing.assert_allclose(default_model.coord_std, x.std(axis=0), rtol=1e-12)


def test_moments_merged_in_blocks_equal_the_moments_of_all_rows():
    rng = np.random.default_rng(3)
    x = rng.normal(50.0, 3.0, (1000, 6)) @ rng.normal(size=(6, 6))
    whole = Moments.of(x)
    merged = Moments.empty(6)
    for a, b in [(0, 1), (1, 17), (17, 17), (17, 400), (400, 1000)]:   # one empty block
        merged = merged.merged(Moments.of(x[a:b]))
    assert merged.n == 1000
    np.testing.assert_allclose(merged.mean, whole.mean, rtol=1e-14)
    np.testing.assert_allclose(merged.scatter, whole.scatter, rtol=1e-11)
    np.testing.assert_allclose(merged.std(), x.std(axis=0), rtol=1e-12)
    a, b = fit_pca(x, 3), pca_of(merged, 3)
    np.testing.assert_allclose(a.components, b.components, atol=1e-10)


def _segs(*spans: tuple[float, float, str]) -> list[PhoneSegment]:
    return [PhoneSegment(a, b, lab) for a, b, lab in spans]


def regression_direction(pcs: np.ndarray, aperture: np.ndarray) -> np.ndarray:
    """The oracle of the closing direction, from every frame at once: ``d = cov(p, a) / var(a)``
    over the finite rows (the gather's comes from moments merged an utterance at a time)."""
    ok = np.isfinite(pcs).all(axis=1) & np.isfinite(aperture)
    p = pcs[ok] - pcs[ok].mean(axis=0)
    a = aperture[ok] - aperture[ok].mean()
    return p.T @ a / (a @ a)


def test_closure_statistics_gathered_an_utterance_at_a_time():
    """The medians (closed aperture, rest face) exactly as of every frame at once, the closing
    direction to rounding; and the fallbacks of a corpus with no pause or no /p b m/: the rest
    face from every frame, the closed aperture the 10th percentile of every frame's."""
    rng = np.random.default_rng(7)
    g, a0, rate = np.array([1.0, -0.5, 0.25]), 10.0, 10.0
    pcs = [rng.normal(size=(30, 3)) for _ in range(3)]
    pcs[1][4] = np.nan
    labelled = [_segs((0, 1, "sil"), (1, 2, "b"), (2, 3, "aa")),
                _segs((0, 0.5, "aa"), (0.5, 1.5, "m"), (1.5, 3, "sil")),
                _segs((0, 3, "aa"))]
    gather = ClosureGather(3)
    for p, segs in zip(pcs, labelled, strict=True):
        gather.add(closure_part(p, segs, rate, a0, g))
    stats = gather.stats()
    every = np.concatenate(pcs)
    ok = np.isfinite(every).all(axis=1)
    apertures = a0 + every @ g
    t = [np.arange(30) / rate] * 3
    minima = [np.nanmin((a0 + pcs[0] @ g)[(t[0] >= 1) & (t[0] < 2)]),
              np.nanmin((a0 + pcs[1] @ g)[(t[1] >= 0.5) & (t[1] < 1.5)])]
    rest = np.concatenate([pcs[0][:10], pcs[1][15:]])
    assert stats.closed == np.median(minima)
    np.testing.assert_array_equal(stats.rest, np.median(rest[np.isfinite(rest).all(axis=1)], axis=0))
    np.testing.assert_allclose(stats.direction, regression_direction(every[ok], apertures[ok]),
                               rtol=1e-12)
    # no pause, no /p b m/ anywhere: the fallbacks, from every frame
    gather = ClosureGather(3)
    for p in pcs:
        gather.add(closure_part(p, _segs((0, 3, "aa")), rate, a0, g))
    stats = gather.stats()
    assert stats.closed == pytest.approx(np.nanpercentile(apertures, 10), rel=1e-14)
    np.testing.assert_array_equal(stats.rest, np.median(every[ok], axis=0))


@dataclass
class _Watched(Corpus):
    """A corpus that notes how many of its loaded utterances are alive at each load."""

    alive: list = field(default_factory=list)
    most: int = 0
    loads: int = 0
    marker_reads: int = 0

    def utterance(self, utt_id):
        utt = super().utterance(utt_id)
        self.alive = [r for r in self.alive if r() is not None] + [weakref.ref(utt)]
        self.most, self.loads = max(self.most, len(self.alive)), self.loads + 1
        return utt

    def markers(self, utt_id, n_frames):
        self.marker_reads += 1
        return super().markers(utt_id, n_frames)


def test_training_holds_one_utterance_at_a_time(toy_corpus, toy_model):
    """Each utterance is let go before the next is read; after the first pass only its markers
    are read again (and the detector's few whole); and the model is the one of the corpus read
    whole."""
    watched = _Watched(toy_corpus.root, toy_corpus.info)
    model = train(watched)
    n = len(toy_corpus.info.train)
    assert watched.most == 1
    # pass 1, the voice reference's and the closure detector's (pass 4)
    assert watched.loads == n + min(n, 40) + min(n, DETECTOR_UTTERANCES)
    assert watched.marker_reads == 2 * n - min(n, 40)  # passes 2 and 3
    np.testing.assert_array_equal(model.codebook.lsf, toy_model.codebook.lsf)
    np.testing.assert_array_equal(model.pca.components, toy_model.pca.components)


def test_training_in_two_processes_equals_one_to_the_bit(default_corpus, default_model):
    """Every sum is merged in the utterances' order, and BLAS runs one thread in the serial run
    as in the workers: on the default corpus the model does not depend on ``workers``."""
    b = train(default_corpus, workers=2)
    a = default_model
    for x, y in ((a.codebook.lsf, b.codebook.lsf), (a.codebook.pcs, b.codebook.pcs),
                 (a.codebook.contexts, b.codebook.contexts), (a.means, b.means),
                 (a.index.order, b.index.order), (a.pca.components, b.pca.components),
                 (a.pca.mean, b.pca.mean), (a.coord_std, b.coord_std), (a.reference, b.reference),
                 (a.closure.direction, b.closure.direction), (a.closure.rest, b.closure.rest)):
        np.testing.assert_array_equal(x, y)
    assert (a.closure.closed, a.voice_distance) == (b.closure.closed, b.voice_distance)


def test_the_neutral_pose_in_blocks_is_the_pose_of_all_frames_at_once():
    """``reference_pose`` fits a block of frames at a time (what it holds stays the same whatever
    the corpus's length) and sums the aligned frames one after the other: the same bits as the
    mean of every frame aligned at once."""
    from facetraj_engine.corpusgen.face import _rotation
    from facetraj_engine.method.markers import kabsch, reference_pose

    rng = np.random.default_rng(11)
    pose = rng.normal(0, 30, (4, 3))
    angles = rng.normal(0, 0.05, (500, 3))
    frames = np.stack([pose @ _rotation(*a).T + rng.normal(0, 2, 3) for a in angles])
    frames += rng.normal(0, 0.3, frames.shape)
    ref = frames[0]
    for _ in range(3):                                     # the computation of all at once
        rot, trans = kabsch(frames, np.broadcast_to(ref, frames.shape))
        ref = (np.einsum("tij,tmj->tmi", rot, frames) + trans[:, None, :]).mean(axis=0)
    for block in (1, 7, 500, 8192):
        np.testing.assert_array_equal(reference_pose(frames, np.arange(4), block=block), ref)


def test_training_reports_its_progress_through_the_passes(toy_corpus):
    """The bar of `facetraj train` (with its time left): fractions that never go back, from 0 to
    1, each pass naming the utterance it is on."""
    seen: list[tuple[float, str]] = []
    train(toy_corpus, progress=lambda f, m: seen.append((f, m)), workers=2)
    fractions = [f for f, _ in seen]
    assert fractions[0] == 0.0 and fractions[-1] == 1.0
    assert all(b >= a for a, b in itertools.pairwise(fractions))
    first = toy_corpus.info.train[0]
    for what in ("reading", "PCA", "codebook"):
        assert f"{what}: {first}" in [m for _, m in seen]
