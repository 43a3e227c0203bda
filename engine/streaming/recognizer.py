"""Streaming phone recognition (live mode, issue 27): PocketSphinx's all-phone search fed as the
audio arrives, its partial hypotheses settled into phones with a confidence.

The search is offline recognition's (:func:`facetraj_engine.labels.alignment.allphone_decoder`, the same
settings), fed in 10 ms steps; every ``partial_every`` steps its partial hypothesis (the best
path's phone segments so far) is observed, and the frames ``settle_s`` behind the decoder's front
are frozen (:class:`facetraj_engine.streaming.phones.PhoneTrack`): the phones synthesis may use. The steps
are the same whatever the size of the blocks fed, so the phones are too.

Two things differ from offline recognition, both measured on the CMU ARCTIC samples:

* **Cepstral mean.** Offline, the whole utterance's cepstral mean is removed (``full_utt``).
  PocketSphinx's live mean stays at its initial value for the first 8 s (it is updated at the end
  of an utterance or after 800 frames), and that value (c0 = 40) is far from real recordings'
  (c0 = 54-60 on the ARCTIC samples). :class:`RunningCmn` estimates the mean from the frames so far
  and sets it every 5 frames, PocketSphinx's initial mean counting as :data:`CMN_PRIOR_FRAMES`
  frames (the count whose running mean is nearest the whole-utterance mean on PocketSphinx's own
  test recordings: :func:`facetraj_engine.evaluation.live_eval.prior_count_errors`).
* **Utterances.** The search's history grows with the utterance and each partial hypothesis is a
  back-trace over all of it, so the decoder starts a new utterance at the settled frame when the
  settled phones end in a pause (``restart_silence_s``) or the utterance reaches
  ``max_utterance_s``; the audio after the settled frame is decoded again in the new one.
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass

import numpy as np

from ..labels.alignment import ALIGN_RATE, FRAME_S, allphone_decoder, phone_label, pocketsphinx_version
from ..labels.phoneset import SILENCE
from ..method.lsf import ResampleStream
from .phones import PhoneTrack

log = logging.getLogger(__name__)

#: PocketSphinx's samples per frame (10 ms at 16 kHz).
FRAME_SAMPLES = int(round(FRAME_S * ALIGN_RATE))
#: PocketSphinx's live CMN: ``set_cmn`` holds the mean as this many frames' worth of sum
#: (``cmn.h``; its window decays back to it after 800 frames: the mean is set far more often).
CMN_WIN = 500
#: PocketSphinx's initial cepstral mean (its ``cmninit``, 13 coefficients).
CMN_INIT = np.array([40.0, 3.0, -1.0] + [0.0] * 10)
#: How many frames :data:`CMN_INIT` counts as in the running mean (a MAP-style prior): the count
#: of 0 to 200 (steps of 10) whose running mean is nearest (squared error over the 13 coefficients,
#: every 5-frame block of every recording) each recording's whole-utterance mean on the 16 real
#: recordings of PocketSphinx 5.1.1's test data (7 sources: goforward, numbers, something,
#: tidigits, cards, forever, LibriVox), none of them a test recording of this project
#: (``python -m benchmarks.cmn_prior``; it was 20). It keeps the mean of a stream's first words
#: from following the few frames of speech heard so far (docs/algorithm.md, "Cepstral mean").
CMN_PRIOR_FRAMES = 40.0


@dataclass(frozen=True)
class RecognizerConfig:
    """Settings of streaming recognition.

    Attributes
    ----------
    settle_s : frames this far behind the decoder's front are frozen (its front is about 40 ms
        behind the audio received, and its hypothesis ends about 10 ms before its front).
    partial_every : a partial hypothesis every this many 10 ms steps.
    cmn_every : the running cepstral mean is set every this many frames (``None``: PocketSphinx's
        own live mean).
    cmn_prior_frames, cmn_speech_share : the initial mean counts as this many frames in the
        running estimate (:data:`CMN_PRIOR_FRAMES`), speech as this share of it
        (:class:`RunningCmn`).
    max_utterance_s, restart_silence_s : a new utterance at the settled frame once the current
        one is this long, or once the settled phones end in a pause this long.
    """

    settle_s: float = 0.1
    partial_every: int = 2
    cmn_every: int | None = 5
    cmn_prior_frames: float = CMN_PRIOR_FRAMES
    cmn_speech_share: float | None = 0.78
    max_utterance_s: float = 10.0
    restart_silence_s: float = 0.3
    redecode_at_s: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if not 0.0 <= self.settle_s <= 2.0:
            raise ValueError(f"settle_s must be 0 to 2 s, not {self.settle_s!r}")
        if self.partial_every < 1 or (self.cmn_every is not None and not 1 <= self.cmn_every <= 200):
            raise ValueError("partial_every must be >= 1 and cmn_every 1 to 200 frames (or None)")


# --------------------------------------------------------------------------- the running mean
def held_sum(reported: np.ndarray, current: np.ndarray, frames: int, held: int = CMN_WIN
             ) -> np.ndarray:
    """The sum of the cepstra of the ``frames`` frames decoded since the mean was set to
    ``current``, from the mean PocketSphinx reports now (``get_cmn(update=True)``: its sum, which
    began as ``held * current``, over ``held + frames``).

    >>> held_sum(np.array([42.0]), np.array([40.0]), 100, held=400).tolist()
    [5000.0]
    """
    return np.asarray(reported, dtype=np.float64) * (held + frames) - held * np.asarray(current)


class RunningCmn:
    """The cepstral mean a stream's frames so far suggest for the whole utterance.

    Offline recognition removes the mean of the whole sentence (``full_utt``), about 78 % of whose
    frames are speech (the median speech share of the default corpus's read sentences, by energy;
    83 % on the ARCTIC samples). A stream's first second is mostly the silence before the speech,
    whose cepstra are far from speech's (c0 35 against 55-60): the plain mean of the frames so far
    stays low for seconds. So the frames are taken in blocks (one per update), the blocks split at
    the midpoint of their c0 range (5th to 95th percentile) into loud and quiet, and the two means
    weighed ``speech_share`` to ``1 - speech_share`` (the plain mean until the range reaches
    ``MIN_RANGE_C0``, or with ``speech_share=None``); the initial mean counts as ``prior_frames``
    frames (:data:`CMN_PRIOR_FRAMES`, a MAP-style prior). Only the last ``MAX_BLOCKS`` blocks
    count. Measured against offline recognition's phones (10 ms speech frames labelled alike,
    :func:`facetraj_engine.evaluation.live_eval.phone_agreement`) on the default corpus's 94 test
    sentences and 7 real ones (the ARCTIC and MOCHA samples), the prior worth 40 frames: these
    weighed means 65.0 % and 74.5 % (63.8 % and 72.9 % worth 20), the plain running mean 65.0 %
    and 75.8 %, PocketSphinx's own live mean 61.3 % and 61.1 %; live closure on the ARCTIC
    samples 77 %, 69 % and 54 %.

    >>> cmn = RunningCmn(np.array([40.0]), prior_frames=10, speech_share=None)
    >>> cmn.add(np.array([600.0]), 10).round(3).tolist()       # 10 frames of mean 60
    [50.0]
    >>> cmn = RunningCmn(np.array([40.0]), prior_frames=0, speech_share=0.75)
    >>> for c0 in (30.0, 30.0, 30.0, 60.0):                      # 3 quiet blocks, 1 loud one
    ...     mean = cmn.add(np.array([5 * c0]), 5)
    >>> mean.round(3).tolist()                                    # 0.75 * 60 + 0.25 * 30
    [52.5]
    """

    MAX_BLOCKS = 400
    MIN_RANGE_C0 = 5.0

    def __init__(self, init: np.ndarray = CMN_INIT, prior_frames: float = CMN_PRIOR_FRAMES,
                 speech_share: float | None = 0.78):
        self.init = np.asarray(init, dtype=np.float64)
        self.prior = float(prior_frames)
        self.speech_share = speech_share
        self._blocks: deque[tuple[np.ndarray, int]] = deque(maxlen=self.MAX_BLOCKS)
        self.mean = self.init.copy()

    @property
    def frames(self) -> int:
        return sum(n for _, n in self._blocks)

    def add(self, total: np.ndarray, frames: int) -> np.ndarray:
        """Add a block of ``frames`` frames whose cepstra sum to ``total``; the new mean."""
        if frames > 0:
            self._blocks.append((np.asarray(total, dtype=np.float64) / frames, int(frames)))
        means = np.array([m for m, _ in self._blocks])
        counts = np.array([n for _, n in self._blocks], dtype=np.float64)
        data, n = (means * counts[:, None]).sum(axis=0), counts.sum()
        if n == 0:
            return self.mean
        data = data / n
        if self.speech_share is not None and len(means) > 1:
            lo, hi = np.percentile(means[:, 0], [5, 95])
            loud = means[:, 0] > 0.5 * (lo + hi)
            if hi - lo >= self.MIN_RANGE_C0 and loud.any() and (~loud).any():
                speech = (means[loud] * counts[loud, None]).sum(axis=0) / counts[loud].sum()
                quiet = (means[~loud] * counts[~loud, None]).sum(axis=0) / counts[~loud].sum()
                data = self.speech_share * speech + (1.0 - self.speech_share) * quiet
        self.mean = (self.prior * self.init + n * data) / (self.prior + n)
        return self.mean


def _cmn_text(v: np.ndarray) -> str:
    return ",".join(f"{x:.4f}" for x in v)


def _cmn_vector(text: str) -> np.ndarray:
    return np.array([float(x) for x in text.split(",")])


# --------------------------------------------------------------------------- the recognizer
class StreamingRecognizer:
    """Audio blocks (any rate, mono floats in [-1, 1]) in with :meth:`feed`, :meth:`flush` at the
    end; the settled phones in :attr:`track` (``track.snapshot()``, ``track.settled_s``)."""

    def __init__(self, sample_rate: int, config: RecognizerConfig | None = None,
                 cmn: RunningCmn | None = None):
        self.config = config or RecognizerConfig()
        self.sample_rate = int(sample_rate)
        self.track = PhoneTrack(FRAME_S)
        self.cmn = cmn or RunningCmn(prior_frames=self.config.cmn_prior_frames,
                                     speech_share=self.config.cmn_speech_share)
        self.tool = f"PocketSphinx {pocketsphinx_version()}, streamed"
        self._resampler = ResampleStream(self.sample_rate, ALIGN_RATE)
        self._decoder = allphone_decoder()
        self._settle = int(round(self.config.settle_s / FRAME_S))
        self._pending = np.zeros(0)            # 16 kHz samples not yet a whole step
        self._pcm = bytearray()                # 16-bit audio from frame self._pcm_frame on
        self._pcm_frame = 0
        self._offset = 0                       # the utterance's first frame
        self._steps = 0
        self._since_cmn = 0                    # frames decoded since the mean was last set
        self._seen = 0                         # frames decoded in this utterance
        self.samples = 0                       # 16 kHz samples received
        self.restarts = 0
        self._redecodes = 0
        self._start()

    # ------------------------------------------------------------------ public
    @property
    def front_s(self) -> float:
        """Seconds of audio the decoder has turned into frames."""
        return (self._offset + self._seen) * FRAME_S

    def feed(self, block: np.ndarray) -> None:
        """Decode the next ``block`` of audio."""
        x = self._resampler.feed(np.asarray(block, dtype=np.float64).ravel())
        x = np.concatenate([self._pending, x]) if len(self._pending) else x
        whole = len(x) // FRAME_SAMPLES * FRAME_SAMPLES
        self._pending = x[whole:]
        for a in range(0, whole, FRAME_SAMPLES):
            self._step(x[a:a + FRAME_SAMPLES])

    def flush(self) -> None:
        """The audio ended: decode the rest, and settle every frame with the final hypothesis
        (frames after its last phone: silence)."""
        x = np.concatenate([self._pending, self._resampler.flush()])
        self._pending = np.zeros(0)
        if len(x):
            self._step(x)
        self._decoder.end_utt()
        self._observe()
        total = -(-self.samples // FRAME_SAMPLES)
        self.track.freeze(max(total, self.track.frozen))

    # ------------------------------------------------------------------ the steps
    def _start(self) -> None:
        self._decoder.start_utt()
        self._set_cmn()
        self._seen = 0

    def _set_cmn(self) -> None:
        if self.config.cmn_every is not None:
            self._decoder.set_cmn(_cmn_text(self.cmn.mean))
        self._since_cmn = 0

    def _step(self, x: np.ndarray) -> None:
        pcm = (np.clip(x, -1.0, 1.0) * 32767).astype("<i2").tobytes()
        self.samples += len(x)
        self._pcm += pcm
        self._decoder.process_raw(pcm, False, False)
        n = self._decoder.n_frames()
        self._since_cmn += n - self._seen
        self._seen = n
        every = self.config.cmn_every
        if every is not None and self._since_cmn >= every:
            reported = _cmn_vector(self._decoder.get_cmn(True))
            self.cmn.add(held_sum(reported, self.cmn.mean, self._since_cmn), self._since_cmn)
            self._set_cmn()
        self._steps += 1
        if self._steps % self.config.partial_every == 0:
            self._observe()
            self.track.freeze(min(self._offset + n - self._settle, self.track.observed_until()))
            self._maybe_redecode()
            self._trim_pcm()
            self._maybe_restart()

    def _observe(self) -> None:
        """The current hypothesis, as labels of the frames from the first unsettled one on."""
        segs = self._decoder.seg()
        if segs is None:
            return
        spans = [(self._offset + s.start_frame, self._offset + s.end_frame + 1, phone_label(s.word))
                 for s in segs]
        first = max(self.track.frozen, self._offset)
        labels = [SILENCE] * max(0, (spans[-1][1] if spans else first) - first)
        for a, b, lab in spans:
            for f in range(max(a, first), b):
                labels[f - first] = lab
        if labels:
            self.track.observe(first, labels)

    def _maybe_redecode(self) -> None:
        """Decode the utterance so far again with the running mean, at its young ages."""
        age = self._seen * FRAME_S
        if self._redecodes < len(self.config.redecode_at_s) and \
                age >= self.config.redecode_at_s[self._redecodes]:
            self._redecodes += 1
            self._decoder.end_utt()
            self._decoder.start_utt()
            self._set_cmn()
            self._decoder.process_raw(bytes(self._pcm), False, False)
            self._seen = self._decoder.n_frames()
            self._set_cmn()
            self._observe()

    def _trim_pcm(self) -> None:
        if self._redecodes < len(self.config.redecode_at_s):
            return                              # the utterance may be decoded again
        drop = self.track.frozen - self._pcm_frame
        if drop > 0:
            del self._pcm[:2 * drop * FRAME_SAMPLES]
            self._pcm_frame = self.track.frozen

    def _maybe_restart(self) -> None:
        """A new utterance at the settled frame, after a settled pause or a long utterance."""
        frozen = self.track.frozen
        length = frozen - self._offset
        last = self.track.phones[-1] if self.track.phones else None
        pause = (last is not None and last.label == SILENCE and last.end == frozen
                 and (last.end - last.start) * FRAME_S >= self.config.restart_silence_s)
        if length * FRAME_S < 1.0 or not (pause or length * FRAME_S >= self.config.max_utterance_s):
            return
        self._decoder.end_utt()
        self._offset = frozen
        self._start()
        if self._pcm:                                   # the unsettled audio again
            self._decoder.process_raw(bytes(self._pcm), False, False)
            self._seen = self._decoder.n_frames()
            self._set_cmn()                             # its frames were counted before
        self.restarts += 1
