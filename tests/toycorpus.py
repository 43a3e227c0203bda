"""A small deterministic audio-visual corpus for fast engine tests.

Eight phones, each with its own resonances (so LSFs tell them apart) and its own face target
(jaw opening, lip closure, rounding, lower lip to teeth); 12 markers with rigid head motion,
noise and short dropouts. Written in the project's corpus format.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter1d
from scipy.signal import lfilter

from facetraj_engine.data import PhoneSegment
from facetraj_engine.io.audio import write_audio
from facetraj_engine.io.corpus import CorpusInfo, save_corpus_info
from facetraj_engine.io.labelfiles import write_textgrid
from facetraj_engine.io.markerfiles import write_c3d

RATE = 16000
FPS = 60.0
NAMES = ["FH_L", "FH_R", "NB", "NT", "UL_C", "LL_C", "LC_R", "LC_L", "CHIN", "JAW_R", "JAW_L",
         "CHK_R"]
FIXED = ["FH_L", "FH_R", "NB", "NT"]
NEUTRAL = np.array([
    [-30, 60, 60], [30, 60, 60], [0, 40, 85], [0, 5, 100], [0, -12, 92], [0, -25, 90],
    [25, -18, 82], [-25, -18, 82], [0, -55, 85], [50, -40, 40], [-50, -40, 40], [40, -10, 75],
], dtype=float)

# phone: (formants Hz, voiced, gain, jaw open mm, lip gap mm (+ opens), rounding mm, ll_up mm)
PHONES = {
    "sil": ((), False, 0.0, 0.0, -2.0, 0.0, 0.0),
    "aa": ((750, 1200, 2500), True, 1.0, 12.0, 8.0, 0.0, 0.0),
    "iy": ((300, 2300, 3000), True, 0.8, 3.0, 2.0, -3.0, 0.0),
    "uw": ((320, 850, 2300), True, 0.7, 4.0, 1.0, 6.0, 0.0),
    "m": ((250, 1100, 2500), True, 0.3, 2.0, -3.0, 0.0, 0.0),
    "f": ((1800, 4500, 6500), False, 0.15, 2.0, 0.0, 0.0, 5.0),
    "s": ((4500, 6000, 7000), False, 0.2, 1.0, 1.0, -1.0, 0.0),
    "t": ((1800, 3500, 5000), False, 0.25, 3.0, 2.0, 0.0, 0.0),
}
SPEECH = [p for p in PHONES if p != "sil"]


def _resonator(freqs, bw=120.0):
    a = np.array([1.0])
    for f in freqs:
        r = np.exp(-np.pi * bw / RATE)
        a = np.convolve(a, [1, -2 * r * np.cos(2 * np.pi * f / RATE), r * r])
    return a


def make_utterance(rng: np.random.Generator, n_phones: int):
    """Phone segments, audio and markers (T, 12, 3) of one random utterance."""
    seq = ["sil", *list(rng.choice(SPEECH, n_phones)), "sil"]
    durs = [0.25, *list(rng.uniform(0.07, 0.16, n_phones)), 0.25]
    bounds = np.concatenate([[0], np.cumsum(durs)])
    n_samp = int(round(bounds[-1] * RATE))
    audio = np.zeros(n_samp)
    for p, a, b in zip(seq, bounds[:-1], bounds[1:], strict=True):
        formants, voiced, gain = PHONES[p][:3]
        i0, i1 = int(round(a * RATE)), int(round(b * RATE))
        n = i1 - i0
        if gain == 0:
            continue
        if voiced:
            exc = np.zeros(n)
            exc[:: int(RATE / 120)] = 1.0
            exc += 0.02 * rng.standard_normal(n)
        else:
            exc = rng.standard_normal(n) * 0.3
        seg = lfilter([1.0], _resonator(formants), exc)
        seg = seg / (np.abs(seg).max() + 1e-9) * 0.5 * gain
        ramp = np.minimum(1, np.minimum(np.arange(n), np.arange(n)[::-1]) / (0.01 * RATE))
        audio[i0:i1] = seg * ramp
    audio += 1e-4 * rng.standard_normal(n_samp)
    n_frames = int(np.floor(bounds[-1] * FPS)) + 1
    t = np.arange(n_frames) / FPS
    idx = np.clip(np.searchsorted(bounds[1:], t, side="right"), 0, len(seq) - 1)
    params = np.array([PHONES[seq[i]][3:] for i in idx])      # (T, 4)
    params = gaussian_filter1d(params, 2.0, axis=0, mode="nearest")
    jaw, gap, rnd, llup = params.T
    m = np.repeat(NEUTRAL[None], n_frames, axis=0)
    # jaw rotates the lower face
    for k, w in [(5, 1.0), (8, 1.3), (9, 0.5), (10, 0.5), (11, 0.3)]:
        m[:, k, 1] -= w * jaw
    m[:, 5, 1] -= 0.5 * gap - llup * 0.8
    m[:, 4, 1] += 0.5 * gap
    m[:, 5, 2] += 0.3 * llup
    for k in (4, 5):
        m[:, k, 2] += rnd
    m[:, 6, 0] -= 0.8 * rnd
    m[:, 7, 0] += 0.8 * rnd
    m += 0.1 * rng.standard_normal(m.shape)
    # rigid head motion: small rotation about y and translation
    ang = 0.03 * np.sin(2 * np.pi * 0.3 * t + rng.uniform(0, 6))
    c, s = np.cos(ang), np.sin(ang)
    rot = np.zeros((n_frames, 3, 3))
    rot[:, 0, 0], rot[:, 0, 2], rot[:, 1, 1], rot[:, 2, 0], rot[:, 2, 2] = c, s, 1, -s, c
    m = np.einsum("tij,tmj->tmi", rot, m) + np.array([1.0, 2.0, -1.0]) * np.sin(t)[:, None, None]
    # a short dropout
    f0 = int(rng.integers(5, n_frames - 10))
    m[f0:f0 + 3, int(rng.integers(4, 12))] = np.nan
    phones = [PhoneSegment(float(a), float(b), p)
              for p, a, b in zip(seq, bounds[:-1], bounds[1:], strict=True)]
    return phones, audio, m


def build_toy_corpus(root: Path, n_train: int = 24, n_test: int = 8, seed: int = 0) -> Path:
    """Write the toy corpus into ``root`` and return it."""
    rng = np.random.default_rng(seed)
    root.mkdir(parents=True, exist_ok=True)
    ids = [f"toy{i:03d}" for i in range(n_train + n_test)]
    for utt_id in ids:
        phones, audio, markers = make_utterance(rng, int(rng.integers(12, 22)))
        dur = len(audio) / RATE
        write_audio(root / f"{utt_id}.wav", audio, RATE)
        write_textgrid(root / f"{utt_id}.TextGrid", {"phones": phones}, dur)
        write_c3d(root / f"{utt_id}.c3d", markers, FPS, NAMES)
    save_corpus_info(root, CorpusInfo(
        marker_names=NAMES, marker_rate=FPS, fixed_markers=FIXED, upper_lip="UL_C",
        lower_lip="LL_C", lip_corners=["LC_R", "LC_L"], train=ids[:n_train], test=ids[n_train:],
        name="toy"))
    return root
