"""The audio-visual codebook (paper section 2.1, Figure 3): per phone token, one context-phone and
5 codewords at uniformly spaced times, each holding an LSF vector L_i and a PC vector F_i.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .heap import give_back


def codeword_times(start: np.ndarray, end: np.ndarray, n: int = 5,
                   placement: str = "centres") -> np.ndarray:
    """Uniformly spaced codeword times across each phone, ``(tokens, n)``.

    ``centres``: the centres of ``n`` equal parts, ``start + (k + 1/2) (end - start) / n``;
    ``edges``: ``start + k (end - start) / (n - 1)``, first and last on the boundaries.

    Examples
    --------
    >>> codeword_times(np.array([0.0]), np.array([1.0]), 5).round(2).tolist()
    [[0.1, 0.3, 0.5, 0.7, 0.9]]
    >>> codeword_times(np.array([0.0]), np.array([1.0]), 5, "edges").round(2).tolist()
    [[0.0, 0.25, 0.5, 0.75, 1.0]]
    """
    start = np.asarray(start, dtype=np.float64)[:, None]
    dur = np.asarray(end, dtype=np.float64)[:, None] - start
    k = np.arange(n)[None, :]
    if placement == "centres":
        return start + (k + 0.5) * dur / n
    if placement == "edges":
        return start + k * dur / max(n - 1, 1)
    raise ValueError(f"unknown codeword placement {placement!r} (centres or edges)")


def interpolate_frames(values: np.ndarray, rate: float, times: np.ndarray) -> np.ndarray:
    """Linear interpolation of frame-rate vectors ``(T, K)`` (frame t at ``t / rate``) at ``times``.

    NaN frames propagate to the times that touch them.
    """
    pos = np.clip(np.asarray(times) * rate, 0, values.shape[0] - 1)
    lo = np.floor(pos).astype(int)
    hi = np.minimum(lo + 1, values.shape[0] - 1)
    frac = (pos - lo)[..., None]
    return values[lo] * (1 - frac) + values[hi] * frac


@dataclass
class Codebook:
    """The audio-visual codebook.

    Attributes
    ----------
    contexts : ``(L, 2C+1)`` phone ids of each context-phone ``[l_C .. l_1, c, r_1 .. r_C]``.
    lsf : ``(L * n, P)`` codeword LSF vectors L_i.
    pcs : ``(L * n, K)`` codeword PC vectors F_i.
    token_utt : ``(L,)`` index of the training utterance each token comes from.
    token_start, token_end : ``(L,)`` phone boundaries in seconds.
    n_per_phone : codewords per context-phone (5); codeword ``i`` belongs to context ``i // n``.
    lsf_context : ``(L * n, 2, P)`` each codeword's LSF vectors ``TrainConfig.lsf_context_frames``
        marker frames before and after it (the robust mode's acoustic context), or ``None``
        (older models, or no context trained).
    """

    contexts: np.ndarray
    lsf: np.ndarray
    pcs: np.ndarray
    token_utt: np.ndarray
    token_start: np.ndarray
    token_end: np.ndarray
    n_per_phone: int = 5
    lsf_context: np.ndarray | None = None

    @property
    def n_contexts(self) -> int:
        return int(self.contexts.shape[0])

    @property
    def centre(self) -> np.ndarray:
        """Centre phone id of each context-phone."""
        return self.contexts[:, self.contexts.shape[1] // 2]

    def codewords_of(self, contexts: np.ndarray) -> np.ndarray:
        """Codebook indices of the codewords of the given context-phones, ``(..., n * count)``."""
        contexts = np.asarray(contexts)
        idx = contexts[..., :, None] * self.n_per_phone + np.arange(self.n_per_phone)
        return idx.reshape(*contexts.shape[:-1], -1)

    def codeword_phone(self) -> np.ndarray:
        """Centre phone id of every codeword, ``(L * n,)``."""
        return np.repeat(self.centre, self.n_per_phone)


def concatenate(parts: list[Codebook]) -> Codebook:
    """Join codebooks built per utterance, consuming them: the parts' arrays are let go field by
    field as they are joined (training's parts: the peak is the joined codebook and one field of
    the parts, not the codebook twice); the parts are left without their arrays."""
    if not parts:
        raise ValueError("no codebook entries: the training data has no usable phone tokens")
    joined: dict[str, np.ndarray | None] = {}
    for name in ("contexts", "lsf", "pcs", "token_utt", "token_start", "token_end",
                 "lsf_context"):
        arrays = [getattr(p, name) for p in parts]
        for part in parts:
            setattr(part, name, None)
        joined[name] = (np.concatenate(arrays) if all(a is not None for a in arrays)
                        else None)
        del arrays
        give_back()                                # the parts' small arrays, freed
    return Codebook(**joined, n_per_phone=parts[0].n_per_phone)
