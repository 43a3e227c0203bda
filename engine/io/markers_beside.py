"""The marker file beside a recording: a recording opened for synthesis (``facetraj synth``, the
app's *Open audio*) that has its own markers beside it (``s002.flac`` and ``s002.c3d``; MOCHA's
``fsew0_001.wav`` and ``fsew0_001.ema``) can be compared with them.

:func:`read_markers_beside` reads them when their marker set is the model's (resampled to the
model's rate and fitted to the audio's length, as a corpus utterance's are), and otherwise says
what they hold instead, so that the caller can point to *Import your own recordings* (which
trains a model on that marker set).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import FacetrajError
from .corpus import fitted_frames, marker_path, marker_set_difference
from .markerfiles import read_markers


def marker_file_beside(audio_path: str | os.PathLike[str]) -> Path | None:
    """The marker file (C3D, TSV/CSV, MOCHA .ema) with the audio file's name beside it, if any."""
    audio_path = Path(audio_path)
    try:
        return marker_path(audio_path.parent, audio_path.stem)
    except FacetrajError:
        return None


@dataclass(frozen=True)
class MarkersBeside:
    """What the marker file beside a recording holds. ``markers`` ``(T, M, 3)`` when its marker
    set is the model's (else None, and ``difference`` says how it differs)."""

    path: Path
    names: list[str]
    markers: np.ndarray | None
    difference: str = ""

    @property
    def usable(self) -> bool:
        return self.markers is not None

    def hint(self, audio_name: str, model_markers: int | None = None) -> str:
        """One sentence for the user when the markers cannot be used with this model (of
        ``model_markers`` markers), in words (no list syntax).

        >>> MarkersBeside(Path("a.ema"), ["UL", "LL", "TT"], None).hint("a.wav", 54).split(":")[0]
        "a.ema beside a.wav holds 3 other markers (UL, LL and TT) than the model's 54"
        """
        names = self.names if len(self.names) <= 10 else [*self.names[:8], f"{len(self.names) - 8} more"]
        listed = names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"
        model = f" the model's {model_markers}" if model_markers else " this model's"
        return (f"{self.path.name} beside {audio_name} holds {len(self.names)} other markers "
                f"({listed}) than{model}: to compare with them, import its folder (File → Import "
                "your own recordings…) and open that corpus")


def read_markers_beside(audio_path: str | os.PathLike[str], marker_names: Sequence[str],
                        marker_rate: float, duration_s: float) -> MarkersBeside | None:
    """The markers beside ``audio_path`` (None without a marker file). With the model's marker
    set (``marker_names``): resampled to ``marker_rate`` and fitted to ``duration_s`` of audio
    (one frame per 1/rate s from 0, NaN where they end early). A file that cannot be read raises
    the reader's :class:`~facetraj_engine.errors.InputError` naming it."""
    path = marker_file_beside(audio_path)
    if path is None:
        return None
    data = read_markers(path, marker_rate)
    if list(data.names) != list(marker_names):
        return MarkersBeside(path, list(data.names), None,
                             marker_set_difference(list(data.names), list(marker_names)))
    n_frames = int(np.floor(duration_s * marker_rate + 1e-9)) + 1
    return MarkersBeside(path, list(data.names), fitted_frames(data.markers, n_frames))


__all__ = ["MarkersBeside", "marker_file_beside", "read_markers_beside"]
