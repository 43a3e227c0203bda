"""Phone labels for any English recording: forced alignment of a transcript, or phone recognition.

The paper's phonetic mode (section 2.3, eq 4) needs the phone labels of the input speech; the
paper obtained them with an HMM aligner from the orthographic transcript. Here the aligner is
PocketSphinx (US English acoustic model and CMU pronouncing dictionary shipped in its wheel, so it
works offline):

- :func:`align` -- audio + sentence -> phones and words (two decoding passes: word alignment, then
  phone alignment);
- :func:`recognize` -- audio alone -> phones, by the all-phone search (a phone loop with a phone
  language model), then aligned again as a phone sequence so that its scores are on the same
  scale as :func:`align`'s.

Both return :class:`Labels`: the ``phones`` tier (ARPAbet, lower case, ``sil`` for silence,
covering ``[0, duration]``), the ``words`` tier (aligned words only), ``source`` (``"file"``,
``"aligned"`` or ``"recognized"``) and one acoustic ``score`` per phone (see :class:`Labels`).
PocketSphinx is imported inside the functions: the rest of the engine does not need it.
"""

from __future__ import annotations

import logging
import os
import re
import unicodedata
from collections.abc import Iterable, Mapping, Sequence
from math import gcd
from pathlib import Path

import numpy as np

from ..data import PhoneSegment, Provenance
from ..errors import FacetrajError, InputError
from .phoneset import ARPABET, SILENCE
from .provenance import Labels

log = logging.getLogger(__name__)

#: PocketSphinx's acoustic model rate.
ALIGN_RATE = 16000
#: One PocketSphinx frame, seconds.
FRAME_S = 0.01
#: Shortest audio the aligner is given.
MIN_DURATION_S = 0.25
#: Frames per phone the HMM topology needs at least (3 emitting states).
MIN_FRAMES_PER_PHONE = 3
#: Mean per-frame score margin (alignment minus the free phone loop) beyond which the text is
#: taken not to match the audio.
UNALIGNABLE_MARGIN = 12.0
#: Decoder settings of the all-phone search. The phone language model's weight ``lw`` 4 (2 before
#: issue 25): on six real CMU ARCTIC sentences it finds 11 of 13 /p b m/ (lw 0.5-1: 7, 2: 9,
#: 6.5: 9; 3 false /p b m/ of 15 found), on the real MOCHA-TIMIT sample the phone error rate is
#: the same at lw 2-4 (42.9 %); on the synthetic default corpus it finds fewer (14 of 35 against
#: 20), where synthesis trusts recognized bilabials least (facetraj_engine.method.closure).
ALLPHONE_SETTINGS = {"lw": 4.0, "pip": 0.3, "beam": 1e-20, "pbeam": 1e-20}


class MissingWordsError(InputError):
    """Words of the sentence that the pronouncing dictionary lacks (``.words``, in order)."""

    def __init__(self, path: str | os.PathLike[str] | None, words: Sequence[str]):
        self.words = list(words)
        super().__init__(path, "not in the pronouncing dictionary: " + ", ".join(self.words)
                         + " (give their pronunciations with --dict FILE, CMUdict lines "
                           "'WORD  PH1 PH2 ...')")


class UnalignableError(InputError):
    """The text could not be aligned to the audio (wrong sentence, silence, noise)."""


# --------------------------------------------------------------------------- text
def words_of(text: str, source: str | os.PathLike[str] | None = None) -> list[str]:
    """The sentence as lower-case dictionary words (punctuation dropped, accents stripped).

    Raises :class:`InputError` for empty text, digits, or letters outside the English alphabet.

    >>> words_of("Don't  go -- it's 'late', Zoë!")
    ["don't", 'go', "it's", 'late', 'zoe']
    """
    text = unicodedata.normalize("NFKD", text.replace("\u2019", "'").replace("\u2018", "'"))
    text = "".join(c for c in text if not unicodedata.combining(c)).lower()
    if re.search(r"\d", text):
        raise InputError(source, "the text holds digits: write numbers as words to align them")
    foreign = sorted({c for c in text if c.isalpha() and not ("a" <= c <= "z")})
    if foreign:
        raise InputError(source, "the text holds non-English characters ("
                                 + " ".join(foreign) + "): the aligner knows US English only")
    words = [w.strip("'") for w in re.split(r"[^a-z']+", text)]
    words = [w for w in words if w]
    if not words:
        raise InputError(source, "the text is empty: give the sentence spoken, or recognize the "
                                 "phones without text")
    return words


def read_dictionary(path: str | os.PathLike[str]) -> dict[str, list[str]]:
    """Read pronunciations in CMUdict format: ``WORD  PH1 PH2 ...`` (stress digits allowed,
    ``;;;`` comments, ``WORD(2)`` variants); phones must be ARPAbet.

    Raises :class:`InputError` naming the file and line of a bad entry.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(path, "no such dictionary file")
    try:
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError:
        raise InputError(path, "the dictionary is not UTF-8 text") from None
    known = set(ARPABET)
    out: dict[str, list[str]] = {}
    for lineno, line in enumerate(lines, 1):
        parts = line.split()
        if not parts or line.startswith(";;;") or parts[0].startswith("#"):
            continue
        if len(parts) < 2:
            raise InputError(path, f"line {lineno}: expected 'WORD PH1 PH2 ...', got {line!r}")
        word = re.sub(r"\(\d+\)$", "", parts[0]).lower()
        phones = [re.sub(r"[012]$", "", p).lower() for p in parts[1:]]
        bad = [p for p in phones if p not in known]
        if bad:
            raise InputError(path, f"line {lineno}: {', '.join(bad)} not ARPAbet phones")
        out.setdefault(word, phones)
    return out


# --------------------------------------------------------------------------- audio
def _pcm16k(audio: np.ndarray, rate: int, source: str | os.PathLike[str] | None) -> bytes:
    """Mono audio at any rate as 16 kHz 16-bit PCM bytes, checked for length and silence."""
    from scipy.signal import resample_poly

    audio = np.asarray(audio, dtype=float)
    duration = len(audio) / float(rate)
    if duration < MIN_DURATION_S:
        raise InputError(source, f"the audio is too short ({duration * 1000:.0f} ms) to label: "
                                 f"at least {MIN_DURATION_S * 1000:.0f} ms of speech is needed")
    if rate != ALIGN_RATE:
        g = gcd(int(rate), ALIGN_RATE)
        audio = resample_poly(audio, ALIGN_RATE // g, int(rate) // g)
    if not np.any(np.abs(audio) * 32767 >= 1.0):
        raise UnalignableError(source, "the audio is silent: there is no speech to label")
    return (np.clip(audio, -1.0, 1.0) * 32767).astype("<i2").tobytes()


def _decoder(**settings):
    return _pocketsphinx().Decoder(samprate=ALIGN_RATE, loglevel="FATAL", **settings)


def _decode(decoder, pcm: bytes) -> None:
    decoder.start_utt()
    decoder.process_raw(pcm, full_utt=True)
    decoder.end_utt()


def _pocketsphinx():
    """The ``pocketsphinx`` module, imported on first use; a clear error when it is missing."""
    try:
        import pocketsphinx
    except ImportError as exc:
        raise FacetrajError("phone labelling needs PocketSphinx, which is not installed "
                            "(pip install 'pocketsphinx>=5.1,<6')") from exc
    return pocketsphinx


def pocketsphinx_version() -> str:
    """The installed PocketSphinx version (part of the label cache key)."""
    from importlib.metadata import PackageNotFoundError, version

    _pocketsphinx()
    try:
        return version("pocketsphinx")
    except PackageNotFoundError:
        return "unknown"


# --------------------------------------------------------------------------- alignment
def phone_label(name: str) -> str:
    """A PocketSphinx phone or filler as a label: ARPAbet lower case, ``sil`` for silence, fillers
    and anything else.

    >>> phone_label("B"), phone_label("SIL"), phone_label("+NSN+")
    ('b', 'sil', 'sil')
    """
    lab = name.lower()
    return SILENCE if lab == "sil" or lab.startswith("+") or lab not in ARPABET else lab


def _segments(entries: Iterable[tuple[str, int, int, float]], duration: float
              ) -> tuple[list[PhoneSegment], np.ndarray]:
    """Phones from ``(name, start_frame, n_frames, score)``, adjacent silences merged, stretched
    to cover ``[0, duration]``; scores per frame."""
    phones: list[PhoneSegment] = []
    scores: list[float] = []
    frames: list[int] = []
    for name, start, length, score in entries:
        lab = phone_label(name)
        t0, t1 = start * FRAME_S, (start + length) * FRAME_S
        if phones and lab == SILENCE and phones[-1].label == SILENCE:
            prev = phones[-1]
            phones[-1] = PhoneSegment(prev.start, t1, SILENCE)
            scores[-1] += score
            frames[-1] += length
            continue
        phones.append(PhoneSegment(t0, t1, lab))
        scores.append(float(score))
        frames.append(int(length))
    if not phones:
        return [PhoneSegment(0.0, duration, SILENCE)], np.array([np.nan])
    phones[0] = PhoneSegment(0.0, phones[0].end, phones[0].label)
    last = phones[-1]
    if duration - last.end < 0.05:          # frame rounding at the end: the last phone reaches it
        phones[-1] = PhoneSegment(last.start, max(duration, last.start + 1e-3), last.label)
    else:
        phones.append(PhoneSegment(last.end, duration, SILENCE))
        scores.append(np.nan)
        frames.append(1)
    per_frame = np.array(scores) / np.maximum(np.array(frames, dtype=float), 1.0)
    return phones, per_frame


def _phone_alignment(decoder, pcm: bytes, text: str):
    """The two-pass alignment of ``text`` (already in the decoder's dictionary); None on failure."""
    try:
        decoder.set_align_text(text)
        _decode(decoder, pcm)
        if decoder.hyp() is None:
            return None
        decoder.set_alignment()
        _decode(decoder, pcm)
    except RuntimeError:
        return None
    return decoder.get_alignment()


def _free_loop_score(pcm: bytes) -> float:
    """Mean per-frame score of the phone sequence the free phone loop finds, re-aligned (the
    best any sentence could do on this audio, near enough)."""
    phones, scores, _ = _recognize_segments(pcm)
    ok = np.isfinite(scores)
    if not ok.any():
        return np.nan
    dur = np.array([p.duration for p in phones])[ok]
    return float(np.sum(scores[ok] * dur) / np.sum(dur))


def align(audio: np.ndarray, rate: int, text: str, extra_dict: Mapping[str, Sequence[str]] |
          None = None, source: str | os.PathLike[str] | None = None,
          check_fit: bool = True) -> Labels:
    """Forced alignment of ``text`` to ``audio`` (any rate; resampled to 16 kHz): phones and words.

    ``extra_dict`` adds pronunciations (word -> ARPAbet phones), e.g. from
    :func:`read_dictionary`. ``source`` names the input in error messages. With ``check_fit``,
    the alignment's mean per-frame score is compared with a free phone loop's on the same audio
    and the text rejected when it fits much worse (``UNALIGNABLE_MARGIN``).

    Raises :class:`MissingWordsError` (naming each word the dictionary lacks),
    :class:`UnalignableError` (text that does not match the audio, silence) and
    :class:`InputError` (audio too short, empty text, digits, non-English characters).
    """
    words = words_of(text, source)
    pcm = _pcm16k(audio, rate, source)
    duration = len(audio) / float(rate)
    decoder = _decoder(bestpath=False)
    extra = {k.lower(): list(v) for k, v in (extra_dict or {}).items()}
    for word in dict.fromkeys(words):
        if word in extra:
            decoder.add_word(word, " ".join(p.upper() for p in extra[word]), False)
    missing = [w for w in dict.fromkeys(words) if decoder.lookup_word(w) is None]
    if missing:
        raise MissingWordsError(source, missing)
    n_frames = len(pcm) // 2 // int(ALIGN_RATE * FRAME_S)
    n_phones = sum(len(decoder.lookup_word(w).split()) for w in words)
    if n_frames < MIN_FRAMES_PER_PHONE * n_phones:
        raise UnalignableError(source, f"the text ({n_phones} phones) is too long for "
                                       f"{duration:.2f} s of audio")
    sentence = " ".join(words)
    alignment = _phone_alignment(decoder, pcm, sentence)
    if alignment is None:
        raise UnalignableError(source, f"the text {sentence!r} does not match the audio: no "
                                       "alignment found (wrong sentence, silence or noise?)")
    entries, word_segs = [], []
    for w in alignment:
        name = re.sub(r"\(\d+\)$", "", w.name)
        if not name.startswith(("<", "[", "+")):
            word_segs.append(PhoneSegment(w.start * FRAME_S, (w.start + w.duration) * FRAME_S, name))
        entries.extend((p.name, p.start, p.duration, p.score) for p in w)
    phones, scores = _segments(entries, duration)
    labels = Labels(phones, word_segs, "aligned", scores, sentence,
                    Provenance("aligned", f"PocketSphinx {pocketsphinx_version()}"))
    if check_fit:
        fit = _mean_score(labels)
        free = _free_loop_score(pcm)
        log.debug("alignment fit %.1f per frame, free phone loop %.1f", fit, free)
        if np.isfinite(free) and free - fit > UNALIGNABLE_MARGIN:
            raise UnalignableError(source, f"the text {sentence!r} does not match the audio (it "
                                           f"fits {free - fit:.0f} log units per frame worse than "
                                           "free phone recognition): wrong sentence or noise?")
    log.info("aligned %d words, %d phones to %.2f s of audio", len(word_segs),
             sum(p.label != SILENCE for p in phones), duration)
    return labels


def _mean_score(labels: Labels) -> float:
    ok = np.isfinite(labels.scores)
    dur = np.array([p.duration for p in labels.phones])[ok]
    return float(np.sum(labels.scores[ok] * dur) / np.sum(dur)) if ok.any() else np.nan


# --------------------------------------------------------------------------- recognition
def allphone_decoder():
    """A PocketSphinx decoder of the all-phone search (:data:`ALLPHONE_SETTINGS`, 16 kHz): the one
    recognition uses, offline here and streamed in live mode (``facetraj_engine.streaming.recognizer``)."""
    lm = os.path.join(_pocketsphinx().get_model_path(), "en-us", "en-us-phone.lm.bin")
    return _decoder(allphone=lm, **ALLPHONE_SETTINGS)


def _recognize_segments(pcm: bytes) -> tuple[list[PhoneSegment], np.ndarray, int]:
    """All-phone search, then the phones found re-aligned as a phone sequence (scores)."""
    dec = allphone_decoder()
    _decode(dec, pcm)
    n_frames = dec.n_frames()
    found = [(s.word, s.start_frame, s.end_frame - s.start_frame + 1) for s in dec.seg()]
    duration = len(pcm) / 2 / ALIGN_RATE
    phones, _ = _segments(((n, a, k, np.nan) for n, a, k in found), duration)
    speech = [p.label for p in phones if p.label != SILENCE]
    if not speech:
        return phones, np.full(len(phones), np.nan), n_frames
    # re-align the phone sequence, each phone a one-phone "word", for scores on align()'s scale
    aligner = _decoder(bestpath=False)
    for ph in set(speech):
        aligner.add_word(f"_{ph}_", ph.upper(), False)
    alignment = _phone_alignment(aligner, pcm, " ".join(f"_{p}_" for p in speech))
    if alignment is None:
        log.debug("recognized phones could not be re-aligned: boundaries of the phone loop kept")
        return phones, np.full(len(phones), np.nan), n_frames
    entries = [(p.name, p.start, p.duration, p.score) for w in alignment for p in w]
    aligned, scores = _segments(entries, duration)
    return aligned, scores, n_frames


def recognize(audio: np.ndarray, rate: int, source: str | os.PathLike[str] | None = None
              ) -> Labels:
    """Phone recognition without text (any rate; resampled to 16 kHz): the phones tier.

    The all-phone search of PocketSphinx (phone loop with a phone trigram model) finds the phone
    sequence; it is then re-aligned to the audio as a phone sequence, which gives boundaries and
    per-phone scores on the same scale as :func:`align`. Raises :class:`InputError` for audio too
    short and :class:`UnalignableError` for silent audio.
    """
    pcm = _pcm16k(audio, rate, source)
    phones, scores, _ = _recognize_segments(pcm)
    duration = len(audio) / float(rate)
    if phones and abs(phones[-1].end - duration) > 1e-9:
        phones[-1] = PhoneSegment(phones[-1].start, max(duration, phones[-1].start + 1e-3),
                                  phones[-1].label)
    log.info("recognized %d phones in %.2f s of audio",
             sum(p.label != SILENCE for p in phones), duration)
    return Labels(phones, [], "recognized", scores, "",
                  Provenance("recognized", f"PocketSphinx {pocketsphinx_version()}"))
