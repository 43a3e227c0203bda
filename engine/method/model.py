"""The trained model: marker normalisation, PCA, codebook and similarity matrix, and its file
(one ``.npz`` with a JSON metadata entry, never pickle).

Training is :func:`facetraj_engine.method.training.train`; synthesis
:func:`facetraj_engine.method.pipeline.synthesize`.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from .. import __version__
from ..config import TrainConfig
from ..errors import ModelFileError
from ..io.files import atomic_write, write_npz
from ..io.model_file import read_model_file
from ..io.sensor_roles import SensorRoles, sensor_roles
from .chain import join_scale
from .closure import ClosureStats
from .closure_detector import ClosureDetector
from .codebook import Codebook
from .context_index import ContextIndex
from .lsf import lsf_frames_at
from .lsf_index import LsfIndex, build_index
from .markers import fill_gaps, remove_head_motion
from .pca import PCA
from .similarity import similarity_matrix

log = logging.getLogger(__name__)

MODEL_FORMAT = "facetraj-model"
MODEL_VERSION = 1


@dataclass
class Model:
    """Everything synthesis needs, learnt from a training corpus.

    Attributes
    ----------
    config : the training configuration.
    phones : the phone set (ids index this list).
    marker_names, marker_rate : the marker set and frame rate of the training data.
    fixed : indices of the fixed (head) markers; ``reference`` their neutral pose ``(F, 3)``;
        none for data already head-corrected.
    upper_lip, lower_lip : indices of the lip centre markers; ``lip_corners`` right and left.
    pca : the PCA of the head-normalised marker vectors.
    codebook : the audio-visual codebook.
    means : ``(K, n_pc)`` eq 1 phone means; ``distances`` ``(K, K)`` eq 2; ``scale`` the divisor
        applied to D before eq 3.
    coord_std : ``(M * 3,)`` standard deviation of every head-normalised coordinate in training.
    train_utterances : ids of the training utterances (codebook ``token_utt`` indexes it).
    index : the coarse index over the codebook LSFs for acoustic-only synthesis; built by
        :func:`train`, or on first use by :meth:`lsf_index` (older model files have none).
    lsf_mean : ``(P,)`` the training speaker's mean codeword LSF (the robust mode's speaker mean
        normalisation); older model files have none and it is computed from the codebook.
    tuned : the synthesis settings chosen by cross-validation on the training split
        (:func:`facetraj_engine.evaluation.tuning.cross_validate`: ``{"settings": {...}, "scores": [...]}``),
        or empty.
    trained_labels : how the training utterances' labels were made: utterances per kind
        (``{"hand-checked": 186}``; ``facetraj_engine.data.Provenance``); empty in older model files.
    closure : the training talker's closed lip aperture, closing direction and rest face
        (:mod:`facetraj_engine.method.closure`); ``None`` in older model files (no closure step).
    voice_distance : ``D0``, the training voice's distance to its own codebook
        (:mod:`facetraj_engine.method.voice_match`); NaN in older model files.
    detector : the bilabial-closure detector (:mod:`facetraj_engine.method.closure_detector`):
        where the lips close without phone labels; ``None`` in older model files (their
        acoustic-only synthesis closes no lips, as before).
    sensor_roles : the training corpus's ``sensor_roles`` (articulograph sensors' roles where
        their names do not say them); :attr:`roles` resolves them with the names.
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
    tuned: dict = field(default_factory=dict)
    trained_labels: dict = field(default_factory=dict)
    closure: ClosureStats | None = None
    voice_distance: float = float("nan")
    detector: ClosureDetector | None = None
    sensor_roles: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        # no fixed markers (head-corrected data) is an empty index array, not numpy's float []
        self.fixed = np.asarray(self.fixed, dtype=np.intp)
        self.reference = np.asarray(self.reference, dtype=np.float64).reshape(len(self.fixed), 3)

    # ------------------------------------------------------------------ derived quantities
    @cached_property
    def join_scale(self) -> float:
        """``s^2`` of the chain's join cost (:func:`facetraj_engine.method.chain.join_scale`), from the
        codebook."""
        cb = self.codebook
        return join_scale(cb.pcs, cb.token_start, cb.token_end, cb.n_per_phone, self.marker_rate)

    @property
    def trained_on_hand_checked(self) -> bool:
        """Whether every training utterance's labels were hand-checked (older files: assumed)."""
        return set(self.trained_labels) <= {"hand-checked"}

    @property
    def n_markers(self) -> int:
        return len(self.marker_names)

    @property
    def is_planar(self) -> bool:
        """Whether the markers are midsagittal (2-D: every x coordinate of the neutral face is 0)."""
        return not self.neutral_face()[:, 0].any()

    @cached_property
    def roles(self) -> SensorRoles:
        """Which marker is which articulator (:func:`facetraj_engine.io.sensor_roles.sensor_roles`):
        ``roles.articulograph`` for articulograph sensors (a tongue among them)."""
        return sensor_roles(self.marker_names, self.upper_lip, self.lower_lip, self.lip_corners,
                            self.fixed.tolist(), self.sensor_roles)

    def phone_id(self, label: str) -> int:
        return self.phones.index(label)

    def similarity(self, nu: float | None = None) -> np.ndarray:
        """The visual phoneme similarity matrix S (eq 3) for ``nu`` (default: the trained one,
        made once and read-only)."""
        if nu is None or nu == self.config.nu:
            return self.trained_similarity
        return similarity_matrix(self.distances, nu, self.scale)

    @cached_property
    def context_index(self) -> ContextIndex:
        """The codebook's contexts grouped for eq 4's search
        (:class:`~facetraj_engine.method.context_index.ContextIndex`), made on first use: every
        synthesis with the model reuses it."""
        return ContextIndex.of(self.codebook.contexts, len(self.distances))

    @cached_property
    def trained_similarity(self) -> np.ndarray:
        """S (eq 3) at the trained ``nu``, read-only (eq 4 reads it for every input)."""
        s = similarity_matrix(self.distances, self.config.nu, self.scale)
        s.flags.writeable = False
        return s

    def neutral_face(self) -> np.ndarray:
        """The PCA mean face, ``(M, 3)``."""
        return self.pca.mean.reshape(self.n_markers, 3)

    def mode_shape(self, component: int, value: float) -> np.ndarray:
        """The face with PC ``component`` set to ``value`` (others 0), ``(M, 3)`` (Figure 2)."""
        coeffs = np.zeros(self.pca.n_components)
        coeffs[component] = value
        return self.pca.inverse(coeffs).reshape(self.n_markers, 3)

    def input_lsf(self, audio: np.ndarray, sample_rate: int, times: np.ndarray,
                  threads: int | None = 1) -> np.ndarray:
        """The input LSF vectors w (eq 5) at ``times``, analysed as in training, ``(T, P)``, in
        ``threads`` spans of frames (``None``: :func:`facetraj_engine.threads.frame_threads`)."""
        return analysed_lsf(self.config, audio, sample_rate, times, threads)

    def lsf_index(self) -> LsfIndex:
        """The coarse LSF index of the codebook (``facetraj_engine.method.lsf_index``), built here and kept if
        the
        model has none or has one for a codebook of another size."""
        if self.index is None or self.index.n_codewords != self.codebook.lsf.shape[0]:
            self.index = build_index(self.codebook.lsf, self.config.index_cells)
        return self.index

    @property
    def lsf_mean(self) -> np.ndarray:
        """The training speaker's mean LSF vector (mean over the codewords), ``(P,)``."""
        return self.codebook.lsf.mean(axis=0)

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
        """Write the model as one ``.npz`` (arrays + a JSON ``meta`` entry); never pickle.

        The members are stored, not deflated: compression saves little of the size and inflating
        slows every start (issue #15). Compressed files (older versions) still load."""
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
            "tuned": self.tuned,
            "trained_labels": self.trained_labels,
            "sensor_roles": self.sensor_roles,
            "voice_distance": self.voice_distance if np.isfinite(self.voice_distance) else None,
        }
        if self.closure is not None:
            meta["closure_closed"] = self.closure.closed
        if self.detector is not None:
            meta["closure_detector"] = self.detector.meta()
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
        if self.codebook.lsf_context is not None:
            arrays["cb_lsf_context"] = self.codebook.lsf_context
        if self.closure is not None:
            arrays.update(closure_direction=self.closure.direction, rest_pcs=self.closure.rest)
        if self.detector is not None:
            arrays.update(self.detector.arrays())
        if self.index is not None:
            arrays.update(ix_centroids=self.index.centroids, ix_order=self.index.order,
                          ix_offsets=self.index.offsets)
        with atomic_write(path, overwrite) as tmp, open(tmp, "wb") as handle:
            write_npz(handle, arrays)
        return path

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Model:
        """Read a model written by :meth:`save`; a wrong, truncated, damaged or newer file is
        refused (:func:`facetraj_engine.io.model_file.read_model_file` checks every entry first)."""
        path = Path(path)
        meta, a = read_model_file(path, MODEL_VERSION, MODEL_FORMAT)
        try:
            pca = PCA(a["pca_mean"], a["pca_components"], a["pca_variances"],
                      float(meta["pca_total_variance"]))
            cb = Codebook(a["cb_contexts"], a["cb_lsf"], a["cb_pcs"], a["cb_token_utt"],
                          a["cb_token_start"], a["cb_token_end"], int(meta["n_per_phone"]),
                          a.get("cb_lsf_context"))
            index = (LsfIndex(a["ix_centroids"], a["ix_order"], a["ix_offsets"])
                     if "ix_centroids" in a else None)
            return cls(
                config=TrainConfig.from_dict(meta["config"]), phones=list(meta["phones"]),
                marker_names=list(meta["marker_names"]), marker_rate=float(meta["marker_rate"]),
                fixed=a["fixed"], reference=a["reference"], upper_lip=int(meta["upper_lip"]),
                lower_lip=int(meta["lower_lip"]), pca=pca, codebook=cb, means=a["means"],
                distances=a["distances"], scale=float(meta["scale"]), coord_std=a["coord_std"],
                lip_corners=list(meta.get("lip_corners", [])),
                train_utterances=list(meta.get("train_utterances", [])),
                corpus_fingerprint=meta.get("corpus_fingerprint", ""), index=index,
                tuned=dict(meta.get("tuned") or {}),
                trained_labels=dict(meta.get("trained_labels") or {}),
                sensor_roles=dict(meta.get("sensor_roles") or {}),
                closure=ClosureStats(float(meta["closure_closed"]), a["closure_direction"],
                                     a["rest_pcs"]) if "closure_closed" in meta else None,
                voice_distance=float(meta.get("voice_distance") or "nan"),
                detector=ClosureDetector.from_file(meta["closure_detector"], a)
                if "closure_detector" in meta else None,
            )
        except KeyError as exc:
            raise ModelFileError(path, f"model file is incomplete: missing {exc}") from exc


def analysed_lsf(config: TrainConfig, audio: np.ndarray, sample_rate: int, times: np.ndarray,
                 threads: int | None = 1) -> np.ndarray:
    """The input LSF vectors w (eq 5) at ``times``, analysed by ``config``'s settings (order,
    window, rate, pre-emphasis) as a model trained with them analyses its training audio."""
    return analysed_frames(config, audio, sample_rate, times, threads)[0]


def analysed_frames(config: TrainConfig, audio: np.ndarray, sample_rate: int, times: np.ndarray,
                    threads: int | None = 1,
                    per_frame: Callable[[np.ndarray], np.ndarray] | None = None
                    ) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`analysed_lsf`, and ``per_frame`` of the same analysis frames
    (:func:`~facetraj_engine.method.lsf.lsf_frames_at`: the closure detector's frame energies
    without framing the audio again)."""
    return lsf_frames_at(audio, sample_rate, times, config.lpc_order, config.window_s,
                         config.audio_rate, config.preemphasis, threads, per_frame)
