"""Live mode against offline synthesis of the same recordings (issue 27): where they differ, and
by how much.

Offline, ``facetraj synth speech.wav`` recognizes the phones of the whole recording (batch
cepstral mean, the phone sequence re-aligned), synthesizes in the robust mode with the voice
ratio of the whole recording and applies the closure step with every frame known. Live mode
(``facetraj live --from-file``) has the audio up to each frame's time plus its lookahead. The
comparison takes both through the measure of :mod:`facetraj_engine.evaluation.closure` against the
reference phones (the transcripts aligned), and compares them directly: the lip aperture frame by
frame, the recognized phones 10 ms frame by 10 ms frame, and which reference /p b m/ each
recognizer found (a recognized /p b m/ overlapping it).

The streamed recognizer's cold start is measured apart from synthesis: :func:`phone_agreement`
(its phones against offline recognition's, on any recordings) and :func:`prior_count_errors`
(how near its running cepstral mean comes to the whole utterance's mean, for each count of the
prior, on recordings the choice is made on).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config import SynthConfig
from ..data import PhoneSegment
from ..labels.alignment import recognize
from ..method.closure import BILABIALS
from ..method.model import Model
from ..method.modes import choose_mode
from ..method.pipeline import synthesize
from ..streaming.live import LiveConfig, stream_file
from ..streaming.recognizer import CMN_INIT, RecognizerConfig, RunningCmn, StreamingRecognizer
from .closure import ClosureScore, closure_score, lip_aperture

#: The frame of the phone comparison (PocketSphinx's).
FRAME_S = 0.01


@dataclass(frozen=True)
class LiveComparison:
    """Offline and live on the same recordings: each one's closure score, the RMS and the
    correlation of their lip apertures over all frames (mm), the share of the offline recognizer's
    speech frames the live recognizer labels alike, and how many reference /p b m/ each
    recognizer found (of ``n``)."""

    offline: ClosureScore
    live: ClosureScore
    aperture_rms_mm: float
    aperture_corr: float
    phones_alike: float
    found_offline: int
    found_live: int
    n: int


def frame_labels(phones: Sequence[PhoneSegment], n: int) -> np.ndarray:
    """The label of each 10 ms frame (its centre's phone; ``sil`` beyond the phones).

    >>> frame_labels([PhoneSegment(0, .02, "sil"), PhoneSegment(.02, .05, "b")], 6).tolist()
    ['sil', 'sil', 'b', 'b', 'b', 'sil']
    """
    out = np.full(n, "sil", dtype=object)
    centres = (np.arange(n) + 0.5) * FRAME_S
    for p in phones:
        out[(centres >= p.start) & (centres < p.end)] = p.label
    return out


def found_bilabials(reference: Sequence[PhoneSegment], phones: Sequence[PhoneSegment]) -> int:
    """How many reference /p b m/ a /p b m/ of ``phones`` overlaps.

    >>> ref = [PhoneSegment(0.1, 0.2, "b"), PhoneSegment(0.5, 0.6, "m")]
    >>> found_bilabials(ref, [PhoneSegment(0.15, 0.3, "p"), PhoneSegment(0.5, 0.6, "n")])
    1
    """
    bil = [p for p in phones if p.label in BILABIALS]
    return sum(any(b.start < r.end and b.end > r.start for b in bil)
               for r in reference if r.label in BILABIALS)


def compare_live_offline(model: Model, refs: Mapping[Path, tuple[np.ndarray, int,
                                                                 list[PhoneSegment]]],
                         config: LiveConfig | None = None, block_s: float = 0.01) -> LiveComparison:
    """Each recording of ``refs`` (audio, rate, reference phones) synthesized offline as
    ``facetraj synth`` does with nothing but the audio, and streamed as ``facetraj live
    --from-file`` does (``config``)."""
    scores: dict[str, list[ClosureScore]] = {"offline": [], "live": []}
    a_off, a_live, alike, speech = [], [], 0, 0
    found = {"offline": 0, "live": 0}
    closed = model.closure.closed
    for audio, rate, ref in refs.values():
        labels = recognize(audio, rate)
        cfg = choose_mode(SynthConfig(), labels.phones, labels.provenance, tuned=model.tuned).config
        res = synthesize(model, audio, rate, labels.phones, cfg, confidence=labels.trust(),
                         provenance=labels.provenance)
        take = stream_file(model, audio, rate, block_s, config=config)
        aperture = {"offline": lip_aperture(res.markers, model.upper_lip, model.lower_lip),
                    "live": lip_aperture(take.frames.markers, model.upper_lip, model.lower_lip)}
        for name, phones in (("offline", labels.phones), ("live", take.labels.phones)):
            scores[name].append(closure_score(aperture[name], res.times, ref, closed))
            found[name] += found_bilabials(ref, phones)
        a_off.append(aperture["offline"])
        a_live.append(aperture["live"])
        n = int(np.ceil(len(audio) / rate / FRAME_S))
        off, live = frame_labels(labels.phones, n), frame_labels(take.labels.phones, n)
        alike += int(((off == live) & (off != "sil")).sum())
        speech += int((off != "sil").sum())
    x, y = np.concatenate(a_off), np.concatenate(a_live)
    n_ref = sum(r.label in BILABIALS for _, _, phones in refs.values() for r in phones)
    return LiveComparison(ClosureScore.pooled(scores["offline"]), ClosureScore.pooled(scores["live"]),
                          float(np.sqrt(np.mean((x - y) ** 2))), float(np.corrcoef(x, y)[0, 1]),
                          alike / max(speech, 1), found["offline"], found["live"], n_ref)


# --------------------------------------------------------------------------- the recognizer alone
def streamed_phones(audio: np.ndarray, rate: int, config: RecognizerConfig | None = None,
                    block_s: float = 0.01) -> list[PhoneSegment]:
    """The phones a fresh :class:`StreamingRecognizer` settles on ``audio`` fed in blocks."""
    rec = StreamingRecognizer(rate, config)
    block = max(1, int(round(block_s * rate)))
    for a in range(0, len(audio), block):
        rec.feed(audio[a:a + block])
    rec.flush()
    return rec.track.snapshot().segments


def phone_agreement(recordings: Mapping[str, tuple[np.ndarray, int]],
                    config: RecognizerConfig | None = None,
                    offline: Mapping[str, Sequence[PhoneSegment]] | None = None) -> float:
    """The share of offline recognition's speech frames (10 ms, not ``sil``) that the streamed
    recognizer (``config``, each recording a fresh stream in 10 ms blocks) labels alike, pooled
    over ``recordings`` (name: audio, rate); ``offline`` gives recognition's phones when already
    known (:func:`facetraj_engine.labels.alignment.recognize` otherwise)."""
    alike = speech = 0
    for name, (audio, rate) in recordings.items():
        ref = offline[name] if offline is not None else recognize(audio, rate).phones
        n = int(np.ceil(len(audio) / rate / FRAME_S))
        off, live = frame_labels(ref, n), frame_labels(streamed_phones(audio, rate, config), n)
        alike += int(((off == live) & (off != "sil")).sum())
        speech += int((off != "sil").sum())
    return alike / max(speech, 1)


class _BlockLog(RunningCmn):
    """A running mean that keeps the blocks it was given (their sums and frame counts)."""

    def __init__(self) -> None:
        super().__init__()
        self.blocks: list[tuple[np.ndarray, int]] = []

    def add(self, total: np.ndarray, frames: int) -> np.ndarray:
        if frames > 0:
            self.blocks.append((np.asarray(total, dtype=np.float64).copy(), int(frames)))
        return super().add(total, frames)


def frame_cepstra(audio: np.ndarray, rate: int) -> np.ndarray:
    """The 13 cepstra of each 10 ms frame the streamed recognizer decodes from ``audio``
    (frames x 13): its running mean set after every frame, each frame's cepstra recovered from
    the mean PocketSphinx reports (:func:`facetraj_engine.streaming.recognizer.held_sum`)."""
    log = _BlockLog()
    rec = StreamingRecognizer(rate, RecognizerConfig(cmn_every=1), cmn=log)
    step = max(1, int(round(FRAME_S * rate)))
    for a in range(0, len(audio), step):
        rec.feed(audio[a:a + step])
    rows = [np.tile(total / n, (n, 1)) for total, n in log.blocks]
    return np.vstack(rows) if rows else np.zeros((0, len(CMN_INIT)))


def prior_count_errors(cepstra: Sequence[np.ndarray], counts: Sequence[float],
                       init: np.ndarray = CMN_INIT, speech_share: float | None = 0.78,
                       every: int = 5) -> dict[float, float]:
    """For each prior count, the mean over every ``every``-frame block of every recording of the
    squared distance (13 coefficients summed) between :class:`RunningCmn`'s mean after the block
    (``init`` counting as that many frames) and the recording's whole mean (the mean offline
    recognition removes). ``cepstra``: each recording's frames x 13.

    >>> c = [np.vstack([np.full((20, 1), 30.0), np.full((80, 1), 60.0)])]
    >>> e = prior_count_errors(c, [0, 1000], init=np.array([54.0]), speech_share=None)
    >>> e[0] > e[1000]             # a prior at the whole mean beats the early frames
    True
    """
    errors = dict.fromkeys(counts, 0.0)
    blocks = 0
    for c in cepstra:
        c = np.asarray(c, dtype=np.float64)
        whole = c.mean(axis=0)
        for count in counts:
            cmn = RunningCmn(init, prior_frames=count, speech_share=speech_share)
            for a in range(0, len(c), every):
                mean = cmn.add(c[a:a + every].sum(axis=0), len(c[a:a + every]))
                errors[count] += float(((mean - whole) ** 2).sum())
        blocks += -(-len(c) // every)
    return {k: v / max(blocks, 1) for k, v in errors.items()}
