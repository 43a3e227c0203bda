"""Training (paper sections 2.1-2.2), step by step: the training set read, head motion removed,
PCA, the audio-visual codebook, the phone means and distances of eqs 1-2, and the LSF index.

The corpus is streamed: each utterance is read, analysed and let go in turn (in ``workers``
processes, :func:`facetraj_engine.fanout.fan_out`), so that only what the model keeps grows with the
corpus (the codewords, the PCA's moments, the closure statistics). The steps that need every
frame come from sufficient statistics gathered an utterance at a time, in passes over the
utterances (:mod:`facetraj_engine.method.training_set`):

1. every utterance loaded whole: its labels checked, its marker gaps filled, every fifth frame
   of its fixed markers kept (the neutral pose, :func:`reference_pose`), its codewords' LSF
   vectors computed (they need the audio, not the PCA);
2. its markers read again and moved into the head frame of that pose: the count, mean and
   scatter matrix of its complete frames, merged in order (:class:`~facetraj_engine.method.moments.Moments`),
   whose eigenvectors are the PCA (:func:`~facetraj_engine.method.pca.pca_of`);
3. its markers read a third time: their PCs, the codewords' PC vectors, its share of the
   closure statistics; and the audio of the few utterances the voice reference ``D0`` is
   measured on;
4. the audio of (up to :data:`DETECTOR_UTTERANCES`) utterances read again, for the
   bilabial-closure detector's frames (its logistic fit needs them all at once: a bounded
   sample of a long corpus).

The model equals the one of all frames at once to rounding (the PCA to about 1e-12), and the
same bits whatever ``workers``: every sum is merged in the utterances' order.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..config import TrainConfig
from ..data import PhoneSegment, Utterance
from ..errors import InputError, warn_file
from ..fanout import Skips, fan_out
from ..io.corpus import Corpus
from ..io.labelfiles import validate_phones
from ..labels.phoneset import SILENCE, apply_label_map
from ..progress import Progress, no_progress
from ..threads import one_blas_thread
from .closure import ClosureGather, ClosurePart, aperture_functional, closure_part
from .closure_detector import ClosureDetector, bilabial_frames, train_detector, utterance_inputs
from .closure_search import left_out_rows
from .codebook import Codebook, codeword_times, concatenate, interpolate_frames
from .context import context_ids
from .lsf_index import build_index
from .markers import fill_gaps, reference_pose, remove_head_motion
from .model import Model, analysed_lsf
from .moments import Moments
from .pca import PCA, pca_of
from .similarity import distance_scale, phone_distances, phone_means
from .speech import speech_mask
from .training_set import MarkerSetup, TrainingSet
from .voice_match import training_voice_distance

log = logging.getLogger(__name__)

#: every how many frames the fixed markers are kept for the neutral pose (paper 2.1)
POSE_STEP = 5
#: the training utterances ``D0`` is measured on (evenly spaced), and speech frames of each
VOICE_UTTERANCES, VOICE_FRAMES = 40, 60
#: the training utterances the bilabial-closure detector is fitted on (evenly spaced): every one
#: of a corpus up to this many (the default corpus trains on 186), a bounded sample of a longer
#: one, so that what the fit holds stops growing with the corpus
DETECTOR_UTTERANCES = 400

__all__ = ["MarkerSetup", "marker_roles", "train"]


@dataclass
class _MarkerRoles:
    """Marker indices of the fixed markers, the lip centres and the lip corners."""

    fixed: np.ndarray
    upper_lip: int
    lower_lip: int
    lip_corners: list[int]


def marker_roles(names: Sequence[str], setup: MarkerSetup) -> _MarkerRoles:
    """The indices of ``setup``'s markers in ``names``; an unknown name is an :class:`InputError`."""
    index = {n: i for i, n in enumerate(names)}
    try:
        return _MarkerRoles(np.array([index[n] for n in setup.fixed], dtype=int), index[setup.upper_lip],
                            index[setup.lower_lip], [index[n] for n in setup.lip_corners])
    except KeyError as exc:
        raise InputError(None, f"marker {exc} is not in the marker set") from exc


@dataclass
class _Passes:
    """What the three passes share: the training set, the settings, the marker roles, the
    worker processes and the progress range of each pass."""

    source: TrainingSet
    config: TrainConfig
    roles: _MarkerRoles
    label_map: Mapping[str, str] | None
    workers: int
    progress: Progress

    def fan_out(self, fn: Callable[[int], Any], names: Sequence[str], lo: float, hi: float,
                what: str, skip: Skips | None = None) -> Iterator[tuple[int, Any]]:
        """``(j, fn(j))`` for the utterances ``j`` named ``names[j]``, in order, in the worker
        processes, progress from ``lo`` to ``hi``. With ``skip``, those left out are recorded
        there by name."""
        local = Skips(skip.noun) if skip is not None else None
        yield from fan_out(fn, range(len(names)), self.workers, skip=local,
                           progress=lambda f, m: self.progress(lo + (hi - lo) * f, m),
                           describe=lambda j: f"{what}: {names[j]}")
        if skip is not None:
            skip.tried.update(names)
            skip.bad.update({names[j]: message for j, message in local.bad.items()})

    def normalised(self, markers: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """Gap filling and head-motion removal (paper 2.1), ``(T, M, 3)`` in the head frame."""
        filled, _ = fill_gaps(markers, self.source.marker_rate, self.config.max_gap_s)
        return remove_head_motion(filled, self.roles.fixed, reference)


# --------------------------------------------------------------------------- pass 1: reading
@dataclass
class _Segments:
    """Phone segments held as three arrays (a few bytes a phone, not a Python object each)."""

    starts: np.ndarray
    ends: np.ndarray
    labels: np.ndarray

    @classmethod
    def of(cls, segs: Sequence[PhoneSegment]) -> _Segments:
        return cls(np.array([s.start for s in segs], dtype=np.float64),
                   np.array([s.end for s in segs], dtype=np.float64),
                   np.array([s.label for s in segs], dtype=str))

    def segments(self) -> list[PhoneSegment]:
        return [PhoneSegment(float(a), float(b), str(lab))
                for a, b, lab in zip(self.starts, self.ends, self.labels, strict=True)]


@dataclass
class _Read:
    """Pass 1's result for one utterance: what the later passes and the model need of it."""

    name: str
    n_frames: int
    phones: _Segments                   # as labelled: the phone set, the closure statistics
    tokens: _Segments                   # checked and tidied: the codebook's phone tokens
    kind: str
    pose: np.ndarray                    # every POSE_STEP-th frame of the fixed markers, filled
    lsf: np.ndarray | None = None       # the codewords' LSF vectors
    lsf_context: np.ndarray | None = None

    def times(self, config: TrainConfig) -> np.ndarray:
        """The codeword times ``(tokens, n)``."""
        return codeword_times(self.tokens.starts, self.tokens.ends, config.codewords_per_phone,
                              config.placement)


def _check_utterance(utt: Utterance, names: Sequence[str]) -> None:
    if utt.markers is None:
        raise InputError(utt.name, "the utterance has no marker data to train on")
    if list(utt.marker_names) != list(names):
        raise InputError(utt.name, f"marker set differs from the first utterance "
                                   f"({len(utt.marker_names)} vs {len(names)} markers)")
    if utt.n_frames < 2:
        raise InputError(utt.name, "only one marker frame")


def _read(p: _Passes, k: int) -> _Read:
    """Pass 1 on utterance ``k``: loaded and checked, its fixed markers sampled for the neutral
    pose, its codewords' LSF vectors (at ``codewords_per_phone`` times per phone)."""
    config, utt = p.config, p.source.utterance(k)
    _check_utterance(utt, p.source.marker_names)
    segments = validate_phones(utt.phones, utt.duration, utt.name)
    filled, valid = fill_gaps(utt.markers, p.source.marker_rate, config.max_gap_s)
    if (~valid).any():
        warn_file(log, utt.name, "frames with marker gaps left out",
                  f"{(~valid).sum()} frames with gaps over {config.max_gap_s * 1000:.0f} ms "
                  f"left out", logging.INFO)
    read = _Read(utt.name, utt.n_frames, _Segments.of(utt.phones), _Segments.of(segments),
                 utt.provenance.kind, filled[::POSE_STEP][:, p.roles.fixed])
    times = read.times(config).ravel()
    read.lsf = analysed_lsf(config, utt.audio, utt.sample_rate, times)
    if config.lsf_context_frames > 0:
        off = config.lsf_context_frames / p.source.marker_rate
        read.lsf_context = np.stack([analysed_lsf(config, utt.audio, utt.sample_rate,
                                                  np.clip(times + o, 0, None)) for o in (-off, off)],
                                    axis=1)
    return read


def _read_all(p: _Passes, skip: Skips | None) -> tuple[list[int], list[_Read]]:
    """Pass 1 over every utterance: the indices kept (a bad file stops training with its error,
    or with ``skip`` its utterance is left out) and what was read of each."""
    kept, reads = [], []
    for k, read in p.fan_out(lambda k: _read(p, k), p.source.names, 0.0, 0.45, "reading", skip):
        kept.append(k)
        reads.append(read)
    if not reads:
        raise InputError(None, "no training utterances" + (
            " left (every one was skipped)" if len(p.source) or skip else ""))
    return kept, reads


# --------------------------------------------------------------------------- pass 2: the PCA
def _face_pca(p: _Passes, kept: Sequence[int], reads: Sequence[_Read], reference: np.ndarray
              ) -> tuple[PCA, np.ndarray]:
    """The PCA of the complete head-normalised marker vectors and each coordinate's std, from
    their moments gathered an utterance at a time."""
    def moments(j: int) -> Moments:
        normed = p.normalised(p.source.markers(kept[j], reads[j].n_frames), reference)
        flat = normed.reshape(normed.shape[0], -1)
        return Moments.of(flat[np.isfinite(flat).all(axis=1)])

    total = Moments.empty(3 * len(p.source.marker_names))
    for _, m in p.fan_out(moments, [r.name for r in reads], 0.45, 0.6, "PCA"):
        total = total.merged(m)
    if total.n < 2:
        raise InputError(None, "no complete marker frames to train on")
    pca = pca_of(total, p.config.n_components, p.config.variance_target)
    log.info("PCA: %d components explain %.2f %% of the variance", pca.n_components,
             100 * pca.explained_ratio.sum())
    return pca, total.std()


# --------------------------------------------------------------------------- pass 3: codewords
@dataclass
class _Codewords:
    """Pass 3's result for one utterance: its codewords' PC vectors and which tokens have
    complete marker data, its share of the closure statistics, and (for the few utterances
    ``D0`` is measured on) the LSF vectors of its speech frames."""

    pcs: np.ndarray
    ok: np.ndarray
    closure: ClosurePart
    voice: np.ndarray | None = None


def _codewords(p: _Passes, k: int, read: _Read, reference: np.ndarray, pca: PCA,
               aperture: tuple[float, np.ndarray], voice: bool) -> _Codewords:
    """Pass 3 on utterance ``k``: PC vectors at the codeword times (tokens without complete
    marker data left out), its closure statistics, and its voice frames when ``voice``."""
    config, rate = p.config, p.source.marker_rate
    utt = p.source.utterance(k) if voice else None
    markers = utt.markers if utt is not None else p.source.markers(k, read.n_frames)
    normed = p.normalised(markers, reference)
    pcs = pca.transform(normed.reshape(normed.shape[0], -1))       # NaN rows stay NaN
    times = read.times(config)
    cw_pcs = interpolate_frames(pcs, rate, times.ravel())
    n = config.codewords_per_phone
    ok = np.isfinite(cw_pcs).all(axis=1).reshape(-1, n).all(axis=1)
    ok &= times[:, -1] <= (normed.shape[0] - 1) / rate + 0.5 / rate
    if (~ok).any():
        warn_file(log, read.name, "phone tokens without complete marker data left out",
                  f"{(~ok).sum()} phone tokens without complete marker data left out", logging.INFO)
    part = closure_part(pcs, read.phones.segments(), rate, *aperture)
    return _Codewords(cw_pcs[np.repeat(ok, n)], ok, part,
                      _voice_frames(config, utt) if utt is not None else None)


def _voice_frames(config: TrainConfig, utt: Utterance) -> np.ndarray:
    """The LSF vectors of (up to :data:`VOICE_FRAMES` evenly spaced) speech frames of ``utt``."""
    times = utt.frame_times()
    keep = np.flatnonzero(speech_mask(utt.audio, utt.sample_rate, times))
    if keep.size:
        keep = keep[np.linspace(0, keep.size - 1, min(keep.size, VOICE_FRAMES)).astype(int)]
    return analysed_lsf(config, utt.audio, utt.sample_rate, times[keep])


def _codebook(p: _Passes, kept: Sequence[int], reads: Sequence[_Read], reference: np.ndarray,
              pca: PCA, pid: Mapping[str, int], closure: ClosureGather, voice: Sequence[int]
              ) -> tuple[Codebook, dict[int, np.ndarray]]:
    """Pass 3 over every utterance: the codebook (context-phones, LSF and PC codewords), the
    closure statistics gathered into ``closure``, and the voice frames of utterances ``voice``
    (positions in ``kept``)."""
    aperture = aperture_functional(pca, p.roles.upper_lip, p.roles.lower_lip)
    picked = set(voice)
    config, n = p.config, p.config.codewords_per_phone
    parts, frames = [], {}

    def work(j: int) -> _Codewords:
        return _codewords(p, kept[j], reads[j], reference, pca, aperture, j in picked)

    for j, done in p.fan_out(work, [r.name for r in reads], 0.6, 0.9, "codebook"):
        read = reads[j]
        ids = [pid[apply_label_map(str(lab), p.label_map)] for lab in read.tokens.labels]
        ctx = context_ids(ids, config.context, pid[SILENCE])
        keep, ok = np.repeat(done.ok, n), done.ok
        parts.append(Codebook(ctx[ok], read.lsf[keep], done.pcs, np.full(ok.sum(), j),
                              read.tokens.starts[ok], read.tokens.ends[ok], n,
                              None if read.lsf_context is None else read.lsf_context[keep]))
        read.lsf = read.lsf_context = None                      # held by the part now
        closure.add(done.closure)
        if done.voice is not None:
            frames[j] = done.voice
    return concatenate(parts), frames


# --------------------------------------------------------------------------- the whole
def train(utterances: Iterable[Utterance] | Corpus, setup: MarkerSetup | None = None,
          config: TrainConfig | None = None, progress: Progress | None = None,
          label_map: Mapping[str, str] | None = None, workers: int = 1,
          skip: Skips | None = None) -> Model:
    """Train a model (paper sections 2.1-2.2) on utterances with markers and phone labels.

    Given a :class:`~facetraj_engine.io.corpus.Corpus`, its ``train`` split is used and the marker roles come
    from ``corpus.json``; otherwise pass ``setup``.

    Steps: gap filling; head-motion removal against a Procrustes-mean neutral pose of the fixed
    markers; PCA; context-phones; LSF and PC vectors at 5 codeword times per phone; eq 1-2 phone
    means and distances; the coarse LSF index of acoustic-only synthesis.

    The corpus is streamed (the module's docstring), in ``workers`` processes
    (:func:`facetraj_engine.fanout.fan_out`; the model equals the serial run's). A bad file stops training
    with its error, or with ``skip`` its utterance is left out (``--skip-bad``).
    """
    config = config or TrainConfig()
    progress = progress or no_progress
    source = TrainingSet.of(utterances, setup)
    if not len(source):
        raise InputError(None, "no training utterances")
    roles = marker_roles(source.marker_names, source.setup)
    p = _Passes(source, config, roles, label_map, workers, progress)
    with one_blas_thread():          # as in the workers: the same sums whatever ``workers``
        kept, reads = _read_all(p, skip)
        progress(0.45, "neutral pose")
        reference = reference_pose(np.concatenate([r.pose for r in reads]),
                                   np.arange(len(roles.fixed)))
        for r in reads:
            r.pose = np.zeros(0)
        pca, coord_std = _face_pca(p, kept, reads, reference)
        phone_set = sorted({SILENCE} | {apply_label_map(str(lab), label_map)
                                        for r in reads for lab in set(r.phones.labels)})
        pid = {ph: i for i, ph in enumerate(phone_set)}
        voice = _evenly(len(reads), VOICE_UTTERANCES)
        closure = ClosureGather(pca.n_components)
        cb, frames = _codebook(p, kept, reads, reference, pca, pid, closure, voice)

    # eqs 1-2 on the codeword PC vectors grouped by centre phone
    means = phone_means(cb.pcs, cb.codeword_phone(), len(phone_set))
    dist = phone_distances(means)
    progress(0.9, "LSF index")
    model = Model(config=config, phones=phone_set, marker_names=list(source.marker_names),
                  marker_rate=source.marker_rate, fixed=roles.fixed, reference=reference,
                  upper_lip=roles.upper_lip, lower_lip=roles.lower_lip, pca=pca, codebook=cb,
                  means=means, distances=dist, scale=distance_scale(dist, config.distance_scale),
                  coord_std=coord_std, lip_corners=roles.lip_corners,
                  train_utterances=[r.name for r in reads],
                  corpus_fingerprint=source.fingerprint,
                  index=build_index(cb.lsf, config.index_cells),
                  trained_labels=dict(Counter(r.kind for r in reads)),
                  sensor_roles=dict(source.setup.sensor_roles))
    progress(0.95, "closure and voice statistics")
    model.closure = closure.stats()
    position = np.full(len(reads), -1)
    position[voice] = np.arange(len(voice))
    owner = position[cb.token_utt[np.arange(len(cb.lsf)) // cb.n_per_phone]]   # in lsf's order
    lsf = [frames[j] for j in voice]
    model.voice_distance = training_voice_distance(lsf, [np.ones(len(w), bool) for w in lsf],
                                                   owner, cb.lsf, workers)
    if config.closure_detector:
        with one_blas_thread():
            model.detector = _detector(p, kept, reads, model)
    progress(1.0, "done")
    return model


def _evenly(n: int, most: int) -> list[int]:
    """Up to ``most`` of ``range(n)``, evenly spaced (all of them when ``n <= most``)."""
    return [int(j) for j in np.unique(np.linspace(0, n - 1, min(n, most)).astype(int))]


# --------------------------------------------------------------------------- pass 4: the detector
def _detector(p: _Passes, kept: Sequence[int], reads: Sequence[_Read], model: Model
              ) -> ClosureDetector | None:
    """The bilabial-closure detector (:mod:`facetraj_engine.method.closure_detector`), fitted on
    the marker frames of (up to :data:`DETECTOR_UTTERANCES`, evenly spaced) training utterances,
    their /p b m/ labels as targets; its second part with the acoustic search's opinion, each
    utterance searched without its own codewords (:mod:`facetraj_engine.method.closure_search`).
    A fourth pass: each utterance read again."""
    picks = _evenly(len(reads), DETECTOR_UTTERANCES)

    def work(i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        j = picks[i]
        utt = p.source.utterance(kept[j])
        times = utt.frame_times()
        w, e = utterance_inputs(p.config, utt.audio, utt.sample_rate, times)
        phones = [PhoneSegment(s.start, s.end, apply_label_map(s.label, p.label_map))
                  for s in utt.phones]
        return w, e, bilabial_frames(phones, times), left_out_rows(model, w, j)

    parts = [part for _, part in p.fan_out(work, [reads[j].name for j in picks], 0.96, 1.0,
                                           "closure detector")]
    lsf, energy, targets, search = (list(x) for x in zip(*parts, strict=True))
    return train_detector(lsf, energy, targets, ridge=p.config.closure_detector_ridge,
                          search=search)
