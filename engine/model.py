"""The trained model: marker normalisation, PCA, codebook and similarity matrix; training,
synthesis, and saving without pickle (one ``.npz`` with a JSON metadata entry).
"""

from __future__ import annotations

import json
import logging
import os
import zipfile
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import __version__
from .codebook import Codebook, codeword_times, concatenate, interpolate_frames
from .config import SynthConfig, TrainConfig
from .corpus import Corpus
from .data import PhoneSegment, Utterance
from .errors import InputError, ModelFileError
from .formats import atomic_write, validate_phones
from .lsf import lsf_at
from .lsf_index import LsfIndex, build_index
from .markers import fill_gaps, reference_pose, remove_head_motion
from .pca import PCA, fit_pca
from .phones import SILENCE, apply_label_map, context_ids, map_labels, segment_index
from .similarity import (
    distance_scale,
    phone_distances,
    phone_means,
    similarity_matrix,
    top_context_phones,
)
from .smoothing import smooth
from .synthesis import FrameWeights, gamma_grid, nearest_codewords, weight_frames

log = logging.getLogger(__name__)

MODEL_FORMAT = "facetraj-model"
MODEL_VERSION = 1

Progress = Callable[[float, str], None]


def _no_progress(fraction: float, message: str) -> None:
    pass


@dataclass
class Model:
    """Everything synthesis needs, learnt from a training corpus.

    Attributes
    ----------
    config : the training configuration.
    phones : the phone set (ids index this list).
    marker_names, marker_rate : the marker set and frame rate of the training data.
    fixed : indices of the fixed (head) markers; ``reference`` their neutral pose ``(F, 3)``.
    upper_lip, lower_lip : indices of the lip centre markers; ``lip_corners`` right and left.
    pca : the PCA of the head-normalised marker vectors.
    codebook : the audio-visual codebook.
    means : ``(K, n_pc)`` eq 1 phone means; ``distances`` ``(K, K)`` eq 2; ``scale`` the divisor
        applied to D before eq 3.
    coord_std : ``(M * 3,)`` standard deviation of every head-normalised coordinate in training.
    train_utterances : ids of the training utterances (codebook ``token_utt`` indexes it).
    index : the coarse index over the codebook LSFs for acoustic-only synthesis; built by
        :func:`train`, or on first use by :meth:`lsf_index` (older model files have none).
    """

    config: TrainConfig
    phones: list[str]
    marker_names: list[str]
    marker_rate: float
    fixed: np.ndarray
    reference: np.ndarray
    upper_lip: int
    lower_lip: int
    pca: PCA
    codebook: Codebook
    means: np.ndarray
    distances: np.ndarray
    scale: float
    coord_std: np.ndarray
    lip_corners: list[int] = field(default_factory=list)
    train_utterances: list[str] = field(default_factory=list)
    corpus_fingerprint: str = ""
    index: LsfIndex | None = None

    # ------------------------------------------------------------------ derived quantities
    @property
    def n_markers(self) -> int:
        return len(self.marker_names)

    def phone_id(self, label: str) -> int:
        return self.phones.index(label)

    def similarity(self, nu: float | None = None) -> np.ndarray:
        """The visual phoneme similarity matrix S (eq 3) for ``nu`` (default: the trained one)."""
        return similarity_matrix(self.distances, self.config.nu if nu is None else nu, self.scale)

    def neutral_face(self) -> np.ndarray:
        """The PCA mean face, ``(M, 3)``."""
        return self.pca.mean.reshape(self.n_markers, 3)

    def mode_shape(self, component: int, value: float) -> np.ndarray:
        """The face with PC ``component`` set to ``value`` (others 0), ``(M, 3)`` (Figure 2)."""
        coeffs = np.zeros(self.pca.n_components)
        coeffs[component] = value
        return self.pca.inverse(coeffs).reshape(self.n_markers, 3)

    def input_lsf(self, audio: np.ndarray, sample_rate: int, times: np.ndarray) -> np.ndarray:
        """The input LSF vectors w (eq 5) at ``times``, analysed as in training, ``(T, P)``."""
        mc = self.config
        return lsf_at(audio, sample_rate, times, mc.lpc_order, mc.window_s, mc.audio_rate,
                      mc.preemphasis)

    def lsf_index(self) -> LsfIndex:
        """The coarse LSF index of the codebook (``engine.lsf_index``), built here and kept if the
        model has none or has one for a codebook of another size."""
        if self.index is None or self.index.n_codewords != self.codebook.lsf.shape[0]:
            self.index = build_index(self.codebook.lsf, self.config.index_cells)
        return self.index

    def normalise_markers(self, markers: np.ndarray) -> np.ndarray:
        """Fill short gaps and remove head motion: ``(T, M, 3)`` in the model's head frame."""
        markers = np.asarray(markers, dtype=np.float64)
        if markers.ndim != 3 or markers.shape[1:] != (self.n_markers, 3):
            raise ValueError(f"markers must be (frames, {self.n_markers}, 3), got {markers.shape}")
        filled, _ = fill_gaps(markers, self.marker_rate, self.config.max_gap_s)
        return remove_head_motion(filled, self.fixed, self.reference)

    def to_pcs(self, normalised: np.ndarray) -> np.ndarray:
        """PC coefficients ``(T, K)`` of head-normalised markers ``(T, M, 3)``."""
        return self.pca.transform(normalised.reshape(normalised.shape[0], -1))

    def to_markers(self, pcs: np.ndarray) -> np.ndarray:
        """Marker coordinates ``(T, M, 3)`` from PC coefficients ``(T, K)``."""
        return self.pca.inverse(pcs).reshape(-1, self.n_markers, 3)

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | os.PathLike[str], overwrite: bool = True) -> Path:
        """Write the model as one ``.npz`` (arrays + a JSON ``meta`` entry); never pickle."""
        path = Path(path)
        meta = {
            "format": MODEL_FORMAT,
            "version": MODEL_VERSION,
            "facetraj": __version__,
            "config": self.config.to_dict(),
            "phones": self.phones,
            "marker_names": self.marker_names,
            "marker_rate": self.marker_rate,
            "upper_lip": self.upper_lip,
            "lower_lip": self.lower_lip,
            "lip_corners": self.lip_corners,
            "pca_total_variance": self.pca.total_variance,
            "scale": self.scale,
            "n_per_phone": self.codebook.n_per_phone,
            "train_utterances": self.train_utterances,
            "corpus_fingerprint": self.corpus_fingerprint,
        }
        arrays = {
            "meta": np.array(json.dumps(meta)),
            "fixed": self.fixed, "reference": self.reference,
            "pca_mean": self.pca.mean, "pca_components": self.pca.components,
            "pca_variances": self.pca.variances,
            "cb_contexts": self.codebook.contexts, "cb_lsf": self.codebook.lsf,
            "cb_pcs": self.codebook.pcs, "cb_token_utt": self.codebook.token_utt,
            "cb_token_start": self.codebook.token_start, "cb_token_end": self.codebook.token_end,
            "means": self.means, "distances": self.distances, "coord_std": self.coord_std,
        }
        if self.index is not None:
            arrays.update(ix_centroids=self.index.centroids, ix_order=self.index.order,
                          ix_offsets=self.index.offsets)
        with atomic_write(path, overwrite) as tmp, open(tmp, "wb") as handle:
            np.savez_compressed(handle, **arrays)
        return path

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Model:
        """Read a model written by :meth:`save`; a wrong, truncated or newer file is refused."""
        path = Path(path)
        if not path.exists():
            raise ModelFileError(path, "no such model file")
        if not zipfile.is_zipfile(path):
            raise ModelFileError(path, "not a facetraj model (not an .npz archive, or truncated)")
        try:
            with np.load(path, allow_pickle=False) as z:
                if "meta" not in z.files:
                    raise ModelFileError(path, "not a facetraj model (no metadata entry)")
                meta = json.loads(str(z["meta"]))
                if meta.get("format") != MODEL_FORMAT:
                    raise ModelFileError(path, "not a facetraj model")
                if int(meta.get("version", 0)) > MODEL_VERSION:
                    raise ModelFileError(path, f"model format {meta['version']} is newer than this "
                                               f"facetraj reads ({MODEL_VERSION}); upgrade facetraj")
                a = {k: z[k] for k in z.files if k != "meta"}
        except ModelFileError:
            raise
        except (zipfile.BadZipFile, OSError, ValueError, EOFError, KeyError) as exc:
            raise ModelFileError(path, f"not a readable facetraj model ({exc})") from exc
        try:
            pca = PCA(a["pca_mean"], a["pca_components"], a["pca_variances"],
                      float(meta["pca_total_variance"]))
            cb = Codebook(a["cb_contexts"], a["cb_lsf"], a["cb_pcs"], a["cb_token_utt"],
                          a["cb_token_start"], a["cb_token_end"], int(meta["n_per_phone"]))
            index = (LsfIndex(a["ix_centroids"], a["ix_order"], a["ix_offsets"])
                     if "ix_centroids" in a else None)
            if index is not None and not _index_fits(index, cb.lsf):
                raise ModelFileError(path, "its LSF index does not match its codebook (damaged file?)")
            return cls(
                config=TrainConfig.from_dict(meta["config"]), phones=list(meta["phones"]),
                marker_names=list(meta["marker_names"]), marker_rate=float(meta["marker_rate"]),
                fixed=a["fixed"], reference=a["reference"], upper_lip=int(meta["upper_lip"]),
                lower_lip=int(meta["lower_lip"]), pca=pca, codebook=cb, means=a["means"],
                distances=a["distances"], scale=float(meta["scale"]), coord_std=a["coord_std"],
                lip_corners=list(meta.get("lip_corners", [])),
                train_utterances=list(meta.get("train_utterances", [])),
                corpus_fingerprint=meta.get("corpus_fingerprint", ""), index=index,
            )
        except KeyError as exc:
            raise ModelFileError(path, f"model file is incomplete: missing {exc}") from exc


def _index_fits(index: LsfIndex, cb_lsf: np.ndarray) -> bool:
    """Whether a stored LSF index partitions exactly this codebook."""
    n, order, offsets = cb_lsf.shape[0], index.order, index.offsets
    return (order.shape == (n,) and offsets.shape == (index.n_cells + 1,)
            and index.centroids.shape[1:] == cb_lsf.shape[1:] and n > 0
            and offsets[0] == 0 and offsets[-1] == n and bool(np.all(np.diff(offsets) >= 0))
            and np.array_equal(np.sort(order), np.arange(n)))


# ---------------------------------------------------------------------- training
@dataclass
class MarkerSetup:
    """Which markers are which, for training on utterances outside a corpus folder."""

    fixed: list[str]
    upper_lip: str
    lower_lip: str
    lip_corners: list[str] = field(default_factory=list)


def _check_utterance(utt: Utterance, names: Sequence[str]) -> None:
    if utt.markers is None:
        raise InputError(utt.name, "the utterance has no marker data to train on")
    if list(utt.marker_names) != list(names):
        raise InputError(utt.name, f"marker set differs from the first utterance "
                                   f"({len(utt.marker_names)} vs {len(names)} markers)")
    if utt.n_frames < 2:
        raise InputError(utt.name, "only one marker frame")


def train(utterances: Iterable[Utterance] | Corpus, setup: MarkerSetup | None = None,
          config: TrainConfig | None = None, progress: Progress | None = None,
          label_map: Mapping[str, str] | None = None) -> Model:
    """Train a model (paper sections 2.1-2.2) on utterances with markers and phone labels.

    Given a :class:`~engine.corpus.Corpus`, its ``train`` split is used and the marker roles come
    from ``corpus.json``; otherwise pass ``setup``.

    Steps: gap filling; head-motion removal against a Procrustes-mean neutral pose of the fixed
    markers; PCA; context-phones; LSF and PC vectors at 5 codeword times per phone; eq 1-2 phone
    means and distances.
    """
    config = config or TrainConfig()
    progress = progress or _no_progress
    fingerprint = ""
    if isinstance(utterances, Corpus):
        corpus = utterances
        info = corpus.info
        setup = setup or MarkerSetup(info.fixed_markers, info.upper_lip, info.lower_lip,
                                     info.lip_corners)
        ids = list(info.train)
        fingerprint = corpus.fingerprint()
        loaded: list[Utterance] = []
        for k, utt_id in enumerate(ids):
            progress(0.3 * k / max(len(ids), 1), f"loading {utt_id}")
            loaded.append(corpus.utterance(utt_id))
    else:
        loaded = list(utterances)
    if setup is None:
        raise ValueError("pass a MarkerSetup (fixed markers and lips) when not training on a Corpus")
    if not loaded:
        raise InputError(None, "no training utterances")
    names = list(loaded[0].marker_names)
    for utt in loaded:
        _check_utterance(utt, names)
    rate = float(loaded[0].marker_rate)
    index = {n: i for i, n in enumerate(names)}
    try:
        fixed = np.array([index[n] for n in setup.fixed])
        upper, lower = index[setup.upper_lip], index[setup.lower_lip]
        corners = [index[n] for n in setup.lip_corners]
    except KeyError as exc:
        raise InputError(None, f"marker {exc} is not in the marker set") from exc

    # 1. gaps, neutral pose, head motion
    progress(0.3, "removing head motion")
    filled = []
    for utt in loaded:
        f, valid = fill_gaps(utt.markers, rate, config.max_gap_s)
        if (~valid).any():
            log.info("%s: %d frames with gaps over %.0f ms left out", utt.name, (~valid).sum(),
                     config.max_gap_s * 1000)
        filled.append(f)
    sample = np.concatenate([f[::5] for f in filled])
    reference = reference_pose(sample, fixed)
    normed = [remove_head_motion(f, fixed, reference) for f in filled]

    # 2. PCA
    progress(0.4, "PCA")
    flat = np.concatenate([n.reshape(n.shape[0], -1) for n in normed])
    flat = flat[np.isfinite(flat).all(axis=1)]
    if len(flat) < 2:
        raise InputError(None, "no complete marker frames to train on")
    pca = fit_pca(flat, config.n_components, config.variance_target)
    coord_std = flat.std(axis=0)
    log.info("PCA: %d components explain %.2f %% of the variance", pca.n_components,
             100 * pca.explained_ratio.sum())

    # 3. phone set and codebook
    phone_set = sorted({SILENCE} | {apply_label_map(s.label, label_map)
                                    for utt in loaded for s in utt.phones})
    pid = {p: i for i, p in enumerate(phone_set)}
    parts = []
    for k, (utt, nm) in enumerate(zip(loaded, normed, strict=True)):
        progress(0.45 + 0.5 * k / len(loaded), f"codebook: {utt.name}")
        phones = validate_phones(utt.phones, utt.duration, utt.name)
        ids_ = [pid[apply_label_map(s.label, label_map)] for s in phones]
        ctx = context_ids(ids_, config.context, pid[SILENCE])
        starts = np.array([s.start for s in phones])
        ends = np.array([s.end for s in phones])
        times = codeword_times(starts, ends, config.codewords_per_phone, config.placement)
        pcs_frames = pca.transform(nm.reshape(nm.shape[0], -1))  # NaN rows stay NaN
        cw_pcs = interpolate_frames(pcs_frames, rate, times.ravel())
        cw_lsf = lsf_at(utt.audio, utt.sample_rate, times.ravel(), config.lpc_order,
                        config.window_s, config.audio_rate, config.preemphasis)
        n = config.codewords_per_phone
        ok = np.isfinite(cw_pcs).all(axis=1).reshape(-1, n).all(axis=1)
        ok &= times[:, -1] <= (nm.shape[0] - 1) / rate + 0.5 / rate
        if (~ok).any():
            log.info("%s: %d phone tokens without complete marker data left out", utt.name,
                     (~ok).sum())
        keep = np.repeat(ok, n)
        parts.append(Codebook(ctx[ok], cw_lsf[keep], cw_pcs[keep],
                              np.full(ok.sum(), k), starts[ok], ends[ok], n))
    cb = concatenate(parts)

    # 4. eqs 1-2 on the codeword PC vectors grouped by centre phone
    means = phone_means(cb.pcs, cb.codeword_phone(), len(phone_set))
    dist = phone_distances(means)
    scale = distance_scale(dist, config.distance_scale)
    # 5. the coarse LSF index for acoustic-only synthesis
    progress(0.97, "LSF index")
    index = build_index(cb.lsf, config.index_cells)
    progress(1.0, "done")
    return Model(config=config, phones=phone_set, marker_names=names, marker_rate=rate,
                 fixed=fixed, reference=reference, upper_lip=upper, lower_lip=lower, pca=pca,
                 codebook=cb, means=means, distances=dist, scale=scale, coord_std=coord_std,
                 lip_corners=corners, train_utterances=[u.name for u in loaded],
                 corpus_fingerprint=fingerprint, index=index)


# ---------------------------------------------------------------------- synthesis
@dataclass
class SegmentChoice:
    """The context-phones chosen for one input phone segment (eq 4)."""

    segment: PhoneSegment
    context: np.ndarray      # (2C+1,) phone ids of the input context-phone
    chosen: np.ndarray       # (N,) codebook context-phone indices, best first
    scores: np.ndarray       # (N,) their n_j


@dataclass
class Synthesis:
    """The result of :func:`synthesize`.

    Attributes
    ----------
    times : ``(T,)`` frame times in seconds (frame t at ``t / marker_rate``).
    lsf : ``(T, P)`` input LSF vectors w.
    raw_pcs : ``(T, K)`` unsmoothed p-hat(t) (eq 8).
    pcs : ``(T, K)`` smoothed PCs; ``markers`` ``(T, M, 3)`` rebuilt from them (head frame).
    frames : per-frame eq 5-8 details (gamma, weights, candidates, w-hat).
    segments : per input phone, the chosen context-phones (phonetic mode), else empty.
    frame_segment : ``(T,)`` index into ``segments`` (phonetic mode), else -1.
    """

    times: np.ndarray
    lsf: np.ndarray
    raw_pcs: np.ndarray
    pcs: np.ndarray
    markers: np.ndarray
    frames: FrameWeights
    config: SynthConfig
    segments: list[SegmentChoice] = field(default_factory=list)
    frame_segment: np.ndarray | None = None


def synthesize(model: Model, audio: np.ndarray, sample_rate: int,
               phones: Sequence[PhoneSegment] | None = None, config: SynthConfig | None = None,
               n_frames: int | None = None, label_map: Mapping[str, str] | None = None,
               source: str | None = None, lsf: np.ndarray | None = None) -> Synthesis:
    """Synthesize face point trajectories from speech (paper section 2.3).

    With ``phones`` and ``mode="phonetic"``: per input phone, the top-N context-phones by eq 4,
    and per frame eqs 5-8 over their 5N codewords. Otherwise (acoustic-only) eqs 5-8 over the
    ``config.acoustic_prefilter`` codewords nearest to each frame, found through the model's LSF
    index (``acoustic_probe`` cells), or over the whole codebook as the paper does
    (``acoustic_prefilter=None``). Then smoothing, and the PCs back to ``(T, M, 3)`` markers.

    ``n_frames`` defaults to every marker frame inside the audio. ``source`` names the input in
    error messages. ``lsf`` may pass the input LSFs already computed by :meth:`Model.input_lsf`
    for these frames (when one utterance is synthesized under several configs).
    """
    config = config or SynthConfig()
    duration = len(audio) / float(sample_rate)
    rate = model.marker_rate
    if n_frames is None:
        n_frames = int(np.floor(duration * rate + 1e-9)) + 1
    if n_frames < 2 or duration < 2.0 / rate:
        raise InputError(source, f"the audio is too short ({duration * 1000:.1f} ms) to synthesize")
    times = np.arange(n_frames) / rate
    mc = model.config
    if lsf is None:
        w = model.input_lsf(audio, sample_rate, times)
    elif lsf.shape != (n_frames, mc.lpc_order):
        raise ValueError(f"lsf must be ({n_frames}, {mc.lpc_order}) for these frames, got {lsf.shape}")
    else:
        w = lsf
    cb = model.codebook
    segments: list[SegmentChoice] = []
    frame_seg = None
    if config.mode == "phonetic":
        if not phones:
            raise InputError(source, "phonetic mode needs phone labels (or use acoustic mode)")
        segs = validate_phones(list(phones), duration, source)
        segs = map_labels(segs, model.phones, label_map, source)
        pid = {p: i for i, p in enumerate(model.phones)}
        ctx = context_ids([pid[s.label] for s in segs], mc.context, pid[SILENCE])
        s = model.similarity(config.nu)
        top, scores = top_context_phones(ctx, cb.contexts, s, config.xi,
                                         min(config.context, mc.context), config.n_context_phones)
        segments = [SegmentChoice(seg, ctx[i], top[i], scores[i]) for i, seg in enumerate(segs)]
        frame_seg = segment_index(segs, times)
        candidates = cb.codewords_of(top)[frame_seg]
    elif config.mode == "acoustic":
        if config.acoustic_prefilter is not None and config.acoustic_probe is not None:
            candidates = model.lsf_index().nearest(w, cb.lsf, config.acoustic_prefilter,
                                                   config.acoustic_probe)
        else:                                   # every codeword, or the exact K nearest
            candidates = nearest_codewords(w, cb.lsf, config.acoustic_prefilter)
    else:
        raise ValueError(f"unknown mode {config.mode!r} (phonetic or acoustic)")
    gammas = gamma_grid(config.gamma_min, config.gamma_max, config.gamma_steps)
    fw = weight_frames(w, candidates, cb.lsf, cb.pcs, gammas)
    pcs = smooth(fw.pcs, rate, config.smoothing, config.triangle_s, config.spline_knot_s)
    return Synthesis(times=times, lsf=w, raw_pcs=fw.pcs, pcs=pcs, markers=model.to_markers(pcs),
                     frames=fw, config=config, segments=segments, frame_segment=frame_seg)


def write_trajectories(path: str | os.PathLike[str], markers: np.ndarray, model: Model,
                       synthesis: Synthesis | None = None, overwrite: bool = True,
                       which: str = "synthesized") -> Path:
    """Write ``(T, M, 3)`` trajectories in the model's head frame as C3D, TSV/CSV or NPZ (by the
    suffix). The NPZ also holds ``synthesis``'s times, smoothed and raw PCs, gamma, input LSF and
    settings, and says ``which`` trajectories it holds (synthesized or original)."""
    from .formats import write_c3d, write_marker_tsv

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        write_c3d(path, markers, model.marker_rate, model.marker_names, overwrite)
    elif suffix in (".tsv", ".txt", ".csv"):
        write_marker_tsv(path, markers, model.marker_rate, model.marker_names, overwrite)
    elif suffix == ".npz":
        arrays = {"markers": markers, "marker_names": np.array(model.marker_names),
                  "which": np.array(which)}
        if synthesis is not None:
            arrays.update(times=synthesis.times, pcs=synthesis.pcs, raw_pcs=synthesis.raw_pcs,
                          gamma=synthesis.frames.gamma, lsf=synthesis.lsf,
                          config=np.array(json.dumps(synthesis.config.to_dict())))
        with atomic_write(path, overwrite) as tmp, open(tmp, "wb") as handle:
            np.savez_compressed(handle, **arrays)
    else:
        raise InputError(path, "unknown format (use .c3d, .tsv, .csv or .npz)")
    return path


def resmooth(model: Model, result: Synthesis, method: str) -> np.ndarray:
    """Markers ``(T, M, 3)`` from ``result``'s raw PCs smoothed with another ``method``."""
    cfg = result.config
    return model.to_markers(smooth(result.raw_pcs, model.marker_rate, method, cfg.triangle_s,
                                   cfg.spline_knot_s))
