"""The phones a streaming recognizer has settled (live mode, issue 27).

A phone recognizer that decodes as the audio arrives revises its recent past: the best path's
last phones change as more audio comes in (on the CMU ARCTIC samples, 61 % of the 10 ms frames
20 ms behind the decoder carry the label they end with, 89 % at 100 ms, all of them at 360 ms).
:class:`PhoneTrack` keeps what live synthesis may use: each partial hypothesis is *observed*,
and the frames older than the settle age are *frozen* with the label the latest hypothesis gives
them, never to change again (frames already on screen were made with it). A frozen phone's
**confidence** is its *stability*: over the partial hypotheses that covered its frames before
they froze, the share that gave them the label they froze with (1: never in doubt).

Frames are the recognizer's (10 ms); labels are ARPAbet lower case or ``sil``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..data import PhoneSegment
from ..labels.phoneset import SILENCE


@dataclass(frozen=True)
class PhoneSnapshot:
    """The settled phones at one moment: ``segments`` (seconds; the last one may still grow),
    their ``confidence`` and ``settled_s``, where the settled audio ends."""

    segments: list[PhoneSegment]
    confidence: np.ndarray
    settled_s: float


@dataclass
class FrozenPhone:
    """A settled phone: frames ``[start, end)``, its label, and the sums its stability comes
    from (``agree`` of ``seen`` observations of its frames gave it this label)."""

    start: int
    end: int
    label: str
    agree: int = 0
    seen: int = 0

    @property
    def confidence(self) -> float:
        """Its stability in (0, 1]; 1 for a phone no hypothesis saw before it froze (at the end
        of the stream, when the final hypothesis is the only one)."""
        return self.agree / self.seen if self.seen else 1.0


def stability(history: Sequence[str], final: str) -> tuple[int, int]:
    """``(agree, seen)``: how many of a frame's observed labels equal the one it froze with.

    >>> stability(["t", "d", "d"], "d")
    (2, 3)
    """
    return sum(1 for h in history if h == final), len(history)


class PhoneTrack:
    """Frozen phones from frame 0 to :attr:`frozen` (exclusive), and the observations of the
    frames after it.

    >>> track = PhoneTrack(frame_s=0.01)
    >>> track.observe(0, ["sil", "sil", "b", "b"])
    >>> track.observe(0, ["sil", "sil", "m", "m", "aa"])
    >>> track.freeze(4)
    >>> [(p.start, p.end, p.label, p.confidence) for p in track.phones]
    [(0, 2, 'sil', 1.0), (2, 4, 'm', 0.5)]
    >>> snap = track.snapshot()
    >>> snap.segments[1], snap.confidence.tolist(), snap.settled_s
    (PhoneSegment(start=0.02, end=0.04, label='m'), [1.0, 0.5], 0.04)
    """

    def __init__(self, frame_s: float = 0.01):
        self.frame_s = frame_s
        self.phones: list[FrozenPhone] = []
        self.frozen = 0                       # frames [0, frozen) are settled
        self._history: list[list[str]] = []   # per frame from `frozen` on, its observed labels
        self._latest: list[str] = []          # the latest hypothesis's labels from `frozen` on

    @property
    def settled_s(self) -> float:
        """Seconds of audio whose phones are settled."""
        return self.frozen * self.frame_s

    def observe(self, first: int, labels: Sequence[str]) -> None:
        """A partial hypothesis: ``labels`` of frames ``first, first + 1, ...`` (frames before
        :attr:`frozen` are settled and ignored)."""
        skip = max(0, self.frozen - first)
        labels = list(labels[skip:])
        start = first + skip - self.frozen
        if start > len(self._history):       # a gap (not expected): nothing seen there
            self._history += [[] for _ in range(start - len(self._history))]
            self._latest += [SILENCE] * (start - len(self._latest))
        need = start + len(labels)
        self._history += [[] for _ in range(need - len(self._history))]
        self._latest += [SILENCE] * (need - len(self._latest))
        for k, lab in enumerate(labels):
            self._history[start + k].append(lab)
            self._latest[start + k] = lab

    def freeze(self, until: int) -> None:
        """Settle the frames before ``until`` with the latest hypothesis's labels (frames it did
        not cover: silence)."""
        count = until - self.frozen
        if count <= 0:
            return
        for k in range(count):
            final = self._latest[k] if k < len(self._latest) else SILENCE
            agree, seen = stability(self._history[k] if k < len(self._history) else [], final)
            frame = self.frozen + k
            last = self.phones[-1] if self.phones else None
            if last is not None and last.label == final and last.end == frame:
                last.end, last.agree, last.seen = frame + 1, last.agree + agree, last.seen + seen
            else:
                self.phones.append(FrozenPhone(frame, frame + 1, final, agree, seen))
        self._history = self._history[count:]
        self._latest = self._latest[count:]
        self.frozen = until

    def observed_until(self) -> int:
        """The first frame no hypothesis has covered yet."""
        return self.frozen + len(self._latest)

    def snapshot(self, since_s: float = 0.0, before: int = 0) -> PhoneSnapshot:
        """The settled phones from the one holding ``since_s`` on, and ``before`` more before it
        (eq 4's left context)."""
        first = max(0, first_phone_after(self.phones, since_s / self.frame_s) - before)
        f = self.frame_s
        phones = self.phones[first:]
        return PhoneSnapshot([PhoneSegment(p.start * f, p.end * f, p.label) for p in phones],
                             np.array([p.confidence for p in phones], dtype=np.float64),
                             self.settled_s)


def first_phone_after(phones: Sequence[FrozenPhone], frame: float) -> int:
    """The index of the first phone ending after ``frame`` (binary search: phones are in order).

    >>> first_phone_after([FrozenPhone(0, 2, "sil"), FrozenPhone(2, 5, "b")], 2.0)
    1
    """
    lo, hi = 0, len(phones)
    while lo < hi:
        mid = (lo + hi) // 2
        if phones[mid].end <= frame:
            lo = mid + 1
        else:
            hi = mid
    return lo


class KnownPhones:
    """Phones known before the audio comes (labels found by the one rule for a file streamed,
    :func:`facetraj_engine.io.labelling.resolve_labels`): every one settled from the start, each
    with its confidence (1 for hand-checked labels) -- a :class:`PhoneTrack`'s place in a stream.

    >>> known = KnownPhones([PhoneSegment(0, .2, "sil"), PhoneSegment(.2, .3, "b")], np.ones(2))
    >>> [s.label for s in known.snapshot(0.25).segments], known.snapshot(0.25, 1).confidence.tolist()
    (['b'], [1.0, 1.0])
    """

    def __init__(self, phones: Sequence[PhoneSegment], confidence: np.ndarray):
        self.phones = list(phones)
        self.confidence = np.asarray(confidence, dtype=np.float64)
        #: settled to beyond the end (a second after the last phone, which reaches it)
        self.settled_s = (self.phones[-1].end if self.phones else 0.0) + 1.0
        self._ends = np.array([p.end for p in self.phones])

    def snapshot(self, since_s: float = 0.0, before: int = 0) -> PhoneSnapshot:
        """The phones from the one holding ``since_s`` on, and ``before`` more before it."""
        first = max(0, int(np.searchsorted(self._ends, since_s, side="right")) - before)
        return PhoneSnapshot(self.phones[first:], self.confidence[first:], self.settled_s)
