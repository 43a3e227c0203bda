"""The data model: one utterance of synchronized speech, phone labels and face markers."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class PhoneSegment:
    """One labelled interval, times in seconds."""

    start: float
    end: float
    label: str

    @property
    def duration(self) -> float:
        return self.end - self.start


@dataclass
class Utterance:
    """Speech, phone labels and (optionally) 3-D face markers of one utterance.

    Attributes
    ----------
    name : utterance id (file stem).
    audio : mono samples, float64 in [-1, 1].
    sample_rate : audio rate in Hz.
    phones : phone segments in time order covering the audio (``sil`` for silence).
    markers : ``(frames, n_markers, 3)`` in mm, NaN where a marker was not seen; ``None`` when
        the utterance has no face data (synthesis input only).
    marker_rate : marker frames per second (60 in the paper).
    marker_names : one name per marker.
    words : optional word segments (display only).
    text : optional orthographic text.
    label_source : where ``phones`` came from: ``"file"`` (a label file), ``"aligned"`` (forced
        alignment of ``text``), ``"recognized"`` (phone recognition) or ``"none"``
        (``engine.labels.alignment`` / ``engine.io.labelling``).
    """

    name: str
    audio: np.ndarray
    sample_rate: int
    phones: list[PhoneSegment] = field(default_factory=list)
    markers: np.ndarray | None = None
    marker_rate: float = 60.0
    marker_names: list[str] = field(default_factory=list)
    words: list[PhoneSegment] = field(default_factory=list)
    text: str = ""
    label_source: str = "file"

    @property
    def duration(self) -> float:
        """Audio duration in seconds."""
        return len(self.audio) / float(self.sample_rate)

    @property
    def n_frames(self) -> int:
        """Number of marker frames (0 without markers)."""
        return 0 if self.markers is None else int(self.markers.shape[0])

    def frame_times(self, n_frames: int | None = None) -> np.ndarray:
        """Times in seconds of marker frames ``0 .. n-1`` (frame k at ``k / marker_rate``).

        Without markers, ``n_frames`` defaults to the number of frames that fit in the audio.
        """
        if n_frames is None:
            n_frames = self.n_frames or int(np.floor(self.duration * self.marker_rate)) + 1
        return np.arange(n_frames) / float(self.marker_rate)
