"""How close automatic phone labels are to reference labels: boundary error and phone error rate.

The paper's phonetic mode used aligner labels (section 3); these measures say how much such labels
differ from hand-checked or exact ones:

- the two phone sequences are matched by a minimum edit-distance alignment (substitution,
  insertion, deletion cost 1; silence merged and kept, since its edges are boundaries too);
- a **boundary** is the start of a reference phone (not the first) matched to a hypothesis phone
  whose predecessor is matched to the reference predecessor; its error is the difference of the
  two start times;
- the **phone error rate** is the edit distance between the non-silence phone sequences divided
  by the reference's phone count (substitutions + deletions + insertions) / N.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from ..data import PhoneSegment
from ..labels.phoneset import SILENCE, apply_label_map

#: A boundary "agrees" when within this many seconds (the usual 20 ms tolerance).
TOLERANCE_S = 0.020


def merged(phones: Sequence[PhoneSegment], label_map: Mapping[str, str] | None = None
           ) -> list[PhoneSegment]:
    """Labels mapped onto ARPAbet (``label_map``, e.g. MOCHA's) with adjacent silences merged.

    >>> [s.label for s in merged([PhoneSegment(0, 1, "sil"), PhoneSegment(1, 2, "breath"),
    ...                           PhoneSegment(2, 3, "@")], {"@": "ah", "breath": "sil"})]
    ['sil', 'ah']
    """
    out: list[PhoneSegment] = []
    for s in phones:
        lab = apply_label_map(s.label, label_map)
        if out and lab == SILENCE and out[-1].label == SILENCE:
            out[-1] = PhoneSegment(out[-1].start, s.end, SILENCE)
        else:
            out.append(PhoneSegment(s.start, s.end, lab))
    return out


def edit_alignment(ref: Sequence[str], hyp: Sequence[str]) -> tuple[int, list[tuple[int, int]]]:
    """Minimum edit distance of two label sequences and the matched pairs ``(i, j)``
    (equal or substituted labels), in order.

    >>> edit_alignment("abcd", "abd")
    (1, [(0, 0), (1, 1), (3, 2)])
    >>> edit_alignment("ab", "xb")[0]
    1
    """
    n, m = len(ref), len(hyp)
    d = np.zeros((n + 1, m + 1), dtype=int)
    d[:, 0] = np.arange(n + 1)
    d[0, :] = np.arange(m + 1)
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            d[i, j] = min(d[i - 1, j] + 1, d[i, j - 1] + 1,
                          d[i - 1, j - 1] + (ref[i - 1] != hyp[j - 1]))
    pairs: list[tuple[int, int]] = []
    i, j = n, m
    while i > 0 and j > 0:
        if d[i, j] == d[i - 1, j - 1] + (ref[i - 1] != hyp[j - 1]):
            pairs.append((i - 1, j - 1))
            i, j = i - 1, j - 1
        elif d[i, j] == d[i - 1, j] + 1:
            i -= 1
        else:
            j -= 1
    return int(d[n, m]), pairs[::-1]


def boundary_errors(reference: Sequence[PhoneSegment], hypothesis: Sequence[PhoneSegment]
                    ) -> np.ndarray:
    """Signed errors (hypothesis - reference, seconds) of the matched phone boundaries.

    Labels are compared as given (map and merge them first with :func:`merged`).

    >>> ref = [PhoneSegment(0, .2, "sil"), PhoneSegment(.2, .3, "b"), PhoneSegment(.3, .5, "iy")]
    >>> hyp = [PhoneSegment(0, .21, "sil"), PhoneSegment(.21, .33, "b"), PhoneSegment(.33, .5, "iy")]
    >>> boundary_errors(ref, hyp).round(3).tolist()
    [0.01, 0.03]
    """
    _, pairs = edit_alignment([s.label for s in reference], [s.label for s in hypothesis])
    errors = [hypothesis[j].start - reference[i].start
              for (pi, pj), (i, j) in pairwise(pairs)
              if i == pi + 1 and j == pj + 1]
    return np.array(errors, dtype=float)


def phone_error_rate(reference: Sequence[PhoneSegment], hypothesis: Sequence[PhoneSegment]
                     ) -> tuple[int, int]:
    """Edit distance between the non-silence phone sequences, and the reference's phone count.

    >>> ref = [PhoneSegment(0, 1, "sil"), PhoneSegment(1, 2, "b"), PhoneSegment(2, 3, "iy")]
    >>> phone_error_rate(ref, [PhoneSegment(0, 2, "p"), PhoneSegment(2, 3, "iy")])
    (1, 2)
    """
    r = [s.label for s in reference if s.label != SILENCE]
    h = [s.label for s in hypothesis if s.label != SILENCE]
    return edit_alignment(r, h)[0], len(r)


@dataclass
class LabelAccuracy:
    """Accuracy of one labelling method over a set of utterances.

    ``median_error_ms``: median absolute boundary error; ``within_20ms``: share of boundaries
    within :data:`TOLERANCE_S`; ``per``: phone error rate (edits / reference phones).
    """

    method: str
    utterances: int
    boundaries: int
    median_error_ms: float
    within_20ms: float
    per: float

    def to_json(self) -> dict:
        return dict(self.__dict__)


def summarise(method: str, pairs: Iterable[tuple[Sequence[PhoneSegment], Sequence[PhoneSegment]]],
              label_map: Mapping[str, str] | None = None) -> LabelAccuracy:
    """:class:`LabelAccuracy` of ``(reference, hypothesis)`` label pairs (``label_map`` maps the
    reference labels onto ARPAbet)."""
    errors: list[np.ndarray] = []
    edits = total = n = 0
    for ref, hyp in pairs:
        ref_m, hyp_m = merged(ref, label_map), merged(hyp)
        errors.append(boundary_errors(ref_m, hyp_m))
        e, t = phone_error_rate(ref_m, hyp_m)
        edits, total, n = edits + e, total + t, n + 1
    err = np.abs(np.concatenate(errors)) if errors else np.zeros(0)
    return LabelAccuracy(method, n, int(err.size),
                         float(np.median(err) * 1000) if err.size else float("nan"),
                         float(np.mean(err <= TOLERANCE_S + 1e-9)) if err.size else float("nan"),
                         edits / total if total else float("nan"))
