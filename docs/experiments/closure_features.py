"""Which features of the bilabial-closure detector carry to a voice it was not trained on?
(docs/algorithm.md, "Lips that close without phones")

Each feature set feeds a logistic regression (``fit_logistic``, ridge 100 on standardised
features) fitted on the training split's frames (1 inside a /p b m/); scored on the held-out
sentences in the training voice and in their second voice (``second_voice``) by how well the
largest probability inside each /p b m/ beats the largest inside each other consonant (an AUC
over segments: 1 is perfect, 0.5 chance). Feature sets, each at frames t-3 .. t+3:

- dip + place (the detector's): the energy dip and the 8 lowest log LSFs minus their running
  mean over voiced frames, gated by voicing;
- + spectrum: with spectral tilt (the first normalised autocorrelation), zero crossings, LPC gain
  and six band energies (0-0.3-0.8-1.5-2.5-4-8 kHz, shares of the frame's energy in dB), each
  mean- and variance-normalised per utterance;
- cepstra: the dip and 12 LPC cepstra, mean-normalised per utterance;
- 18 LSFs: the dip and every LSF as it is;
- the search's opinion: the share of eq 7's weight on /p b m/ codewords and eq 8's unsmoothed
  aperture (``closure_search``; the training utterances searched without their own codewords).

    python docs/experiments/closure_features.py
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from facetraj_engine.config import SynthConfig, TrainConfig
from facetraj_engine.evaluation.closure import VOWELS, segment_frames
from facetraj_engine.evaluation.second_voice import second_voice
from facetraj_engine.io.corpus import load_corpus
from facetraj_engine.method.closure_detector import (
    BILABIALS,
    DetectorSpec,
    Logistic,
    bilabial_frames,
    detector_features,
    relative_energy,
    stacked,
    utterance_inputs,
    voiced_mean,
)
from facetraj_engine.method.closure_search import left_out_rows, search_rows
from facetraj_engine.method.lsf import analysis_frames, autocorrelation, levinson, resample_audio
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.training import train as train_model

SPEC = DetectorSpec()
CONFIG = TrainConfig()          # the analysis of the default model's inputs
BANDS_HZ = (0, 300, 800, 1500, 2500, 4000, 8000)


def spectrum(audio: np.ndarray, rate: int, times: np.ndarray) -> np.ndarray:
    """Per frame: tilt, zero crossings, LPC gain (dB), six band shares (dB); and 12 LPC cepstra."""
    x = resample_audio(np.asarray(audio, dtype=np.float64), rate, 16000)
    fr = analysis_frames(x, 16000, times, 0.025, 0.97)
    r = autocorrelation(fr, 19)
    r0 = np.where(r[:, 0] > 0, r[:, 0], 1.0) * (1 + 1e-4)
    a, err = levinson(np.column_stack([r0, r[:, 1:]]), 18)
    signs = np.signbit(fr)
    power = np.abs(np.fft.rfft(fr, 512)) ** 2
    f = np.fft.rfftfreq(512, 1 / 16000)
    total = power.sum(axis=1) + 1e-12
    bands = [10 * np.log10(power[:, (f >= lo) & (f < hi)].sum(axis=1) / total + 1e-6)
             for lo, hi in pairwise(BANDS_HZ)]
    cep = np.zeros((len(fr), 13))                       # LPC cepstrum of 1/A(z), c_1 .. c_12
    for m in range(1, 13):
        cep[:, m] = -a[:, m] - sum((k / m) * cep[:, k] * a[:, m - k] for k in range(1, m))
    return np.column_stack([r[:, 1] / r0, (signs[:, 1:] != signs[:, :-1]).mean(axis=1),
                            10 * np.log10(r0 / np.maximum(err, 1e-12)), *bands]), cep[:, 1:]


def normalised(x: np.ndarray, voiced: np.ndarray, scale: bool = True) -> np.ndarray:
    rows = x[voiced] if voiced.sum() > 10 else x
    return (x - rows.mean(axis=0)) / (rows.std(axis=0) + 1e-6 if scale else 1.0)


def feature_sets(audio, rate, times, mu0) -> dict[str, np.ndarray]:
    """Every feature set of one input (module docstring)."""
    w, e = utterance_inputs(CONFIG, audio, rate, times)
    dip = relative_energy(e, SPEC.back, SPEC.floor_db)[:, None]
    voiced = dip[:, 0] > -15
    spec, cep = spectrum(audio, rate, times)
    ours = detector_features(w, e, SPEC, mu0)
    return {"dip + place": ours,
            "+ spectrum": np.concatenate([ours, stacked(normalised(spec, voiced), SPEC.offsets)], 1),
            "cepstra": stacked(np.column_stack([dip, normalised(cep, voiced, False)]), SPEC.offsets),
            "18 LSFs": stacked(np.column_stack([dip, w]), SPEC.offsets)}


def segment_auc(p: list[np.ndarray], utts) -> float:
    """P(the largest p inside a /p b m/ > inside another consonant), ties counted half."""
    bil, other = [], []
    for q, u in zip(p, utts, strict=True):
        times = u.frame_times()
        for s in u.phones:
            if s.label in ("sil", "sp") or s.label in VOWELS:
                continue
            (bil if s.label in BILABIALS else other).append(q[segment_frames(s.start, s.end, times)].max())
    b, o = np.array(bil)[:, None], np.array(other)[None, :]
    return float((b > o).mean() + 0.5 * (b == o).mean())


def searched(model, audio, rate, n_frames) -> np.ndarray:
    res = synthesize(model, audio, rate, None, SynthConfig(mode="acoustic", closure=False),
                     n_frames=n_frames)
    return stacked(search_rows(model, res.frames), SPEC.offsets)


def main() -> None:
    corpus = load_corpus("data_samples")
    model = train_model(corpus)
    train = [corpus.utterance(u) for u in corpus.info.train]
    test = [corpus.utterance(u) for u in corpus.info.test]
    inputs = [utterance_inputs(CONFIG, u.audio, u.sample_rate, u.frame_times()) for u in train]
    mu0 = voiced_mean([w for w, _ in inputs], [e for _, e in inputs], SPEC)
    fitted, y = {}, np.concatenate([bilabial_frames(u.phones, u.frame_times()) for u in train])
    sets = [feature_sets(u.audio, u.sample_rate, u.frame_times(), mu0) for u in train]
    for k, (s, (w, _)) in enumerate(zip(sets, inputs, strict=True)):
        s["the search's opinion"] = stacked(left_out_rows(model, w, k), SPEC.offsets)
    for name in sets[0]:
        fitted[name] = Logistic.fit(np.concatenate([s[name] for s in sets]), y, 100.0)
    voices = {"training voice": [u.audio for u in test],
              "second voice": [second_voice(u.audio, u.sample_rate) for u in test]}
    for voice, audio in voices.items():
        held = [feature_sets(a, u.sample_rate, u.frame_times(), mu0) for a, u in zip(audio, test,
                                                                                    strict=True)]
        for h, a, u in zip(held, audio, test, strict=True):
            h["the search's opinion"] = searched(model, a, u.sample_rate, u.n_frames)
        for name, regression in fitted.items():
            auc = segment_auc([regression.probability(h[name]) for h in held], test)
            print(f"{voice}, {name}: /p b m/ against other consonants, AUC {auc:.3f}")


if __name__ == "__main__":
    main()
