"""The talker's closed lips: where the lip markers are when the lips meet, from the model.

The markers sit on the outside of the lips, so even with the lips pressed together the upper and
lower lip markers are apart by the lips' thickness (about 11 mm on the default corpus at the /b/
of "boy"). :func:`closed_lips` takes the face at the middle of every /p b m/ codeword of the
codebook (paper section 2.1: one codeword at each phone's centre), i.e. the training talker's
bilabial closures, and their median: the lip markers' positions and the distance between each
upper and lower lip marker at closure. The 3-D view closes the mouth where a pair is that close
(``app/surface.py``), and the lip panels draw the closed positions as a reference.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..method.model import Model

#: The phones whose middle is a lip closure.
BILABIALS = ("p", "b", "m")
#: Without enough bilabial codewords: the codewords with the smallest lip gap, this share of them.
CLOSEST_SHARE = 0.02


@dataclass(frozen=True)
class ClosedLips:
    """The lips at closure.

    ``markers``: ``(M, 3)`` median marker positions (model head frame, mm) over ``tokens``
    closures; ``how``: ``"bilabials"`` (the middles of /p b m/ codewords) or ``"closest"`` (the
    codewords whose upper and lower lip centres are closest, when the model has too few
    bilabials)."""

    markers: np.ndarray
    tokens: int
    how: str

    def gap(self, upper: Sequence[int] | int, lower: Sequence[int] | int) -> np.ndarray:
        """Distance (mm) between upper and lower lip markers at closure, pair by pair."""
        return np.linalg.norm(self.markers[np.asarray(upper)] - self.markers[np.asarray(lower)],
                              axis=-1)


def closed_lips(model: Model, phones: Sequence[str] = BILABIALS, min_tokens: int = 3) -> ClosedLips:
    """The talker's lips at closure (see the module docstring).

    >>> from types import SimpleNamespace
    >>> faces = {"p": [[0, 5, 0], [0, -5, 0]], "a": [[0, 9, 0], [0, -9, 0]]}
    >>> class Toy(SimpleNamespace):
    ...     def to_markers(self, pcs):
    ...         return np.array([faces["pa"[int(i)]] for i in pcs[:, 0]], dtype=float)
    >>> cb = SimpleNamespace(n_per_phone=1, centre=np.array([0, 0, 0, 1]),
    ...                      pcs=np.array([[0], [0], [0], [1]], dtype=float))
    >>> toy = Toy(phones=["p", "a"], codebook=cb, upper_lip=0, lower_lip=1)
    >>> lips = closed_lips(toy)
    >>> lips.how, lips.tokens, float(lips.gap(0, 1))
    ('bilabials', 3, 10.0)
    """
    cb = model.codebook
    n = cb.n_per_phone
    wanted = [i for i, p in enumerate(model.phones) if p in phones]
    contexts = np.flatnonzero(np.isin(cb.centre, wanted))
    if len(contexts) >= min_tokens:
        faces = model.to_markers(cb.pcs[contexts * n + n // 2])
        return ClosedLips(np.median(faces, axis=0), len(contexts), "bilabials")
    faces = model.to_markers(cb.pcs)
    gap = np.linalg.norm(faces[:, model.upper_lip] - faces[:, model.lower_lip], axis=-1)
    closest = np.argsort(gap)[:max(min_tokens, int(np.ceil(CLOSEST_SHARE * len(gap))))]
    return ClosedLips(np.median(faces[closest], axis=0), len(closest), "closest")
