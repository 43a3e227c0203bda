"""Context-phones (paper section 2.1, Figure 3): each phone with C phones of context each side,
and which phone segment holds each frame."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..data import PhoneSegment


def context_ids(ids: Sequence[int], context: int, pad: int) -> np.ndarray:
    """Context-phones of a phone sequence: ``(n, 2C + 1)`` ids ``[l_C .. l_1, c, r_1 .. r_C]``.

    Positions beyond the utterance are ``pad`` (the silence id).

    Examples
    --------
    >>> context_ids([5, 6, 7], context=1, pad=0).tolist()
    [[0, 5, 6], [5, 6, 7], [6, 7, 0]]
    """
    ids = np.asarray(ids, dtype=np.int64)
    padded = np.concatenate([np.full(context, pad), ids, np.full(context, pad)])
    n = len(ids)
    return np.stack([padded[i:i + n] for i in range(2 * context + 1)], axis=1)


def segment_index(phones: Sequence[PhoneSegment], times: np.ndarray) -> np.ndarray:
    """Index of the segment holding each time (times beyond the ends go to the first/last)."""
    ends = np.array([s.end for s in phones])
    # np.minimum, not np.clip: the indices are >= 0 already, and clip's checks cost more than
    # the search on a second of frames
    return np.minimum(np.searchsorted(ends, np.asarray(times), side="right"), len(phones) - 1)
