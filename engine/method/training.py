"""Training (paper sections 2.1-2.2), step by step: load the training set, remove head motion,
PCA, the audio-visual codebook, the phone means and distances of eqs 1-2, and the LSF index.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..config import TrainConfig
from ..data import PhoneSegment, Utterance
from ..errors import InputError, warn_file
from ..fanout import Skips, fan_out
from ..io.corpus import Corpus
from ..io.labelfiles import validate_phones
from ..labels.phoneset import SILENCE, apply_label_map
from ..progress import Progress, no_progress
from .closure import ClosureStats, aperture_functional, closure_stats
from .closure_detector import ClosureDetector, bilabial_frames, train_detector, utterance_inputs
from .closure_search import left_out_rows
from .codebook import Codebook, codeword_times, concatenate, interpolate_frames
from .context import context_ids
from .lsf import lsf_at
from .lsf_index import build_index
from .markers import fill_gaps, reference_pose, remove_head_motion
from .model import Model
from .pca import PCA, fit_pca
from .similarity import distance_scale, phone_distances, phone_means
from .speech import speech_mask
from .voice_match import training_voice_distance

log = logging.getLogger(__name__)


@dataclass
class MarkerSetup:
    """Which markers are which, for training on utterances outside a corpus folder."""

    fixed: list[str]
    upper_lip: str
    lower_lip: str
    lip_corners: list[str] = field(default_factory=list)


@dataclass
class _MarkerRoles:
    """Marker indices of the fixed markers, the lip centres and the lip corners."""

    fixed: np.ndarray
    upper_lip: int
    lower_lip: int
    lip_corners: list[int]


def _check_utterance(utt: Utterance, names: Sequence[str]) -> None:
    if utt.markers is None:
        raise InputError(utt.name, "the utterance has no marker data to train on")
    if list(utt.marker_names) != list(names):
        raise InputError(utt.name, f"marker set differs from the first utterance "
                                   f"({len(utt.marker_names)} vs {len(names)} markers)")
    if utt.n_frames < 2:
        raise InputError(utt.name, "only one marker frame")


def load_training_set(utterances: Iterable[Utterance] | Corpus, setup: MarkerSetup | None,
                      progress: Progress, workers: int = 1, skip: Skips | None = None
                      ) -> tuple[list[Utterance], MarkerSetup, str]:
    """The training utterances, their marker roles and the corpus fingerprint ("" outside a
    corpus). A :class:`~facetraj_engine.io.corpus.Corpus` gives its ``train`` split (read in ``workers``
    processes) and its ``corpus.json`` roles. An utterance with a bad file stops training with its
    error, or with ``skip`` is left out (recorded there)."""
    fingerprint = ""
    if isinstance(utterances, Corpus):
        corpus = utterances
        info = corpus.info
        setup = setup or MarkerSetup(info.fixed_markers, info.upper_lip, info.lower_lip,
                                     info.lip_corners)
        fingerprint = corpus.fingerprint()
        done = fan_out(corpus.utterance, list(info.train), workers, skip=skip,
                       progress=lambda f, m: progress(0.3 * f, m), describe=lambda u: f"loading {u}")
        loaded = [utt for _, utt in done]
    else:
        loaded = list(utterances)
    if setup is None:
        raise ValueError("pass a MarkerSetup (fixed markers and lips) when not training on a Corpus")
    checked: list[Utterance] = []
    for utt in loaded:
        try:
            _check_utterance(utt, checked[0].marker_names if checked else utt.marker_names)
        except InputError as exc:
            if skip is None:
                raise
            skip.add(utt.name, exc)
            continue
        checked.append(utt)
    if not checked:
        raise InputError(None, "no training utterances" + (" left (every one was skipped)"
                                                           if loaded or skip else ""))
    return checked, setup, fingerprint


def marker_roles(names: Sequence[str], setup: MarkerSetup) -> _MarkerRoles:
    """The indices of ``setup``'s markers in ``names``; an unknown name is an :class:`InputError`."""
    index = {n: i for i, n in enumerate(names)}
    try:
        return _MarkerRoles(np.array([index[n] for n in setup.fixed]), index[setup.upper_lip],
                            index[setup.lower_lip], [index[n] for n in setup.lip_corners])
    except KeyError as exc:
        raise InputError(None, f"marker {exc} is not in the marker set") from exc


def normalise_head(loaded: Sequence[Utterance], fixed: np.ndarray, rate: float,
                   config: TrainConfig) -> tuple[list[np.ndarray], np.ndarray]:
    """Gap filling and head-motion removal (paper 2.1): every utterance's ``(T, M, 3)`` markers in
    the head frame of a Procrustes-mean neutral pose of the fixed markers, and that pose."""
    filled = []
    for utt in loaded:
        f, valid = fill_gaps(utt.markers, rate, config.max_gap_s)
        if (~valid).any():
            warn_file(log, utt.name, "frames with marker gaps left out",
                      f"{(~valid).sum()} frames with gaps over {config.max_gap_s * 1000:.0f} ms "
                      f"left out", logging.INFO)
        filled.append(f)
    sample = np.concatenate([f[::5] for f in filled])
    reference = reference_pose(sample, fixed)
    return [remove_head_motion(f, fixed, reference) for f in filled], reference


def fit_face_pca(normed: Sequence[np.ndarray], config: TrainConfig) -> tuple[PCA, np.ndarray]:
    """The PCA of the complete head-normalised marker vectors and each coordinate's std."""
    flat = np.concatenate([n.reshape(n.shape[0], -1) for n in normed])
    flat = flat[np.isfinite(flat).all(axis=1)]
    if len(flat) < 2:
        raise InputError(None, "no complete marker frames to train on")
    pca = fit_pca(flat, config.n_components, config.variance_target)
    log.info("PCA: %d components explain %.2f %% of the variance", pca.n_components,
             100 * pca.explained_ratio.sum())
    return pca, flat.std(axis=0)


def codebook_part(utt: Utterance, normed: np.ndarray, k: int, pca: PCA, pid: Mapping[str, int],
                  rate: float, config: TrainConfig,
                  label_map: Mapping[str, str] | None) -> Codebook:
    """One utterance's context-phones and their codewords (LSF and PC vectors at
    ``codewords_per_phone`` times per phone); tokens without complete marker data left out."""
    phones = validate_phones(utt.phones, utt.duration, utt.name)
    ids_ = [pid[apply_label_map(s.label, label_map)] for s in phones]
    ctx = context_ids(ids_, config.context, pid[SILENCE])
    starts = np.array([s.start for s in phones])
    ends = np.array([s.end for s in phones])
    times = codeword_times(starts, ends, config.codewords_per_phone, config.placement)
    pcs_frames = pca.transform(normed.reshape(normed.shape[0], -1))  # NaN rows stay NaN
    cw_pcs = interpolate_frames(pcs_frames, rate, times.ravel())
    cw_lsf = lsf_at(utt.audio, utt.sample_rate, times.ravel(), config.lpc_order,
                    config.window_s, config.audio_rate, config.preemphasis)
    ctx_lsf = None
    if config.lsf_context_frames > 0:
        off = config.lsf_context_frames / rate
        ctx_lsf = np.stack([lsf_at(utt.audio, utt.sample_rate, np.clip(times.ravel() + o, 0, None),
                                   config.lpc_order, config.window_s, config.audio_rate,
                                   config.preemphasis) for o in (-off, off)], axis=1)
    n = config.codewords_per_phone
    ok = np.isfinite(cw_pcs).all(axis=1).reshape(-1, n).all(axis=1)
    ok &= times[:, -1] <= (normed.shape[0] - 1) / rate + 0.5 / rate
    if (~ok).any():
        warn_file(log, utt.name, "phone tokens without complete marker data left out",
                  f"{(~ok).sum()} phone tokens without complete marker data left out", logging.INFO)
    keep = np.repeat(ok, n)
    return Codebook(ctx[ok], cw_lsf[keep], cw_pcs[keep], np.full(ok.sum(), k), starts[ok],
                    ends[ok], n, None if ctx_lsf is None else ctx_lsf[keep])


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

    The utterances are read, and their codewords computed, in ``workers`` processes
    (:func:`facetraj_engine.fanout.fan_out`; the model equals the serial run's). A bad file stops training
    with its error, or with ``skip`` its utterance is left out (``--skip-bad``).
    """
    config = config or TrainConfig()
    progress = progress or no_progress
    loaded, setup, fingerprint = load_training_set(utterances, setup, progress, workers, skip)
    names = list(loaded[0].marker_names)
    rate = float(loaded[0].marker_rate)
    roles = marker_roles(names, setup)

    progress(0.3, "removing head motion")
    normed, reference = normalise_head(loaded, roles.fixed, rate, config)
    progress(0.4, "PCA")
    pca, coord_std = fit_face_pca(normed, config)

    phone_set = sorted({SILENCE} | {apply_label_map(s.label, label_map)
                                    for utt in loaded for s in utt.phones})
    pid = {p: i for i, p in enumerate(phone_set)}
    parts = fan_out(lambda k: codebook_part(loaded[k], normed[k], k, pca, pid, rate, config,
                                            label_map),
                    range(len(loaded)), workers, progress=lambda f, m: progress(0.45 + 0.5 * f, m),
                    describe=lambda k: f"codebook: {loaded[k].name}")
    cb = concatenate([part for _, part in parts])

    # eqs 1-2 on the codeword PC vectors grouped by centre phone
    means = phone_means(cb.pcs, cb.codeword_phone(), len(phone_set))
    dist = phone_distances(means)
    scale = distance_scale(dist, config.distance_scale)
    progress(0.95, "LSF index")
    index = build_index(cb.lsf, config.index_cells)
    model = Model(config=config, phones=phone_set, marker_names=names, marker_rate=rate,
                  fixed=roles.fixed, reference=reference, upper_lip=roles.upper_lip,
                  lower_lip=roles.lower_lip, pca=pca, codebook=cb, means=means, distances=dist,
                  scale=scale, coord_std=coord_std, lip_corners=roles.lip_corners,
                  train_utterances=[u.name for u in loaded], corpus_fingerprint=fingerprint,
                  index=index, trained_labels=dict(Counter(u.provenance.kind for u in loaded)))
    progress(0.97, "closure and voice statistics")
    model.closure = closure_part(model, loaded, normed)
    model.voice_distance = voice_part(model, loaded)
    if config.closure_detector:
        progress(0.98, "closure detector")
        model.detector = detector_part(model, loaded, label_map)
    progress(1.0, "done")
    return model


def closure_part(model: Model, loaded: Sequence[Utterance], normed: Sequence[np.ndarray]
                 ) -> ClosureStats:
    """The closure step's statistics (:mod:`facetraj_engine.method.closure`) of the training talker."""
    a0, g = aperture_functional(model.pca, model.upper_lip, model.lower_lip)
    pcs = [model.to_pcs(n) for n in normed]
    return closure_stats(pcs, [u.phones for u in loaded], model.marker_rate, a0, g)


def detector_part(model: Model, loaded: Sequence[Utterance],
                  label_map: Mapping[str, str] | None = None) -> ClosureDetector | None:
    """The bilabial-closure detector (:mod:`facetraj_engine.method.closure_detector`) of the
    training utterances' marker frames, their /p b m/ labels as targets; its second part with the
    acoustic search's opinion, each utterance searched without its own codewords
    (:mod:`facetraj_engine.method.closure_search`)."""
    lsf, energy, targets, search = [], [], [], []
    for k, utt in enumerate(loaded):
        times = utt.frame_times()
        w, e = utterance_inputs(model.config, utt.audio, utt.sample_rate, times)
        phones = [PhoneSegment(s.start, s.end, apply_label_map(s.label, label_map))
                  for s in utt.phones]
        lsf.append(w)
        energy.append(e)
        targets.append(bilabial_frames(phones, times))
        search.append(left_out_rows(model, w, k))
    return train_detector(lsf, energy, targets, ridge=model.config.closure_detector_ridge,
                          search=search)


def voice_part(model: Model, loaded: Sequence[Utterance], utterances: int = 40,
               frames: int = 60) -> float:
    """``D0`` of :mod:`facetraj_engine.method.voice_match` on (up to ``utterances`` evenly spaced)
    training utterances, ``frames`` speech frames each."""
    pick = np.unique(np.linspace(0, len(loaded) - 1, min(len(loaded), utterances)).astype(int))
    position = np.full(len(loaded), -1)
    position[pick] = np.arange(len(pick))
    cb = model.codebook
    owner = position[cb.token_utt[np.arange(len(cb.lsf)) // cb.n_per_phone]]   # in lsf's order
    lsf, speech = [], []
    for k in pick:
        utt = loaded[k]
        times = utt.frame_times()
        mask = speech_mask(utt.audio, utt.sample_rate, times)
        keep = np.flatnonzero(mask)
        keep = keep[np.linspace(0, keep.size - 1, min(keep.size, frames)).astype(int)] if keep.size else keep
        lsf.append(model.input_lsf(utt.audio, utt.sample_rate, times[keep]))
        speech.append(np.ones(keep.size, bool))
    return training_voice_distance(lsf, speech, owner, cb.lsf)
