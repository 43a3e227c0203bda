"""What every marker-file reader returns: a :class:`MarkerRecording`."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ...data import PhoneSegment


@dataclass
class MarkerRecording:
    """Marker trajectories read from one file, and what the file brings along.

    Attributes
    ----------
    markers : ``(frames, markers, 3)`` in mm, facetraj's axes (x right, y up, z forward); NaN where
        a sample is missing. Two-dimensional (midsagittal) data has x = 0 for every marker.
    rate : frames per second.
    names : one name per marker (the file's, else ``Ch1``, ``Ch2``, ...).
    format : the name of the format that read it (:mod:`.registry`).
    head_corrected : ``True`` when the file says its data is already corrected for head motion
        (no fixed markers are needed), ``None`` when it does not say.
    audio, audio_rate : the speech the file holds (mono float samples), if any.
    phones, words : labels the file holds (times in seconds), if any.
    transcript : the sentence the file holds, if any.
    missing : samples the reader marked missing (NaN, a sentinel value, a status flag, an rms
        over the threshold): never positions.
    """

    markers: np.ndarray
    rate: float
    names: list[str]
    format: str = ""
    head_corrected: bool | None = None
    audio: np.ndarray | None = None
    audio_rate: int = 0
    phones: list[PhoneSegment] = field(default_factory=list)
    words: list[PhoneSegment] = field(default_factory=list)
    transcript: str = ""
    missing: int = 0

    @property
    def dimensions(self) -> int:
        """2 for midsagittal data (every seen x is 0), else 3."""
        x = self.markers[..., 0]
        return 2 if not np.any(x[np.isfinite(x)]) else 3

    def with_markers(self, markers: np.ndarray, rate: float | None = None,
                     names: list[str] | None = None) -> MarkerRecording:
        """The same recording with other trajectories (resampled, renamed, a subset)."""
        return replace(self, markers=markers, rate=self.rate if rate is None else float(rate),
                       names=list(self.names if names is None else names))


def unnamed(n: int) -> list[str]:
    """The names of ``n`` channels a file does not name, as Carstens' own text export calls them.

    >>> unnamed(3)
    ['Ch1', 'Ch2', 'Ch3']
    """
    return [f"Ch{i + 1}" for i in range(n)]


def midsagittal(anterior: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Midsagittal (2-D) positions in facetraj's axes: x = 0 (the midsagittal plane), y up, z
    forward; ``anterior`` and ``up`` are ``(frames, markers)`` in mm."""
    return np.stack([np.zeros_like(anterior), up, anterior], axis=-1)
