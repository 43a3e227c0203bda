"""The voice match of a stream, measured as it runs (live mode, issue 27).

Offline, :func:`facetraj_engine.method.pipeline.input_voice_ratio` takes the median, over (at most 400
evenly spaced) speech frames of the whole recording, of eq 5's distance to the nearest codeword,
over the training voice's own figure ``D0`` (:mod:`facetraj_engine.method.voice_match`). A stream has the
frames so far: :class:`RunningVoice` keeps the distances of the last ``MAX_FRAMES`` speech frames
(6.7 s of speech) and gives their median ratio once ``MIN_FRAMES`` have been heard. It is live
mode's one running adaptation: the robust mode's label weight grows with the ratio
(``SynthConfig.label_weight_by_voice``) and recognized /p b m/ close as far as the voice does not
match (:func:`facetraj_engine.method.closure.closure_strengths`).

Until the voice has been measured, live mode takes it for an unmatched voice (``PRIOR_MATCH``):
a person at a microphone is not the training voice, which is synthetic (the ARCTIC talkers are at
3.5-4.8 ``D0``, voice match 0).
"""

from __future__ import annotations

from collections import deque

import numpy as np

from ..method.voice_match import (
    MAX_FRAMES,
    MIN_FRAMES,
    PRIOR_MATCH,
    indexed_distances,
    label_weight_scale,
    voice_match,
)
from .speech import SPEECH, SpeechStream

#: Speech frames whose voice distances are computed together (the running ratio moves slowly).
VOICE_BATCH = 30


class RunningVoice:
    """Distances of speech frames in (:meth:`add`), the running ratio ``D / D0`` and voice match
    out.

    >>> v = RunningVoice(reference=2.0, min_frames=2)
    >>> v.ratio, v.match
    (nan, 0.0)
    >>> v.add(np.array([4.0, 6.0, 8.0]))
    >>> v.ratio, v.match
    (3.0, 0.0)
    """

    def __init__(self, reference: float, max_frames: int = MAX_FRAMES, min_frames: int = MIN_FRAMES):
        self.reference = float(reference)
        self.min_frames = min_frames
        self._d: deque[float] = deque(maxlen=max_frames)
        self.heard = 0

    def add(self, distances: np.ndarray) -> None:
        """The distances of newly heard speech frames."""
        d = np.asarray(distances, dtype=np.float64)
        self._d.extend(d[np.isfinite(d)].tolist())
        self.heard += int(np.isfinite(d).sum())

    @property
    def ratio(self) -> float:
        """``D / D0`` of the speech frames kept; NaN before ``min_frames`` (or without ``D0``)."""
        if len(self._d) < self.min_frames or not (np.isfinite(self.reference) and self.reference > 0):
            return float("nan")
        return float(np.median(np.fromiter(self._d, float))) / self.reference

    @property
    def match(self) -> float:
        """The voice match in [0, 1] (:func:`facetraj_engine.method.voice_match.voice_match`), or
        ``PRIOR_MATCH`` while the ratio is unknown."""
        r = self.ratio
        return voice_match(r, 1.0) if np.isfinite(r) else PRIOR_MATCH

    def weight_scale(self, by_voice: bool = True) -> float:
        """The factor of the robust mode's label weight
        (:func:`facetraj_engine.method.voice_match.label_weight_scale` of the running ratio)."""
        return label_weight_scale(self.ratio, by_voice)


class VoiceTracker:
    """A stream's :class:`RunningVoice` fed with the analysed frames' LSFs (:meth:`add`) once
    its :class:`~facetraj_engine.streaming.speech.SpeechStream` has decided they are speech, in
    batches of :data:`VOICE_BATCH` speech frames (:meth:`update`)."""

    def __init__(self, model, speech: SpeechStream):
        self.model, self.speech = model, speech
        self.voice = RunningVoice(model.voice_distance)
        self._pending: list[np.ndarray] = []             # LSFs of analysed frames _voiced ...
        self._voiced = 0
        self._counted, self._heard = 0, 0                 # decisions counted, speech among them
        self.heard_from: int | None = None

    def _count_heard(self) -> None:
        """:attr:`heard_from`: the frame after the ``MIN_FRAMES``-th speech frame decided
        (:func:`facetraj_engine.method.voice_match.match_from`, as offline), once it is."""
        if self.heard_from is not None:
            return
        new = np.asarray(self.speech.decisions[self._counted:]) == SPEECH
        at = np.flatnonzero(new)
        if self._heard + at.size >= MIN_FRAMES:
            self.heard_from = self._counted + int(at[MIN_FRAMES - self._heard - 1]) + 1
        self._heard += at.size
        self._counted += new.size

    def add(self, lsf: np.ndarray) -> None:
        """The next analysed frames' LSFs."""
        self._pending.append(lsf)

    def update(self, final: bool = False) -> None:
        """The voice distances of the analysed frames now known to be speech, once there are
        ``VOICE_BATCH`` of them (``final``: all)."""
        self._count_heard()
        pending = np.concatenate(self._pending) if self._pending else np.zeros((0, 1))
        known = min(self.speech.known, self._voiced + len(pending))
        speech = np.asarray(self.speech.decisions[self._voiced:known]) == SPEECH
        if speech.sum() < VOICE_BATCH and not (final and known > self._voiced):
            return
        w = pending[:known - self._voiced][speech]
        if len(w):
            self.voice.add(indexed_distances(w, self.model.codebook.lsf, self.model.lsf_index()))
        self._pending = [pending[known - self._voiced:]]
        self._voiced = known
