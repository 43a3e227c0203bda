"""What the window shows for one utterance: the utterance, its synthesis and derived tracks.

:func:`build_view` does all the work (synthesis, both smoothings, the speech mask) and is meant to
run in a background worker; the result is an immutable snapshot that every view reads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facetraj_engine.config import SynthConfig
from facetraj_engine.data import Utterance
from facetraj_engine.evaluation.scores import speech_mask
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import Synthesis, resmooth, synthesize
from facetraj_engine.method.resynthesis import SynthesisMemo

from .provenance import LabelOrigin


def frame_index(t: float, rate: float, n_frames: int, step: int = 0) -> int:
    """The frame at ``t`` seconds (``round(t * rate)``), moved by ``step`` frames, clipped to
    ``[0, n_frames - 1]``.

    >>> frame_index(0.51, 60.0, 100), frame_index(0.51, 60.0, 100, step=-1), frame_index(9.0, 60.0, 100)
    (31, 30, 99)
    """
    return int(np.clip(round(t * rate) + step, 0, max(n_frames - 1, 0)))


@dataclass
class UtteranceView:
    """The current utterance and everything derived from it.

    Attributes
    ----------
    utterance : the utterance (audio, phones, markers or ``None``).
    split : ``train``, ``test`` or ``external`` (opened from files, not in the corpus).
    synthesis : the engine's synthesis result (``synthesis.markers`` uses the chosen smoothing).
    original : ``(T, M, 3)`` original markers in the model's head frame, ``None`` without markers.
    triangular, spline : ``(T, M, 3)`` the synthesis smoothed each way (paper Figure 4).
    speech : ``(T,)`` bool, speech frames (112 ms median-filtered energy, paper section 3).
    times : ``(T,)`` frame times in seconds.
    mode_reason : why the synthesis runs in its mode (:func:`facetraj_engine.method.modes.choose_mode`).
    voice_match : how well the recording's voice matches the training voice, in [0, 1]
        (:mod:`facetraj_engine.method.voice_match`; NaN for a model file without the figure).
    origin : where the phone labels came from (the file, the transcript aligned), if known.
    """

    utterance: Utterance
    split: str
    synthesis: Synthesis
    original: np.ndarray | None
    triangular: np.ndarray
    spline: np.ndarray
    speech: np.ndarray
    times: np.ndarray
    mode_reason: str = ""
    voice_match: float = float("nan")
    origin: LabelOrigin | None = None

    @property
    def label_origin(self) -> LabelOrigin:
        """Where the phone labels came from (at least their source)."""
        utt = self.utterance
        source = utt.label_source if utt.phones else "none"
        corrected = utt.provenance.corrected if utt.phones and not utt.provenance.hand_checked else 0
        if self.origin is None:
            return LabelOrigin(source, corrected=corrected)
        return LabelOrigin(source, self.origin.file, self.origin.transcript, corrected)

    @property
    def shown(self) -> np.ndarray:
        """The synthesized markers the 3-D view shows (the configured smoothing)."""
        return self.synthesis.markers

    @property
    def n_frames(self) -> int:
        return len(self.times)

    @property
    def duration(self) -> float:
        return self.utterance.duration

    @property
    def rate(self) -> float:
        """Marker frames per second."""
        return float(1.0 / (self.times[1] - self.times[0])) if len(self.times) > 1 else 60.0

    def frame_at(self, t: float, step: int = 0) -> int:
        """The frame shown at ``t`` seconds (moved by ``step`` frames), within the utterance."""
        return frame_index(t, self.rate, self.n_frames, step)


def build_view(model: Model, utt: Utterance, split: str, config: SynthConfig,
               mode_reason: str = "", origin: LabelOrigin | None = None,
               memo: SynthesisMemo | None = None) -> UtteranceView:
    """Synthesize ``utt`` with ``config`` (its labels weighed by their confidence) and derive
    every track the window shows (slow: run in a worker). ``memo``: the recording's last
    synthesis (another label set: only what the labels change is computed again,
    ``facetraj_engine.method.resynthesis``). Raises the engine's
    :class:`~facetraj_engine.errors.FacetrajError` on bad input."""
    n_frames = utt.n_frames or None
    res = synthesize(model, utt.audio, utt.sample_rate, utt.phones if utt.phones else None,
                     config, n_frames=n_frames, source=utt.name, confidence=utt.confidence,
                     provenance=utt.provenance, voice=True, memo=memo, checked=utt.checked)
    original = model.normalise_markers(utt.markers) if utt.markers is not None else None
    triangular, spline, speech = _tracks(model, res, utt.audio, utt.sample_rate, memo)
    return UtteranceView(utterance=utt, split=split, synthesis=res, original=original,
                         triangular=triangular, spline=spline, speech=speech, times=res.times,
                         mode_reason=mode_reason, voice_match=res.voice_match, origin=origin)


def _tracks(model: Model, synthesis: Synthesis, audio: np.ndarray | None,
            sample_rate: int, memo: SynthesisMemo | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The triangular and the spline smoothing of ``synthesis`` (its markers for the smoothing it
    was made with) and the speech frames of ``audio`` (none without it; the ``memo``'s, kept)."""
    made = synthesis.config.smoothing
    triangular, spline = (synthesis.markers if made == kind else resmooth(model, synthesis, kind)
                          for kind in ("triangular", "spline"))
    if audio is None:
        return triangular, spline, np.zeros(len(synthesis.times), dtype=bool)
    speech = memo.remember("speech frames", lambda: speech_mask(audio, sample_rate, synthesis.times)) \
        if memo is not None and memo.bound and memo.bound[1] is audio else \
        speech_mask(audio, sample_rate, synthesis.times)
    return triangular, spline, speech


def view_of_synthesis(model: Model, synthesis: Synthesis, audio: np.ndarray | None = None,
                      sample_rate: int = 16000, phones=(), original: np.ndarray | None = None,
                      name: str = "speech", text: str = "", words=(),
                      split: str = "external") -> UtteranceView:
    """The view of a synthesis made elsewhere (``facetraj video``): both smoothings and the
    speech frames of ``audio`` (none without it) derived as :func:`build_view` derives them."""
    triangular, spline, speech = _tracks(model, synthesis, audio, sample_rate)
    if audio is None:
        audio = np.zeros(int(round(synthesis.times[-1] * sample_rate)) + 1)
    utt = Utterance(name=name, audio=audio, sample_rate=sample_rate, phones=list(phones or []),
                    markers=None, marker_rate=model.marker_rate,
                    marker_names=list(model.marker_names), words=list(words or []), text=text,
                    label_source="file" if phones else "none")
    return UtteranceView(utterance=utt, split=split, synthesis=synthesis, original=original,
                         triangular=triangular, spline=spline, speech=speech, times=synthesis.times)
