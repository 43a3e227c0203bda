"""How the bilabial-closure detector's threshold was chosen (docs/algorithm.md, "Lips that close
without phones"): on the training split alone, never on the held-out sentences or the ARCTIC
samples.

The training utterances in 5 folds: the detector fitted on four (``train_detector``, its search
part on the utterances searched with their own codewords left out, as ``facetraj train`` does),
its closures found on the fifth, in the training voice (voice match 1: the mixture's search
part) and in the second voice of the same sentences (``second_voice``; voice match 0: the
acoustic part alone). Per threshold: the /p b m/ found and the closures reaching none
(``detector_score``), and F1 of the two (precision: the share of closures reaching a /p b m/).
The threshold kept is the one with the best mean F1 of the two voices: precision counts as much
as recall, and a voice the model was not trained on as much as its own.

    python docs/experiments/closure_detector.py
"""

from __future__ import annotations

import numpy as np

from facetraj_engine.evaluation.closure import DetectorScore, detector_score
from facetraj_engine.evaluation.second_voice import second_voice
from facetraj_engine.io.corpus import load_corpus
from facetraj_engine.method.closure_detector import (
    bilabial_frames,
    closure_runs,
    train_detector,
    utterance_inputs,
)
from facetraj_engine.method.closure_search import left_out_rows
from facetraj_engine.method.training import train

FOLDS = 5
THRESHOLDS = np.round(np.arange(0.06, 0.42, 0.02), 2)


def f1(s: DetectorScore) -> float:
    p, r = s.precision, s.recall
    return 2 * p * r / (p + r) if p + r > 0 else 0.0


def main() -> None:
    corpus = load_corpus("data_samples")
    model = train(corpus)
    utts = [corpus.utterance(u) for u in corpus.info.train]
    voices = {"training": [], "second": []}
    for k, utt in enumerate(utts):
        times = utt.frame_times()
        w, e = utterance_inputs(model.config, utt.audio, utt.sample_rate, times)
        other = second_voice(utt.audio, utt.sample_rate)
        w2, e2 = utterance_inputs(model.config, other, utt.sample_rate, times)
        target = bilabial_frames(utt.phones, times)
        voices["training"].append((w, e, left_out_rows(model, w, k), target, 1.0))
        voices["second"].append((w2, e2, left_out_rows(model, w2, k), target, 0.0))
    fold = np.arange(len(utts)) % FOLDS
    p = {v: [None] * len(utts) for v in voices}
    for f in range(FOLDS):
        fit = [k for k in range(len(utts)) if fold[k] != f]
        own = voices["training"]
        det = train_detector([own[k][0] for k in fit], [own[k][1] for k in fit],
                             [own[k][3] for k in fit], search=[own[k][2] for k in fit])
        for v, items in voices.items():
            for k in np.flatnonzero(fold == f):
                w, e, s, _, match = items[k]
                p[v][k] = det.frame_probability(w, e, s, match)
    print("threshold | training voice: found, closures, precision, F1 | second voice: ... | mean F1")
    best = None
    for th in THRESHOLDS:
        row, scores = [], []
        for v in voices:
            s = DetectorScore.pooled([
                detector_score(closure_runs(p[v][k], utts[k].frame_times(), th), utts[k].frame_times(),
                               utts[k].phones) for k in range(len(utts))])
            scores.append(f1(s))
            row.append(f"{s.found}/{s.n}, {s.closures}, {100 * s.precision:.0f} %, {f1(s):.3f}")
        mean = float(np.mean(scores))
        best = max(best or (mean, th), (mean, th))
        print(f"{th:.2f} | " + " | ".join(row) + f" | {mean:.3f}")
    print(f"best mean F1 {best[0]:.3f} at threshold {best[1]:.2f}")


if __name__ == "__main__":
    main()
