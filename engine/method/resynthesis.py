"""One recording synthesized again and again as its labels change (a phonetician correcting them,
issue 56): :class:`SynthesisMemo` keeps what the synthesis of the recording computed that the
next label set does not change, so that :func:`facetraj_engine.method.pipeline.synthesize` with
``memo=`` redoes only the rest:

- the work on the audio alone: its LSFs (``_input``), its speech energy, its voice match, and
  the LSF index's acoustically nearest codewords of each frame (the robust mode's candidates);
- the robust mode's eqs 5-8 per frame: only the frames whose candidates (eq 4's, which follow
  the labels and their context) or label confidence changed are weighted again;
- the chain over frames (:mod:`facetraj_engine.method.chain`): its join terms only between
  changed frames, its messages only until they are the previous ones to the bit.

Each part is computed as without the memo, so the result is the same to the bit
(tests/test_resynthesis.py); a memo is for one recording, model and setting: given another, it
starts again. Syntheses with one memo run one at a time (its lock).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np


@dataclass
class SynthesisMemo:
    """What the synthesis of one recording keeps for the next label set (see the module).
    ``searched``: the frames the last synthesis weighted again (eqs 5-8), for the benchmark."""

    lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    bound: tuple = ()
    values: dict = field(default_factory=dict)
    robust: Any = None                  # the robust mode's frames and what they were made of
    chain: Any = None                   # the chain's state (join terms, messages)
    searched: int = -1

    def bind(self, model, audio: np.ndarray, sample_rate: int, n_frames: int | None,
             config) -> None:
        """Use the memo for this input; another one (model, audio, rate, frames or settings)
        empties it."""
        now = (model, audio, int(sample_rate), n_frames, config)
        if len(self.bound) != 5 or not (self.bound[0] is model and self.bound[1] is audio
                                        and self.bound[2:] == now[2:]):
            self.bound, self.values, self.robust, self.chain = now, {}, None, None

    def forget(self) -> None:
        """Keep nothing (a synthesis failed half-way: what is kept may be of two label sets)."""
        self.bound, self.values, self.robust, self.chain = (), {}, None, None

    def remember(self, key, compute: Callable[[], Any]) -> Any:
        """``compute()``'s value, computed once for this input."""
        if key not in self.values:
            self.values[key] = compute()
        return self.values[key]


@dataclass
class _RobustKept:
    """The robust mode's frames as last weighted, and their inputs."""

    candidates: np.ndarray
    confidence: np.ndarray
    kappa: float
    frames: Any


def robust_frames_again(memo: SynthesisMemo, candidates: np.ndarray, confidence: np.ndarray,
                        kappa: float, weigh: Callable[[np.ndarray], Any]) -> Any:
    """The robust mode's frames (:func:`~facetraj_engine.method.selection.robust_frames`) for
    eq 4's ``candidates`` and the frames' label ``confidence``: ``weigh(rows)`` weights the
    frames ``rows`` (all of them the first time, then those whose candidates or confidence
    changed) and their results replace those rows of the frames kept."""
    kept = memo.robust
    conf = np.asarray(confidence, dtype=np.float64)
    if kept is None or kept.kappa != kappa or kept.candidates.shape != candidates.shape:
        rows = np.arange(len(candidates))
        frames = weigh(rows)
    else:
        rows = np.flatnonzero(np.any(kept.candidates != candidates, axis=1) |
                              (kept.confidence != conf))
        frames = _copy(kept.frames)
        if rows.size:
            part = weigh(rows)
            for f in fields(frames):
                value = getattr(part, f.name)
                if isinstance(value, np.ndarray):
                    getattr(frames, f.name)[rows] = value
    memo.searched = int(rows.size)
    memo.robust = _RobustKept(np.array(candidates), conf.copy(), kappa, _copy(frames))
    return frames


def _copy(frames: Any) -> Any:
    """A copy of a dataclass of arrays (the frames kept are never the ones handed out)."""
    return type(frames)(**{f.name: (np.array(getattr(frames, f.name))
                                    if isinstance(getattr(frames, f.name), np.ndarray)
                                    else getattr(frames, f.name)) for f in fields(frames)})


def join_terms_again(memo: SynthesisMemo, candidates: np.ndarray,
                     compute: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray | None]:
    """The chain's join terms (:func:`~facetraj_engine.method.chain.join_log_potentials`):
    ``compute(pairs)`` for the frame pairs ``t, t+1`` (``pairs``: the ``t``) whose candidates
    changed, the others as they were (the array kept is changed in place: one array of the
    terms, ``(T-1, I, I)``, however many edits); and those pairs (``None``: all computed anew)."""
    kept = memo.values.get("joins")
    if kept is None or kept[0].shape != candidates.shape:
        joins, pairs = compute(np.arange(max(len(candidates) - 1, 0))), None
    else:
        old_cand, joins = kept
        moved = np.any(old_cand != candidates, axis=1)
        pairs = np.flatnonzero(moved[:-1] | moved[1:])
        if pairs.size:
            joins[pairs] = compute(pairs)
    memo.values["joins"] = (np.array(candidates), joins)
    return joins, pairs


def chained_pcs(memo: SynthesisMemo, weights: np.ndarray, candidates: np.ndarray,
                cb_pcs: np.ndarray, beta: float, scale: float) -> np.ndarray:
    """:func:`~facetraj_engine.method.chain.chain_pcs` with the join terms and the chain's
    messages of the last label set reused where they are unchanged."""
    from .chain import chain_pcs, joins_between

    joins, changed = join_terms_again(memo, candidates, lambda t: joins_between(
        cb_pcs[candidates[t]], cb_pcs[candidates[t + 1]], beta, scale)) if beta else (None, None)
    previous = memo.chain if changed is not None else None    # terms all new: summed anew
    keep: list = []
    pcs = chain_pcs(weights, candidates, cb_pcs, beta, scale, previous, keep, joins, changed)
    memo.chain = keep[0] if keep else None
    return pcs


__all__ = ["SynthesisMemo", "chained_pcs", "join_terms_again", "robust_frames_again"]
