"""A recording in, a face out: what ``facetraj synth`` (one file or a batch), ``facetraj video``
and the app do with an audio file -- the rule for where its labels come from
(:func:`facetraj_engine.io.label_rule.resolve_labels`, asked by a :class:`LabelRequest`), the rule for
the mode (:func:`facetraj_engine.method.modes.choose_mode`), synthesis
(:func:`facetraj_engine.method.pipeline.synthesize`), and the input's voice match, in one place."""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import SynthConfig
from ..io.audio import read_audio
from ..io.label_rule import FoundLabels, LabelRequest, resolve_labels
from ..labels.labelmap import read_label_map
from ..labels.provenance import Labels
from ..method.model import Model
from ..method.modes import ModeChoice, choose_mode, mode_of
from ..method.pipeline import Synthesis, check_length, synthesize
from ..method.voice_match import explain_match
from ..progress import Progress

__all__ = ["LabelRequest", "RecordingSynthesis", "synthesize_recording"]

log = logging.getLogger(__name__)


@dataclass
class RecordingSynthesis:
    """The face of one recording, with its labels and where they came from (``found``), why its
    mode was chosen, and its voice match (:mod:`facetraj_engine.method.voice_match`, NaN for a
    model file without the figure)."""

    synthesis: Synthesis
    found: FoundLabels
    choice: ModeChoice
    voice_match: float = float("nan")
    audio_path: Path = field(default_factory=Path)

    @property
    def labels(self) -> Labels | None:
        return self.found.labels

    def describe(self) -> str:
        """One line for the log: labels and where they came from, mode and why, voice match and
        what it changed (:func:`facetraj_engine.method.voice_match.explain_match`)."""
        match = ""
        if np.isfinite(self.voice_match):
            match = "; " + explain_match(self.synthesis.voice_ratio, self.choice.config,
                                         self.labels.provenance.kind if self.labels else None)
        return (f"{self.audio_path.name}: labels {self.found.describe()}; {self.choice.describe()}"
                f"{match}")


def synthesize_recording(model: Model, audio_path: str | os.PathLike[str],
                         config: SynthConfig | None = None, request: LabelRequest | None = None,
                         explicit: bool = False, keep: Sequence[str] = (),
                         audio: tuple[np.ndarray, int] | None = None,
                         allow_damaged: bool = False, progress: Progress | None = None
                         ) -> RecordingSynthesis:
    """Synthesize the recording at ``audio_path`` (``audio``: its samples and rate, when already
    read; ``allow_damaged``: read an audio file whose header does not match its data, as
    :func:`facetraj_engine.io.audio.read_audio`) as every command does: its labels by the label rule
    (none when the mode is acoustic and ``explicit``), the mode by the mode rule (``explicit``:
    the user chose ``config.mode``; ``keep``: the settings the user set, which the model's tuned
    ones must not replace; ``progress``: told as labelling and synthesis go, which on a long
    recording take seconds each)."""
    config = config or SynthConfig()
    request = request or LabelRequest()
    audio_path = Path(audio_path)
    samples, rate = audio if audio is not None else read_audio(audio_path, allow_damaged)
    check_length(model, len(samples), rate, str(audio_path))  # before the labels are checked
    found = FoundLabels(None, f"--mode {config.mode}: none asked for")
    if not (explicit and not mode_of(config).needs_labels):
        found = resolve_labels(audio_path, samples, rate, request, progress=progress)
    labels = found.labels
    choice = choose_mode(config, labels.phones if labels else None,
                         labels.provenance if labels else None, explicit=explicit,
                         tuned=model.tuned, keep=keep)
    label_map = read_label_map(request.label_map) if request.label_map and labels and \
        labels.source == "file" else None
    if progress is not None:
        progress(0.0, f"synthesizing {audio_path.name} ({choice.mode} mode)")
    res = synthesize(model, samples, rate, labels.phones if labels else None, choice.config,
                     label_map=label_map, source=str(found.file or audio_path),
                     audio_source=str(audio_path), confidence=labels.trust() if labels else None,
                     provenance=labels.provenance if labels else None, voice=True,
                     checked=labels.checked if labels else None)
    if progress is not None:
        progress(1.0, f"{len(res.times)} frames synthesized")
    return RecordingSynthesis(res, found, choice, res.voice_match, audio_path)
