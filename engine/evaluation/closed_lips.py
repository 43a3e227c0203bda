"""Synthesized closures judged by the talker's own lips (issue 46), beside the correlation.

Wherever a corpus has the talker's lip markers, the frames where the talker's lips are closed
are known from the markers themselves, not from phone labels: a frame is *closed* when its lip
aperture (upper-lip centre y minus lower-lip centre y, head frame, mm) is within ``tol`` (1 mm)
of the talker's closed value, at most ``closed + tol``. The closed value is the talker's own
(:func:`talker_closed`): the median, over the labelled /p b m/ of the utterances measured, of
the original aperture's minimum inside each; where no /p b m/ is labelled, the aperture's lowest
percentile over the speech frames. The synthesized face's closed frames are judged against the
same value, on the frames the correlations are computed on (speech frames by energy, both faces
seen): *precision*, the share of the synthesized closed frames where the talker's lips are
closed; *recall*, the share of the talker's closed frames where the synthesized lips are
(:class:`ClosureAgreement`, pooled over utterances by adding frames).

The closed value depends on every utterance measured, so each utterance's part is kept
(:class:`TalkerLips`, its speech frames' apertures as float32: 4 bytes a frame and face) and
the frames counted once the value is known (:func:`agreements`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..data import PhoneSegment
from ..method.closure import BILABIALS
from .closure import lip_aperture, segment_values

#: Frames within this many mm of the closed aperture are closed.
CLOSED_TOL_MM = 1.0
#: Without labelled /p b m/, the talker's closed value is this percentile of its speech frames'
#: aperture.
LOWEST_PERCENTILE = 1.0


@dataclass
class TalkerLips:
    """One utterance's original lips: the aperture's minimum in each labelled /p b m/
    (``minima``), and on the frames scored (``mask``) the original aperture (``original``) and
    each synthesized face's (``synthesized``, one per condition, in order), float32."""

    minima: np.ndarray
    original: np.ndarray
    synthesized: list[np.ndarray]
    mask: np.ndarray | None = None
    lips: tuple[int, int] = (0, 1)

    def add(self, markers: np.ndarray) -> None:
        """A synthesized face ``(T, M, 3)`` of the utterance: its aperture on the frames scored."""
        if self.mask is None or len(markers) != len(self.mask):
            raise ValueError(f"a face of {len(markers)} frames for an utterance of "
                             f"{0 if self.mask is None else len(self.mask)}")
        self.synthesized.append(lip_aperture(markers, *self.lips)[self.mask].astype(np.float32))


def talker_lips(original: np.ndarray, times: np.ndarray, phones: Sequence[PhoneSegment],
                mask: np.ndarray, upper: int, lower: int) -> TalkerLips:
    """The :class:`TalkerLips` of one utterance's original markers ``(T, M, 3)`` (head frame)
    and its labels, on the frames of ``mask`` where the original is seen; synthesized faces are
    added with :meth:`TalkerLips.add`."""
    a = lip_aperture(original, upper, lower)
    bil = [s for s in phones if s.label in BILABIALS]
    minima = segment_values(a, times, bil, "min") if bil else np.zeros(0)
    seen = np.asarray(mask, dtype=bool) & np.isfinite(original).all(axis=(1, 2))
    return TalkerLips(minima[np.isfinite(minima)], a[seen].astype(np.float32), [], seen,
                      (upper, lower))


@dataclass(frozen=True)
class TalkerClosed:
    """The talker's closed aperture (mm) and how it was found: from ``bilabials`` labelled
    /p b m/ (their median minimum), or (``bilabials == 0``) the lowest percentile of ``frames``
    speech frames."""

    closed: float
    bilabials: int
    frames: int

    def describe(self) -> str:
        """How the value was found, for a log line or a report.

        >>> TalkerClosed(11.17, 110, 9000).describe()
        "the talker's closed lip aperture 11.17 mm (the median minimum of its 110 labelled /p b m/)"
        >>> TalkerClosed(3.2, 0, 80).describe()[-64:]
        'no /p b m/ labelled: the 1st percentile of its 80 speech frames)'
        """
        how = (f"the median minimum of its {self.bilabials} labelled /p b m/" if self.bilabials else
               f"no /p b m/ labelled: the {LOWEST_PERCENTILE:g}st percentile of its {self.frames} "
               f"speech frames")
        return f"the talker's closed lip aperture {self.closed:.2f} mm ({how})"

    def to_json(self) -> dict:
        return {"closed": self.closed, "bilabials": self.bilabials, "frames": self.frames,
                "tol_mm": CLOSED_TOL_MM}


def talker_closed(parts: Sequence[TalkerLips]) -> TalkerClosed:
    """The talker's closed value over ``parts``: the median of their /p b m/ minima, else the
    :data:`LOWEST_PERCENTILE` of their apertures (NaN when there is no frame).

    >>> part = TalkerLips(np.zeros(0), np.arange(101, dtype=np.float32), [])
    >>> talker_closed([part])
    TalkerClosed(closed=1.0, bilabials=0, frames=101)
    >>> talker_closed([TalkerLips(np.array([11.0, 12.0, 15.0]), np.zeros(0, np.float32), [])]).closed
    12.0
    """
    minima = np.concatenate([p.minima for p in parts]) if parts else np.zeros(0)
    frames = np.concatenate([p.original for p in parts]).astype(np.float64) if parts else np.zeros(0)
    frames = frames[np.isfinite(frames)]
    if minima.size:
        return TalkerClosed(float(np.median(minima)), int(minima.size), int(frames.size))
    closed = float(np.percentile(frames, LOWEST_PERCENTILE)) if frames.size else float("nan")
    return TalkerClosed(closed, 0, int(frames.size))


@dataclass(frozen=True)
class ClosureAgreement:
    """Frames where the talker's lips are closed (``talker``), where the synthesized lips are
    (``synthesized``), and where both are (``both``)."""

    talker: int
    synthesized: int
    both: int

    @property
    def precision(self) -> float:
        """The share of the synthesized closed frames where the talker's lips are closed."""
        return self.both / self.synthesized if self.synthesized else float("nan")

    @property
    def recall(self) -> float:
        """The share of the talker's closed frames where the synthesized lips are closed."""
        return self.both / self.talker if self.talker else float("nan")

    def to_json(self) -> dict:
        return {"closed_frames": self.talker, "synthesized_closed_frames": self.synthesized,
                "both_closed_frames": self.both, "closure_precision": self.precision,
                "closure_recall": self.recall}

    @classmethod
    def pooled(cls, parts: Sequence[ClosureAgreement]) -> ClosureAgreement:
        return cls(sum(p.talker for p in parts), sum(p.synthesized for p in parts),
                   sum(p.both for p in parts))


def closure_agreement(original: np.ndarray, synthesized: np.ndarray, closed: float,
                      tol: float = CLOSED_TOL_MM) -> ClosureAgreement:
    """Closed frames of the talker's ``original`` apertures and the ``synthesized`` ones (the
    same frames), against the talker's ``closed`` value.

    >>> o = np.array([11.0, 11.5, 15.0, 18.0, 11.2]); s = np.array([11.1, 14.0, 11.9, 18.0, 11.0])
    >>> a = closure_agreement(o, s, 11.0)
    >>> (a.talker, a.synthesized, a.both, a.precision, round(a.recall, 3))
    (3, 3, 2, 0.6666666666666666, 0.667)
    """
    t = np.asarray(original, dtype=np.float64) <= closed + tol
    s = np.asarray(synthesized, dtype=np.float64) <= closed + tol
    return ClosureAgreement(int(t.sum()), int(s.sum()), int((t & s).sum()))


def agreements(parts: Sequence[TalkerLips], talker: TalkerClosed | None = None
               ) -> list[list[ClosureAgreement]]:
    """Per utterance of ``parts``, per synthesized face, its :class:`ClosureAgreement` with the
    talker's closed frames (``talker``: the value, else :func:`talker_closed` of ``parts``)."""
    talker = talker or talker_closed(parts)
    return [[closure_agreement(p.original, s, talker.closed) for s in p.synthesized] for p in parts]
