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

from ..config import SynthConfig, TrainConfig
from ..io.audio import read_audio
from ..io.labelling import labels_for_audio
from ..labels.labelmap import read_label_map
from ..labels.provenance import Labels
from ..threads import beside
from .model import Model, analysed_lsf
from .modes import ModeChoice, choose_mode
from .pipeline import Synthesis, check_length, frame_count, synthesize

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


class EarlyLsf:
    """A recording's input LSFs (eq 5's w), analysed beside other work (:func:`facetraj_engine.threads.
    beside`) from the moment the model file's settings (its checked metadata,
    :meth:`Model.read_settings`) and the audio are read, while the caller reads the model's
    arrays and the labels: the compiled analysis lets go of the interpreter lock, so on a 60 s
    file its 13 ms ran beside the model file's 15 ms and the labels' 5 ms (issue 28).
    :meth:`for_model` gives them to a model of the same settings and marker rate (else
    ``None``: computed again, as without this); an analysis that fails here gives ``None`` too,
    and fails again where the synthesis computes it, as it would have."""

    def __init__(self, config: TrainConfig, marker_rate: float, samples: np.ndarray, rate: int,
                 kernels: str = "compiled"):
        from .kernels import use_kernels

        self._settings = (config, float(marker_rate))
        times = np.arange(frame_count(len(samples), rate, marker_rate)) / float(marker_rate)

        def analyse() -> np.ndarray | None:
            try:
                with use_kernels(kernels):
                    return analysed_lsf(config, samples, rate, times, threads=1)
            except Exception:                       # computed again, where it fails as it would
                log.debug("the early LSF analysis failed", exc_info=True)
                return None

        self._result = beside(analyse, len(times))

    @classmethod
    def start(cls, model_path: str | os.PathLike[str], audio_path: str | os.PathLike[str],
              kernels: str = "compiled") -> tuple[EarlyLsf, tuple[np.ndarray, int]]:
        """The model file's settings read, then the audio (each refused as it is when the
        command reads it), the analysis begun; the early analysis and the audio read."""
        config, marker_rate = Model.read_settings(model_path)
        samples, rate = read_audio(audio_path)
        return cls(config, marker_rate, samples, rate, kernels), (samples, rate)

    def for_model(self, model: Model) -> np.ndarray | None:
        """The LSFs, once analysed, if ``model`` has the settings and marker rate read first
        (the file was not replaced between the two reads); else ``None``."""
        lsf = self._result()
        return lsf if (model.config, float(model.marker_rate)) == self._settings else None


def synthesize_recording(model: Model, audio_path: str | os.PathLike[str],
                         config: SynthConfig | None = None, request: LabelRequest | None = None,
                         explicit: bool = False, keep: Sequence[str] = (),
                         audio: tuple[np.ndarray, int] | None = None,
                         early: EarlyLsf | None = None) -> RecordingSynthesis:
    """Synthesize the recording at ``audio_path`` (``audio``: its samples and rate, when already
    read; ``early``: its input LSFs being analysed, :class:`EarlyLsf`) as every command does: its
    labels by the label rule (none when the mode is acoustic and ``explicit``), the mode by the
    mode rule (``explicit``: the user chose ``config.mode``; ``keep``: the settings the user
    set, which the model's tuned ones must not replace)."""
    config = config or SynthConfig()
    request = request or LabelRequest()
    audio_path = Path(audio_path)
    samples, rate = audio if audio is not None else read_audio(audio_path)
    check_length(model, len(samples), rate, str(audio_path))  # before the labels are checked
    labels = None
    if not (explicit and config.mode == "acoustic"):
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
                     lsf=early.for_model(model) if early else None,
                     label_map=label_map, source=str(request.labels or audio_path),
                     audio_source=str(audio_path), confidence=labels.trust() if labels else None,
                     provenance=labels.provenance if labels else None, voice=True)
    return RecordingSynthesis(res, labels, choice, res.voice_match, audio_path)
