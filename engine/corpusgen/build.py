"""Build the synthetic audio-visual corpus: text -> phones -> VocalTractLab -> audio + face.

Every utterance is a pure function of (seed, its index, the configuration): the random streams
for its durations, its audio noise floor and its face come from ``SeedSequence([seed, index])``,
so one utterance can be rebuilt alone (:func:`build_utterance`) and comes out bit for bit the
same as in a full build.
"""

from __future__ import annotations

import functools
import logging
import os
import re
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..data import PhoneSegment
from ..errors import FacetrajError
from ..fanout import Skips, fan_out
from ..io.audio import write_audio
from ..io.corpus import CorpusInfo, save_corpus_info
from ..io.labelfiles import write_textgrid
from ..io.markerfiles import write_c3d
from ..progress import Progress
from ..threads import usable_cores
from .durations import PAUSE, DurationModel, Segment, load_cmudict, pronounce, time_phones
from .face import (
    FIXED_MARKERS,
    LIP_CORNERS,
    LOWER_LIP,
    MARKER_NAMES,
    UPPER_LIP,
    FaceConfig,
    add_nuisance,
    articulate,
    drivers,
)
from .phonemap import ARPABET, Phone, vtl_segments
from .sentences import SENTENCES
from .vtl import AUDIO_RATE, synthesize, verify_phone_map

log = logging.getLogger(__name__)

DEFAULT_SEED = 1999
#: the committed corpus: the first 280 of the 300 sentences, about 10.5 minutes of speech and
#: 28 MB (all 300 would be about 30.1 MB; see docs/corpus.md)
DEFAULT_SENTENCES = 280
MIN_PHONE_COUNT = 20




@dataclass(frozen=True)
class CorpusConfig:
    """Settings of a corpus build (the number of sentences and the seed are arguments)."""

    audio_rate: int = 16000
    audio_gain: float = 5.0          # VTL's output peaks near 0.1
    noise_floor: float = 5e-5        # rms of a white background noise (no digital silence)
    test_every: int = 3              # sentences 1, 4, 7, ... go to the test split
    durations: DurationModel = field(default_factory=DurationModel)
    face: FaceConfig = field(default_factory=FaceConfig)


@dataclass
class UtteranceResult:
    """Summary of one built utterance."""

    utt_id: str
    duration: float
    phone_counts: Counter
    dropouts: list[tuple[str, int, int]]
    peak: float
    seconds: float


def utterance_id(index: int) -> str:
    """``0`` -> ``'s001'``."""
    return f"s{index + 1:03d}"


def utterance_index(utt_id: str) -> int:
    """``'s001'`` -> ``0``."""
    m = re.fullmatch(r"s(\d{3,})", utt_id)
    if not m:
        raise ValueError(f"not a corpus utterance id: {utt_id!r}")
    return int(m.group(1)) - 1


def split_ids(n_sentences: int, test_every: int = 3) -> tuple[list[str], list[str]]:
    """Train and test ids: every ``test_every``-th sentence from the first is a test sentence."""
    ids = [utterance_id(i) for i in range(n_sentences)]
    test = [u for i, u in enumerate(ids) if i % test_every == 0]
    train = [u for i, u in enumerate(ids) if i % test_every != 0]
    return train, test


def _word_tier(segs: list[Segment], words: list[str], duration: float) -> list[PhoneSegment]:
    out: list[PhoneSegment] = []
    cur = -1
    for s in segs:
        if s.label == PAUSE:
            continue
        if s.word_index != cur:
            out.append(PhoneSegment(s.start, s.end, words[s.word_index].lower()))
            cur = s.word_index
        else:
            out[-1] = PhoneSegment(out[-1].start, s.end, out[-1].label)
    return out


def build_utterance(utt_id: str, out_dir: str | os.PathLike[str], seed: int = DEFAULT_SEED,
                    config: CorpusConfig | None = None) -> UtteranceResult:
    """Synthesize one utterance of the corpus and write its four files into ``out_dir``."""
    from scipy.signal import resample_poly

    t_start = time.perf_counter()
    config = config or CorpusConfig()
    index = utterance_index(utt_id)
    if index >= len(SENTENCES):
        raise ValueError(f"{utt_id}: only {len(SENTENCES)} sentences are available")
    sentence = SENTENCES[index]
    rng_dur, rng_audio, rng_face = (np.random.default_rng(s) for s in
                                    np.random.SeedSequence([seed, index]).spawn(3))
    words = pronounce(sentence, _lexicon())
    segs = time_phones(words, rng_dur, config.durations)

    vtl_segs: list[tuple[str, float]] = []
    for s in segs:
        if s.label == PAUSE:
            vtl_segs.append(("", s.duration))
        else:
            for name, share in vtl_segments(Phone(s.label, s.stress)):
                vtl_segs.append((name, s.duration * share))
    out = synthesize(vtl_segs)

    # audio: 44.1 -> 16 kHz, fixed gain, a faint noise floor
    audio = resample_poly(out.audio, config.audio_rate // 100, AUDIO_RATE // 100)
    audio = config.audio_gain * audio + rng_audio.normal(0.0, config.noise_floor, len(audio))
    peak = float(np.abs(audio).max())
    if peak > 0.98:
        log.warning("%s: peak %.2f, scaled down to avoid clipping", utt_id, peak)
        audio *= 0.98 / peak
    duration = len(audio) / config.audio_rate

    # labels cover exactly [0, duration]: the final pause absorbs the difference
    last = segs[-1]
    segs[-1] = Segment(last.label, last.start, max(duration, last.start + 0.01), last.stress,
                       last.word_index)
    if segs[-1].end > duration + 1e-9:
        raise RuntimeError(f"{utt_id}: VTL audio ({duration:.3f} s) shorter than the labels")
    phones = [PhoneSegment(s.start, s.end, s.label) for s in segs]
    word_segs = _word_tier(segs, [w.text for w in words], duration)

    # face
    fcfg = config.face
    times = np.arange(int(np.floor(duration * fcfg.rate)) + 1) / fcfg.rate
    pauses = [(s.start, s.end) for s in segs if s.label == PAUSE]
    d = drivers(out, times, pauses, duration, fcfg)
    markers, drops = add_nuisance(articulate(d, fcfg), rng_face, fcfg)

    root = Path(out_dir)
    root.mkdir(parents=True, exist_ok=True)
    write_audio(root / f"{utt_id}.flac", audio, config.audio_rate)
    write_textgrid(root / f"{utt_id}.TextGrid", {"words": word_segs, "phones": phones}, duration)
    write_c3d(root / f"{utt_id}.c3d", markers, fcfg.rate, MARKER_NAMES)
    (root / f"{utt_id}.txt").write_text(sentence + "\n", encoding="utf-8")
    counts = Counter(s.label for s in segs if s.label != PAUSE)
    return UtteranceResult(utt_id, duration, counts, drops, peak, time.perf_counter() - t_start)


_LEXICON: dict | None = None


def _lexicon() -> dict:
    global _LEXICON
    if _LEXICON is None:
        _LEXICON = load_cmudict()
    return _LEXICON


def check_phone_coverage(counts: Counter, minimum: int = MIN_PHONE_COUNT) -> list[str]:
    """ARPAbet phones seen fewer than ``minimum`` times."""
    return [p for p in ARPABET if counts.get(p, 0) < minimum]


def _build_all(ids: list[str], root: Path, seed: int, config: CorpusConfig, workers: int,
               progress: Progress | None) -> dict[str, UtteranceResult]:
    """Every utterance of ``ids`` built into ``root`` in ``workers`` processes
    (:func:`facetraj_engine.fanout.fan_out`). A worker that dies fails its utterance only: the others are
    built, then the build stops with an error naming the ones that were not."""
    results: dict[str, UtteranceResult] = {}
    failed = Skips("utterances", verb="not built")
    build = functools.partial(build_utterance, out_dir=root, seed=seed, config=config)
    for utt_id, res in fan_out(build, ids, workers, skip=failed, progress=progress,
                               ordered=False):
        results[utt_id] = res
        log.info("%s done (%.1f s audio, %.1f s)", res.utt_id, res.duration, res.seconds)
    if failed:
        raise FacetrajError(f"{root}: {failed.summary()} (the other utterances are built; "
                            f"corpus.json is not written)")
    return results


def build_corpus(out_dir: str | os.PathLike[str], n_sentences: int = DEFAULT_SENTENCES,
                 seed: int = DEFAULT_SEED, progress: Progress | None = None,
                 workers: int | None = None, config: CorpusConfig | None = None,
                 check_map: bool = True) -> CorpusInfo:
    """Build the corpus into ``out_dir`` (``corpus.json`` + four files per sentence).

    ``progress(fraction, message)`` is called before synthesis and after each utterance (the
    engine's progress convention). ``workers`` processes (default: the usable cores; forked by
    :func:`facetraj_engine.fanout.fan_out`) synthesize in parallel; every utterance comes out the same
    bits however many. Returns the corpus description.
    """
    config = config or CorpusConfig()
    if not 1 <= n_sentences <= len(SENTENCES):
        raise ValueError(f"n_sentences must be 1..{len(SENTENCES)}, got {n_sentences}")
    root = Path(out_dir)
    root.mkdir(parents=True, exist_ok=True)
    train, test = split_ids(n_sentences, config.test_every)
    ids = [utterance_id(i) for i in range(n_sentences)]
    t0 = time.perf_counter()
    if progress:
        progress(0.0, "checking the phone map")
    if check_map:
        failed = [c for c in verify_phone_map() if not c.ok]
        if failed:
            log.warning("%d phone map checks failed (see above)", len(failed))
    # stale utterances of an earlier, larger build
    keep = set(ids)
    for p in root.iterdir():
        m = re.fullmatch(r"(s\d{3,})\.(flac|wav|TextGrid|c3d|txt)", p.name)
        if m and m.group(1) not in keep:
            p.unlink()
    results = _build_all(ids, root, seed, config, workers or usable_cores(), progress)
    train_counts: Counter = Counter()
    for u in train:
        train_counts.update(results[u].phone_counts)
    rare = check_phone_coverage(train_counts)
    if rare:
        log.warning("phones seen fewer than %d times in train: %s", MIN_PHONE_COUNT,
                    ", ".join(f"{p} ({train_counts.get(p, 0)})" for p in rare))
    dur_train = sum(results[u].duration for u in train)
    dur_test = sum(results[u].duration for u in test)
    n_drops = sum(len(r.dropouts) for r in results.values())
    info = CorpusInfo(
        marker_names=list(MARKER_NAMES), marker_rate=config.face.rate,
        fixed_markers=list(FIXED_MARKERS), upper_lip=UPPER_LIP, lower_lip=LOWER_LIP,
        train=train, test=test, lip_corners=list(LIP_CORNERS),
        name="facetraj synthetic (VocalTractLab JD3)",
        description=(f"Synthetic audio-visual corpus built by facetraj_engine.corpusgen (seed {seed}, "
                     f"{n_sentences} sentences): speech from the VocalTractLab articulatory "
                     f"synthesizer (speaker JD3), 54 face markers driven by its jaw and lip "
                     f"articulators, with head motion, marker noise and {n_drops} short marker "
                     f"dropouts. Train {dur_train / 60:.1f} min, test {dur_test / 60:.1f} min. "
                     f"See docs/corpus.md."),
    )
    save_corpus_info(root, info)
    log.info("corpus of %d sentences (train %.1f min, test %.1f min) built in %.0f s",
             n_sentences, dur_train / 60, dur_test / 60, time.perf_counter() - t0)
    return info
