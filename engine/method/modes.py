"""Which synthesis mode the labels allow: THE rule, used by every command and the app.

The paper's phonetic mode (section 2.3, eq 4) trusts its labels fully: right for hand-checked
labels, wrong for labels from an aligner or a recognizer, whose errors it copies into the face.
So the mode follows the labels' provenance (``facetraj_engine.labels.provenance``):

- no labels: acoustic-only (the paper's "5N replaced with the whole codebook");
- hand-checked labels: the paper's phonetic mode;
- aligned or recognized labels: the robust mode (``facetraj_engine.method.selection``), each phone's label
  counting as much as its maker trusted it, with the settings cross-validated at training
  (:func:`tuned_config`, ``facetraj train``);
- a mode the user chose explicitly is kept (acoustic-only when there are no labels at all).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from ..config import SynthConfig
from ..data import PhoneSegment, Provenance

#: Settings a tuning stores and :func:`tuned_config` applies (the SynthConfig fields it may change).
TUNED_FIELDS = ("n_context_phones", "xi", "label_weight", "context_weight", "robust_candidates",
                "gamma_max", "triangle_s", "chain_beta")


@dataclass(frozen=True)
class ModeChoice:
    """The settings a synthesis runs with, and why its mode was chosen."""

    config: SynthConfig
    reason: str

    @property
    def mode(self) -> str:
        return self.config.mode

    def describe(self) -> str:
        """``"robust mode: aligned labels are not hand-checked"``."""
        return f"{mode_name(self.config)} mode: {self.reason}"


def mode_name(config: SynthConfig) -> str:
    """The mode as the user knows it: ``phonetic``, ``robust``, ``acoustic-only (indexed)`` or
    ``acoustic-only (whole codebook)``, the paper's search.

    >>> mode_name(SynthConfig(mode="acoustic")), mode_name(SynthConfig(mode="acoustic",
    ...                                                               acoustic_prefilter=None))
    ('acoustic-only (indexed)', 'acoustic-only (whole codebook)')
    """
    if config.mode != "acoustic":
        return config.mode
    return "acoustic-only (indexed)" if config.acoustic_prefilter else "acoustic-only (whole codebook)"


def tuned_config(config: SynthConfig, tuned: Mapping | None, keep: Sequence[str] = ()) -> SynthConfig:
    """``config`` with a model's cross-validated settings (robust mode only; fields unknown to
    this facetraj, and the fields in ``keep`` -- set by the user -- are left alone).

    >>> tuned_config(SynthConfig(mode="robust"), {"settings": {"label_weight": 2.0}}).label_weight
    2.0
    >>> tuned_config(SynthConfig(), {"settings": {"label_weight": 2.0}}).label_weight
    16.0
    >>> tuned_config(SynthConfig(mode="robust"), {"settings": {"label_weight": 2.0}},
    ...              keep=("label_weight",)).label_weight
    16.0
    """
    if config.mode != "robust" or not tuned:
        return config
    kw = {k: v for k, v in dict(tuned.get("settings", {})).items()
          if k in TUNED_FIELDS and k not in keep}
    return config.with_(**kw)


def choose_mode(config: SynthConfig, phones: Sequence[PhoneSegment] | None,
                provenance: Provenance | None = None, *, explicit: bool = False,
                tuned: Mapping | None = None, keep: Sequence[str] = ()) -> ModeChoice:
    """THE rule for the synthesis mode (module docstring): ``config`` switched by the labels
    (``phones``, made as ``provenance`` says; ``None``: hand-checked) unless the user chose its
    mode (``explicit``), with the model's ``tuned`` settings in the robust mode (except the
    fields in ``keep``, which the user set).

    >>> segs = [PhoneSegment(0.0, 0.1, "sil")]
    >>> choose_mode(SynthConfig(), None).describe()
    'acoustic-only (indexed) mode: no phone labels'
    >>> choose_mode(SynthConfig(), segs).describe()
    'phonetic mode: hand-checked labels (the paper)'
    >>> choose_mode(SynthConfig(), segs, Provenance("recognized")).describe()
    'robust mode: recognized labels are not hand-checked'
    >>> choose_mode(SynthConfig(), segs, Provenance("aligned"), explicit=True).describe()
    'phonetic mode: chosen, although the labels are aligned'
    """
    provenance = provenance or Provenance()
    if not phones:
        if config.mode == "acoustic":
            return ModeChoice(config, "chosen" if explicit else "no phone labels")
        return ModeChoice(config.with_(mode="acoustic"), "no phone labels")
    if explicit:
        reason = "chosen" if provenance.hand_checked or config.mode != "phonetic" else \
            f"chosen, although the labels are {provenance.kind}"
        return ModeChoice(tuned_config(config, tuned, keep), reason)
    if config.mode == "phonetic" and not provenance.hand_checked:
        robust = tuned_config(config.with_(mode="robust"), tuned, keep)
        reason = f"{provenance.kind} labels are not hand-checked"
        if provenance.corrected:
            reason += f" ({provenance.corrected} phones corrected by hand count as checked)"
        return ModeChoice(robust, reason + (", settings cross-validated at training" if tuned else ""))
    if config.mode == "phonetic":
        return ModeChoice(config, "hand-checked labels (the paper)")
    return ModeChoice(tuned_config(config, tuned, keep), "chosen")
