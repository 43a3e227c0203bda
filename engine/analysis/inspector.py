"""The codebook inspector's numbers: everything eqs 4-8 did at one synthesized frame (the chosen
context-phones with n_j, the 5N candidate codewords with d_i and v_i, gamma, w against w-hat)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..method.model import Model
from ..method.pipeline import Synthesis
from ..method.selection import RobustFrames
from ..method.synthesis import lsf_distances, perceptual_weights


@dataclass
class CodewordRow:
    """One of the 5N candidate codewords of a frame."""

    index: int              # codebook codeword index i
    context_index: int      # its context-phone (codebook row)
    context: str            # the context-phone as text, e.g. "sil m [aa] t"
    position: int           # which of the 5 codewords of the phone (0-4)
    utterance: str          # training utterance it came from
    time: float             # its time in that utterance (s)
    distance: float         # d_i (eq 5)
    weight: float           # v_i (eq 6)
    target_cost: float = float("nan")   # robust mode: eq 5 with acoustic context (facetraj_engine.method.selection)
    label_cost: float = float("nan")    # robust mode: kappa * confidence if eq 4 did not choose it
    from_labels: bool = True            # chosen by eq 4 (always, in phonetic mode)


@dataclass
class FrameInspection:
    """Why one synthesized frame looks as it does (eqs 4-8)."""

    frame: int
    time: float
    phone: str
    context: str
    chosen: list[tuple[str, float, int]]   # (context-phone text, n_j, codebook context index)
    codewords: list[CodewordRow]
    gamma: float
    lsf: np.ndarray          # w (P,)
    lsf_hat: np.ndarray      # w-hat (P,)
    error: float             # sum_k h_k |w_k - w-hat_k|
    audio_rate: float = 16000.0
    mode: str = "phonetic"
    confidence: float = float("nan")   # robust mode: the frame's label confidence

    @property
    def lsf_hz(self) -> np.ndarray:
        """w in Hz (LSFs are angles in radians at the analysis rate)."""
        return self.lsf * self.audio_rate / (2 * np.pi)

    @property
    def lsf_hat_hz(self) -> np.ndarray:
        """w-hat in Hz."""
        return self.lsf_hat * self.audio_rate / (2 * np.pi)

    @property
    def weight_sum(self) -> float:
        return float(sum(c.weight for c in self.codewords))


def context_text(model: Model, ids: Sequence[int]) -> str:
    """A context-phone as text with the centre bracketed: ``l3 l2 l1 [c] r1 r2 r3``."""
    labels = [model.phones[int(i)] for i in ids]
    c = len(labels) // 2
    labels[c] = f"[{labels[c]}]"
    return " ".join(labels)


def inspect_frame(model: Model, synthesis: Synthesis, frame: int, top: int | None = None) -> FrameInspection:
    """The eq 4-8 details of ``frame`` of ``synthesis``: the current phone and context-phone, the
    chosen context-phones with n_j, the candidate codewords with d_i and v_i (heaviest first;
    ``top`` limits them), gamma, and w against w-hat."""
    frame = int(np.clip(frame, 0, len(synthesis.times) - 1))
    fw = synthesis.frames
    cb = model.codebook
    phone, ctx_txt, chosen = "", "", []
    if synthesis.frame_segment is not None and synthesis.segments:
        sc = synthesis.segments[int(synthesis.frame_segment[frame])]
        phone = sc.segment.label
        ctx_txt = context_text(model, sc.context)
        chosen = [(context_text(model, cb.contexts[j]), float(s), int(j))
                  for j, s in zip(sc.chosen, sc.scores, strict=True)]
    cand = np.asarray(fw.candidates[frame])
    robust = isinstance(fw, RobustFrames)
    w = synthesis.lsf[frame]
    d = lsf_distances(w, cb.lsf[cand], perceptual_weights(w))
    v = fw.weights[frame]
    order = np.argsort(-v, kind="stable")
    if top is not None:
        order = order[:top]
    n = cb.n_per_phone
    rows = []
    if robust:
        order = np.array([i for i in order if np.isfinite(fw.acoustic_cost[frame, i])], dtype=int)
    for i in order:
        ci = int(cand[i])
        ctx = ci // n
        utt_k = int(cb.token_utt[ctx])
        utt = model.train_utterances[utt_k] if utt_k < len(model.train_utterances) else str(utt_k)
        pos = ci % n
        start, end = float(cb.token_start[ctx]), float(cb.token_end[ctx])
        extra = (float(fw.acoustic_cost[frame, i]), float(fw.label_cost[frame, i]),
                 bool(fw.from_labels[frame, i])) if robust else ()
        rows.append(CodewordRow(ci, ctx, context_text(model, cb.contexts[ctx]), pos, utt,
                                start + (pos + 0.5) * (end - start) / n, float(d[i]), float(v[i]),
                                *extra))
    return FrameInspection(frame, float(synthesis.times[frame]), phone, ctx_txt, chosen, rows,
                           float(fw.gamma[frame]), np.asarray(w), np.asarray(fw.lsf_hat[frame]),
                           float(fw.error[frame]), float(model.config.audio_rate),
                           synthesis.config.mode,
                           float(fw.confidence[frame]) if robust else float("nan"))


__all__ = ["CodewordRow", "FrameInspection", "context_text", "inspect_frame"]
