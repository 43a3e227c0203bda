"""The data model: one utterance of synchronized speech, phone labels and face markers, and
where its labels came from."""

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


#: How phone labels were made (:class:`Provenance`).
LABEL_KINDS = ("hand-checked", "aligned", "recognized")


@dataclass(frozen=True)
class Provenance:
    """How a set of phone labels was made; the record travels with them in their TextGrid
    (``facetraj_engine.labels.provenance``).

    Attributes
    ----------
    kind : ``hand-checked`` (checked by a person: the paper's labels, and any label file from
        elsewhere unless the user says otherwise), ``aligned`` (from a transcript) or
        ``recognized`` (from speech alone).
    tool : what made them (``PocketSphinx 5.1.1``), if known.
    origin : what they were made from (a transcript file, ``--text``), if known.
    corrected : phones corrected by hand after they were made (0: none).
    why : how the kind was told, when the labels do not record it (a label file in an aligner's
        conventions, :func:`facetraj_engine.labels.provenance.aligner_conventions`), else ``""``.
    """

    kind: str = "hand-checked"
    tool: str = ""
    origin: str = ""
    corrected: int = 0
    why: str = ""

    def __post_init__(self) -> None:
        if self.kind not in LABEL_KINDS:
            raise ValueError(f"label provenance must be one of {', '.join(LABEL_KINDS)}, "
                             f"got {self.kind!r}")

    @property
    def hand_checked(self) -> bool:
        """Whether every phone was checked by a person (the paper's phonetic mode trusts them)."""
        return self.kind == "hand-checked"

    def describe(self) -> str:
        """In words, for logs and the app.

        >>> Provenance("aligned", "PocketSphinx 5.1.1", "s001.txt", corrected=2).describe()
        'aligned from s001.txt (PocketSphinx 5.1.1), 2 phones corrected by hand'
        >>> Provenance().describe()
        'hand-checked'
        """
        text = self.kind
        if self.origin:
            text += f" from {self.origin}"
        if self.tool:
            text += f" ({self.tool})"
        if self.corrected:
            text += f", {self.corrected} phone{'s' if self.corrected != 1 else ''} corrected by hand"
        if self.why:
            text += f" ({self.why})"
        return text


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
        (``facetraj_engine.labels.alignment`` / ``facetraj_engine.io.labelling``).
    provenance : how ``phones`` were made (a label file records it; else hand-checked).
    confidence : per phone, how sure their maker was, in (0, 1] (NaN: no score); ``None`` for
        hand-checked labels.
    checked : per phone of automatic labels, whether a person corrected it since (trusted as
        hand-checked: the closure step closes a corrected /p b m/ whatever the voice); ``None``:
        none.
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
    provenance: Provenance = field(default_factory=Provenance)
    confidence: np.ndarray | None = None
    checked: np.ndarray | None = None

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
