"""A recording in, a face out: what ``facetraj synth`` (one file or a batch) and the app do with
an audio file -- the rule for where its labels come from (:func:`facetraj_engine.io.labelling.
labels_for_audio`), the rule for the mode (:func:`facetraj_engine.method.modes.choose_mode`), synthesis
(:func:`facetraj_engine.method.pipeline.synthesize`), and the input's voice match, in one place."""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import SynthConfig
from ..io.audio import read_audio
from ..io.labelling import labels_for_audio
from ..labels.labelmap import read_label_map
from ..labels.provenance import Labels
from ..method.model import Model
from ..method.modes import ModeChoice, choose_mode, mode_of
from ..method.pipeline import Synthesis, check_length, synthesize

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class LabelRequest:
    """Where a recording's labels come from (the options of ``facetraj synth``): a label file,
    the sentence (``text`` or a ``transcript`` file), recognition, else what lies beside the
    audio, else recognition when ``fallback``; ``declared``: how label files from elsewhere were
    made; ``label_map``: a label map (file or ``mocha``) for label files."""

    labels: Path | None = None
    text: str | None = None
    transcript: Path | None = None
    recognize: bool = False
    declared: str | None = None
    label_map: str | None = None
    extra_dict: Mapping[str, Sequence[str]] | None = None
    fallback: bool = True


@dataclass
class RecordingSynthesis:
    """The face of one recording, with its labels, why its mode was chosen, and its voice match
    (:mod:`facetraj_engine.method.voice_match`, NaN for a model file without the figure)."""

    synthesis: Synthesis
    labels: Labels | None
    choice: ModeChoice
    voice_match: float = float("nan")
    audio_path: Path = field(default_factory=Path)

    def describe(self) -> str:
        """One line for the log: labels, mode and why, voice match."""
        labels = self.labels.provenance.describe() if self.labels else "none"
        match = f"; voice match {self.voice_match:.2f}" if np.isfinite(self.voice_match) else ""
        return f"{self.audio_path.name}: labels {labels}; {self.choice.describe()}{match}"


def synthesize_recording(model: Model, audio_path: str | os.PathLike[str],
                         config: SynthConfig | None = None, request: LabelRequest | None = None,
                         explicit: bool = False, keep: Sequence[str] = (),
                         audio: tuple[np.ndarray, int] | None = None) -> RecordingSynthesis:
    """Synthesize the recording at ``audio_path`` (``audio``: its samples and rate, when already
    read) as every command does: its
    labels by the label rule (none when the mode is acoustic and ``explicit``), the mode by the
    mode rule (``explicit``: the user chose ``config.mode``; ``keep``: the settings the user
    set, which the model's tuned ones must not replace)."""
    config = config or SynthConfig()
    request = request or LabelRequest()
    audio_path = Path(audio_path)
    samples, rate = audio if audio is not None else read_audio(audio_path)
    check_length(model, len(samples), rate, str(audio_path))  # before the labels are checked
    labels = None
    if not (explicit and not mode_of(config).needs_labels):
        labels = labels_for_audio(audio_path, samples, rate, labels=request.labels,
                                  text=request.text, transcript=request.transcript,
                                  recognize=request.recognize, extra_dict=request.extra_dict,
                                  declared=request.declared, fallback=request.fallback,
                                  detect_alphabet=not request.label_map)
    choice = choose_mode(config, labels.phones if labels else None,
                         labels.provenance if labels else None, explicit=explicit,
                         tuned=model.tuned, keep=keep)
    label_map = read_label_map(request.label_map) if request.label_map and labels and \
        labels.source == "file" else None
    res = synthesize(model, samples, rate, labels.phones if labels else None, choice.config,
                     label_map=label_map, source=str(request.labels or audio_path),
                     audio_source=str(audio_path), confidence=labels.trust() if labels else None,
                     provenance=labels.provenance if labels else None, voice=True)
    return RecordingSynthesis(res, labels, choice, res.voice_match, audio_path)
