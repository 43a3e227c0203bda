"""Can the acoustic search itself say where the lips close? (docs/algorithm.md, "Lips that close")

In acoustic-only synthesis each frame's eq 7 weights fall on codewords whose context-phones have a
centre phone; the share of the weight on /p b m/ codewords is a bilabial detector needing no
labels. Scored on the default corpus's held-out sentences (exact labels as the truth) and on the
CMU ARCTIC samples (their transcripts aligned as the truth): the AUC of the share over frames
inside /p b m/ against the rest, and at thresholds the /p b m/ found and the spurious runs.

    python docs/experiments/acoustic_bilabials.py [../shared/data/arctic_samples]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.stats import mannwhitneyu

from facetraj_engine.config import SynthConfig
from facetraj_engine.evaluation.closure_eval import arctic_references
from facetraj_engine.io.corpus import load_corpus
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.training import train

BILABIALS = ("p", "b", "m")


def bilabial_share(model, res) -> np.ndarray:
    """Per frame, the share of eq 7's weight on codewords of /p b m/ context-phones."""
    cb = model.codebook
    is_bilabial = np.isin(np.array(model.phones), BILABIALS)
    per_codeword = is_bilabial[cb.centre][np.arange(len(cb.lsf)) // cb.n_per_phone]
    w = res.frames.weights
    return (w * per_codeword[res.frames.candidates]).sum(1) / w.sum(1)


def inside(times: np.ndarray, phones) -> np.ndarray:
    mask = np.zeros(len(times), bool)
    for s in phones:
        if s.label in BILABIALS:
            mask |= (times >= s.start) & (times < s.end)
    return mask


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    d = np.diff(np.r_[0, mask.astype(int), 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True))


def report(name: str, items: list[tuple[np.ndarray, np.ndarray]]) -> None:
    share = np.concatenate([s for s, _ in items])
    truth = np.concatenate([t for _, t in items])
    auc = mannwhitneyu(share[truth], share[~truth]).statistic / (truth.sum() * (~truth).sum())
    seconds = len(share) / 60.0
    print(f"{name}: {len(share)} frames ({seconds:.0f} s), AUC {auc:.3f}")
    for th in (0.3, 0.5, 0.7):
        found = [s[a:b].max() > th for s, t in items for a, b in runs(t)]
        spurious = sum(len(runs((s > th) & ~t)) for s, t in items)
        print(f"  threshold {th}: {sum(found)} of {len(found)} /p b m/ found, {spurious} spurious runs")


def main(arctic: str = "../shared/data/arctic_samples") -> None:
    corpus = load_corpus("data_samples")
    model = train(corpus)
    config = SynthConfig(mode="acoustic", closure=False)
    items = []
    for utt_id in corpus.info.test[:60]:
        utt = corpus.utterance(utt_id)
        res = synthesize(model, utt.audio, utt.sample_rate, None, config, n_frames=utt.n_frames)
        items.append((bilabial_share(model, res), inside(res.times, utt.phones)))
    report("default corpus, 60 held-out sentences", items)
    items = []
    for audio, rate, ref in arctic_references(Path(arctic)).values():
        res = synthesize(model, audio, rate, None, config)
        items.append((bilabial_share(model, res), inside(res.times, ref)))
    report("CMU ARCTIC samples", items)


if __name__ == "__main__":
    main(*sys.argv[1:])
