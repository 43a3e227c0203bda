"""Configuration of training and synthesis.

Every choice the paper leaves open is a field here; ``docs/algorithm.md`` explains each default.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from typing import Literal

Placement = Literal["centres", "edges"]
DistanceScale = Literal["max", "median", "none"]
Mode = Literal["phonetic", "acoustic", "robust"]
Smoothing = Literal["triangular", "spline", "none"]


@dataclass(frozen=True)
class TrainConfig:
    """Training settings (paper section 2.1-2.2).

    Attributes
    ----------
    audio_rate : analysis rate; audio is resampled to it (the paper: 16 kHz).
    lpc_order : LPC order P, also the LSF dimension.
    window_s : Hamming analysis window, centred on each marker frame or codeword time.
    preemphasis : first-order pre-emphasis coefficient before LPC (0 disables it).
    max_gap_s : marker gaps up to this long are interpolated; longer ones make frames invalid.
    n_components : number of PCs kept; ``None`` keeps the count reaching ``variance_target``.
    variance_target : variance fraction used when ``n_components`` is ``None``.
    context : phones of context C on each side of a context-phone (eq 4).
    codewords_per_phone : codewords per phone token (the paper: 5).
    placement : ``centres`` puts codeword k of n at ``start + (k + 1/2) dur / n``; ``edges`` at
        ``start + k dur / (n - 1)`` (first and last on the boundaries).
    nu : the constant of eq 3.
    distance_scale : how D (eq 2) is normalised before eq 3: ``max`` divides by the largest
        distance, ``median`` by the median off-diagonal distance, ``none`` leaves it in PC units.
    index_cells : cells of the coarse k-means index over the codebook LSFs used by acoustic-only
        synthesis (``facetraj_engine.method.lsf_index``); ``None`` takes ``round(sqrt(5L))``.
    lsf_context_frames : the robust mode's acoustic context (``facetraj_engine.method.selection``): each
    codeword
        also stores its LSF vectors this many marker frames before and after it (0: none).
    closure_detector : train the bilabial-closure detector
        (``facetraj_engine.method.closure_detector``: where the lips close without phone labels).
    closure_detector_ridge : its logistic regression's L2 penalty (on standardised features).
    """

    audio_rate: int = 16000
    lpc_order: int = 18
    window_s: float = 0.025
    preemphasis: float = 0.97
    max_gap_s: float = 0.1
    n_components: int | None = 20
    variance_target: float = 0.99
    context: int = 3
    codewords_per_phone: int = 5
    placement: Placement = "centres"
    nu: float = 10.0
    distance_scale: DistanceScale = "max"
    index_cells: int | None = None
    lsf_context_frames: int = 3
    closure_detector: bool = True
    closure_detector_ridge: float = 100.0

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, obj: dict) -> TrainConfig:
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in obj.items() if k in names})


@dataclass(frozen=True)
class SynthConfig:
    """Synthesis settings (paper section 2.3).

    Attributes
    ----------
    n_context_phones : N, the number of visually most similar context-phones searched (eq 4).
    context : context C used in eq 4 at synthesis (at most the trained context).
    xi : the constant of eq 4 (> 10 so that the centre phone dominates).
    nu : override of eq 3's constant; ``None`` uses the model's.
    mode : ``phonetic`` (labels restrict the search, eq 4), ``acoustic`` (no labels) or
        ``robust`` (eq 4's and the acoustically nearest codewords together, the labels counting
        as much as their confidence, with acoustic context: ``facetraj_engine.method.selection``; the default
        for
        labels that are not hand-checked, :func:`facetraj_engine.method.modes.choose_mode`).
    gamma_min, gamma_max, gamma_steps : the grid searched for gamma (eqs 6-7).
    smoothing : ``triangular`` (100 ms zero-phase window), ``spline`` or ``none``.
    triangle_s : the triangular window's total duration.
    spline_knot_s : knot spacing of the spline smoother.
    acoustic_prefilter : in acoustic mode, keep only the K codewords nearest to each frame by
        eq 5 before eqs 6-8; ``None`` weights all 5L codewords, as the paper does (slow).
    acoustic_probe : how the K nearest are found: among the members of this many cells of the
        model's coarse LSF index (``facetraj_engine.method.lsf_index``, fast, growth about sqrt(5L)); ``None``
        compares every codeword (exact, linear in 5L).
    speaker_warp : speaker normalisation of the input LSFs (``facetraj_engine.method.speaker``): a warp factor
        alpha (1.0: none; below 1 lowers the frequencies, for a voice with a shorter vocal tract
        than the training voice), or ``None`` to choose it per utterance (``choose_warp``).
    robust_candidates : robust mode: acoustically nearest codewords added to eq 4's (index search).
    label_weight : robust mode: kappa, the cost (eq 5 units) of a codeword eq 4 did not choose,
        times the label's confidence.
    label_weight_by_voice : robust mode: the labels weighed by the input's voice
        (``facetraj_engine.method.voice_match``): kappa times the voice's distance ratio ``D / D0`` (at
        least 1: eq 5's distances grow on a voice the codebook does not know), and each label's
        confidence raised towards 1 as the voice match falls (:func:`facetraj_engine.method.pipeline.
        trust_by_voice`).
    context_weight : robust mode: rho, the weight of the context frames in the distance.
    mean_normalise : robust mode: move the input LSFs' mean to the training speaker's.
    chain_beta : robust mode: beta, the join cost's weight of the chain over frames that makes
        the codeword weights consistent over time (``facetraj_engine.method.chain``; 0: eq 8 frame by frame).
    closure : after the smoothing, close the lips at the labelled /p b m/ and rest the face in
        pauses (``facetraj_engine.method.closure``, beyond the paper; the paper's tables run without
        it); off, every part below is off.
    closure_labels : close the lips at the labelled /p b m/ (trusted by where the labels came
        from).
    rest : rest the face in pauses.
    closure_taper_s : the closure's raised-cosine tapers outside each /p b m/.
    closure_detector : without phone labels (the acoustic-only mode, ``facetraj live
        --acoustic-only``), close the lips where the model's bilabial-closure detector finds a
        closure (``facetraj_engine.method.closure_detector``; models without one close none).
        Off by default: on the lips measured here its closures lowered the lip correlation
        (issue 46, docs/algorithm.md).
    closure_threshold : the detector's probability from which a frame is closed (runs of 2
        frames or more).
    closure_second_opinion : beside recognized labels, close the lips also where the detector
        finds a closure and no /p b m/ is recognized, trusted as far as the voice matches the
        training voice (whose recognized labels the step trusts least). Off by default: on real
        talkers its closures fell where their lips were open (issue 46, docs/labels.md).
    rest_pause_s : a silence is a pause, where the face rests, once it is longer than this: the
        longest silence of a stop closure (a closure is not rested open).
    rest_taper_s : past ``rest_pause_s`` the face reaches the rest face over this much more
        silence.
    rest_lookahead_s : the silence a frame's rest reads counts this much after the frame too
        (the speech/silence decisions a live stream has when it shows the frame); the input's
        end is silence after it.
    """

    n_context_phones: int = 3
    context: int = 3
    xi: float = 20.0
    nu: float | None = None
    mode: Mode = "phonetic"
    gamma_min: float = 0.2
    gamma_max: float = 2.0
    gamma_steps: int = 10
    smoothing: Smoothing = "triangular"
    triangle_s: float = 0.1
    spline_knot_s: float = 0.1
    acoustic_prefilter: int | None = 128
    acoustic_probe: int | None = 8
    speaker_warp: float | None = 1.0
    robust_candidates: int = 32
    label_weight: float = 16.0
    label_weight_by_voice: bool = True
    context_weight: float = 1.0
    mean_normalise: bool = False
    chain_beta: float = 0.1
    closure: bool = True
    closure_labels: bool = True
    rest: bool = True
    closure_taper_s: float = 0.05
    closure_detector: bool = False
    closure_threshold: float = 0.12
    closure_second_opinion: bool = False
    rest_pause_s: float = 0.1
    rest_taper_s: float = 0.05
    rest_lookahead_s: float = 0.05

    def with_(self, **changes) -> SynthConfig:
        """A copy with some fields changed."""
        return replace(self, **changes)

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class EvalConfig:
    """Evaluation settings.

    Attributes
    ----------
    energy_window_s, energy_hop_s : short-time energy analysis (Hamming window, hop).
    median_s : median filter over the energy contour (the paper: 112 ms) so that stop closures
        inside speech are kept.
    threshold_fraction : speech where the filtered energy in dB exceeds
        ``floor + fraction * (peak - floor)``, floor and peak being the 5th and 99th percentiles of
        the utterance's energy in dB.
    moving_fraction : "whole face" averages over the coordinates whose training standard deviation
        (head-normalised) is at least this fraction of the largest one.
    by_labels : the synthesis mode follows each utterance's labels, as in every command
        (:func:`facetraj_engine.method.modes.choose_mode`: acoustic-only without labels, robust with the
        model's cross-validated settings for labels that are not hand-checked); ``False``: each
        config's mode is used as it is (the paper's tables, ablations).
    keep : with ``by_labels``, the settings of the configs that the model's cross-validated ones
        must not replace (set by the user; N in the N sweep).
    """

    energy_window_s: float = 0.02
    energy_hop_s: float = 0.004
    median_s: float = 0.112
    threshold_fraction: float = 0.3
    moving_fraction: float = 0.1
    by_labels: bool = False
    keep: tuple[str, ...] = ()
