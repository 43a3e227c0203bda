"""Does the bilabial-closure detector help beside recognized phones? (docs/algorithm.md, "Lips
that close without phones")

With recognized labels the closure step closes the lips at the recognized /p b m/, each trusted
``1 - voice match``. Where the detector and the recognizer disagree the detector could be a
second opinion: add its closures where no recognized /p b m/ is (fully, or trusted by the voice
match: the detector is trained on the training voice's own sounds), or weaken the recognized
/p b m/ where it finds no closure. The detector is the one acoustic-only synthesis uses: its
search part (the acoustic-only search of the same audio) mixed in by the voice match. Each
variant re-runs only the closure step on the same synthesis (``facetraj synth``'s default with
recognized labels) and is scored as ``facetraj report --closure`` scores it: on the default
corpus's held-out sentences (its recognized labels, the exact ones as the reference) and on the
CMU ARCTIC samples (recognized; their transcripts aligned as the reference).

    python docs/experiments/closure_second_opinion.py [../shared/data/arctic_samples]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from facetraj_engine.config import SynthConfig
from facetraj_engine.evaluation.closure import ClosureScore, closure_score, lip_aperture
from facetraj_engine.evaluation.closure_eval import arctic_references
from facetraj_engine.io.corpus import load_corpus
from facetraj_engine.io.label_rule import label_audio
from facetraj_engine.io.labelling import relabelled
from facetraj_engine.method.closure import ClosurePlan
from facetraj_engine.method.closure_detector import closure_runs, input_probability
from facetraj_engine.method.closure_search import search_rows
from facetraj_engine.method.modes import choose_mode
from facetraj_engine.method.pipeline import _smoothed, synthesize
from facetraj_engine.method.training import train


def overlaps(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per interval of ``a``, whether it overlaps one of ``b``."""
    return np.array([bool(((b[:, 0] < t1) & (b[:, 1] > t0)).any()) for t0, t1 in a], dtype=bool)


def variants(model, res, p: np.ndarray, threshold: float) -> dict[str, ClosurePlan]:
    """The closure plans of one synthesis: as it is, and each way of adding the detector."""
    plan = res.closure
    runs = closure_runs(p, res.times, threshold, model.detector.spec.min_frames)
    new = runs[~overlaps(runs, plan.intervals)] if len(runs) else runs
    supported = overlaps(plan.intervals, runs) if len(runs) else np.zeros(len(plan.intervals), bool)
    match = res.voice_match if np.isfinite(res.voice_match) else 1.0

    def with_(iv, st):
        return ClosurePlan(iv, st, plan.pauses, p)

    return {
        "recognized /p b m/ (as it is)": plan,
        "+ the detector's closures where none is recognized": with_(
            np.concatenate([plan.intervals, new]), np.concatenate([plan.strengths, np.ones(len(new))])),
        "+ those closures trusted by the voice match": with_(
            np.concatenate([plan.intervals, new]),
            np.concatenate([plan.strengths, np.full(len(new), match)])),
        "recognized /p b m/ without a detected closure dropped": with_(
            plan.intervals[supported], plan.strengths[supported]),
    }


def score(model, items, threshold: float) -> None:
    pooled: dict[str, list[ClosureScore]] = {}
    for audio, rate, phones, prov, conf, ref, n_frames in items:
        cfg = choose_mode(SynthConfig(), phones, prov, tuned=model.tuned).config
        res = synthesize(model, audio, rate, phones, cfg, n_frames=n_frames, confidence=conf,
                         provenance=prov)
        acoustic = synthesize(model, audio, rate, None, SynthConfig(mode="acoustic", closure=False),
                              n_frames=n_frames)            # the search's opinion: its own search
        p = input_probability(model.detector, model.config, audio, rate, res.times,
                              search=search_rows(model, acoustic.frames), match=res.voice_match)
        for name, plan in variants(model, res, p, threshold).items():
            pcs = _smoothed(model, res.raw_pcs, res.times, res.config, res.config.smoothing, plan)
            a = lip_aperture(model.to_markers(pcs), model.upper_lip, model.lower_lip)
            pooled.setdefault(name, []).append(closure_score(a, res.times, ref, model.closure.closed))
    for name, parts in pooled.items():
        s = ClosureScore.pooled(parts)
        print(f"  {name}: /p b m/ within 1 mm {100 * s.within:.0f} % of {s.n}, vowels shut "
              f"{100 * s.vowels_shut:.1f} %, other consonants shut {100 * s.consonants_shut:.1f} %, "
              f"vowel max {s.vowel_max:.1f} mm")


def main(arctic: str = "../shared/data/arctic_samples") -> None:
    corpus = load_corpus("data_samples")
    model = train(corpus)
    threshold = SynthConfig().closure_threshold
    lab = relabelled(corpus, "recognized", split="test")
    items = []
    for utt_id in lab.info.test:
        ref, utt = corpus.utterance(utt_id), lab.utterance(utt_id)
        items.append((utt.audio, utt.sample_rate, utt.phones, utt.provenance, utt.confidence,
                      ref.phones, utt.n_frames))
    print("default corpus, held-out sentences, recognized labels:")
    score(model, items, threshold)
    items = []
    for audio, rate, ref in arctic_references(Path(arctic)).values():
        labels = label_audio(audio, rate, "recognized")
        items.append((audio, rate, labels.phones, labels.provenance, labels.trust(), ref, None))
    print("CMU ARCTIC samples, recognized labels:")
    score(model, items, threshold)


if __name__ == "__main__":
    main(*sys.argv[1:])
