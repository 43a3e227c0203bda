"""Acoustic-only synthesis from a voice other than the training voice, with and without speaker
normalisation (issue 13).

The model is trained on the training split (the training voice). Each test sentence is then
spoken by a second voice (``facetraj_engine.evaluation.second_voice``: the same recording with a shorter vocal tract's
formants and a higher pitch, timing unchanged, so the original face markers still line up) and
synthesized acoustic-only (the default index search) with the input LSFs left alone
(``speaker_warp = 1.0``), warped by a factor chosen per utterance (``speaker_warp = None``), or
by one factor chosen once for the voice over all its test sentences. The training voice goes
through the same three conditions, so that what normalisation costs a matching voice shows too.
Everything is scored as Table 2 (triangular smoothing, speech frames of the original recording).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from ..config import SynthConfig, TrainConfig
from ..io.corpus import Corpus
from ..io.files import read_json, write_json
from ..method.model import Model
from ..method.pipeline import synthesize
from ..method.speaker import choose_warp
from ..method.training import train
from .label_eval import mean_sd
from .scores import METRICS, UtteranceScore, evaluate_utterance, speech_mask
from .second_voice import VoiceSpec, median_ratios, second_voice, voice_ratios

log = logging.getLogger(__name__)

#: The file of a saved evaluation, beside the report (``facetraj_engine.report``).
VOICE_EVAL_FILE = "voice_eval.json"
#: The voices: the corpus's own (training) voice and the second voice made from it.
VOICES = ("training", "second")
#: Speaker normalisation: none (``speaker_warp = 1.0``), a warp chosen per utterance
#: (``speaker_warp = None``), or one warp chosen for the voice over all its test sentences.
NORMALISATIONS = ("none", "utterance", "speaker")
#: One line per normalisation for the reader.
NORMALISATION_NOTES = {"none": "no normalisation (`speaker_warp = 1.0`)",
                       "utterance": "warp chosen per utterance (`speaker_warp = None`)",
                       "speaker": "one warp chosen for the voice over all its test sentences"}
#: How many frames (evenly spaced over all test sentences) choose the per-voice warp.
SPEAKER_FRAMES = 2000


def condition(voice: str, normalisation: str) -> str:
    """The name of one condition (the ``mode`` of its scores).

    >>> condition("second", "utterance")
    'second/utterance'
    """
    return f"{voice}/{normalisation}"


@dataclass
class VoiceEval:
    """Per-utterance test scores of each voice under each normalisation, the warps chosen, and
    what the second voice is (its spec and its measured formant and F0 ratios).

    Attributes
    ----------
    scores : condition (:func:`condition`) -> per-utterance scores.
    warps : condition -> utterance -> the warp factor applied.
    voice : the second voice: ``spec`` (:class:`~facetraj_engine.evaluation.second_voice.VoiceSpec` as a dict) and
        ``ratios``, the median over test utterances of :func:`~facetraj_engine.evaluation.second_voice.voice_ratios`.
    """

    scores: dict[str, list[UtteranceScore]] = field(default_factory=dict)
    warps: dict[str, dict[str, float]] = field(default_factory=dict)
    voice: dict = field(default_factory=dict)

    def summary(self, cond: str) -> dict[str, tuple[float, float]]:
        """Mean and standard deviation over test utterances of each measure."""
        rows = self.scores.get(cond, [])
        out = {}
        for m in METRICS:
            v = np.array([getattr(r, m) for r in rows], dtype=float)
            out[m] = (float(np.nanmean(v)), float(np.nanstd(v))) if len(v) else (np.nan, np.nan)
        return out

    def warp_summary(self, cond: str) -> tuple[float, float, float, float]:
        """Median, minimum, maximum and mean of the warps applied under ``cond``."""
        v = np.array(list(self.warps.get(cond, {}).values()), dtype=float)
        if not len(v):
            return (np.nan,) * 4
        return float(np.median(v)), float(v.min()), float(v.max()), float(v.mean())

    @classmethod
    def from_json(cls, obj: dict) -> VoiceEval:
        """Read what :meth:`to_json` wrote."""
        return cls({k: [UtteranceScore(**r) for r in v] for k, v in obj["utterances"].items()},
                   {k: dict(v) for k, v in obj.get("warps", {}).items()}, dict(obj.get("voice", {})))

    def to_json(self) -> dict:
        return {"summary": {k: self.summary(k) for k in self.scores},
                "voice": self.voice, "warps": self.warps,
                "utterances": {k: [asdict(s) for s in v] for k, v in self.scores.items()}}


def held_out_ids(corpus: Corpus, max_test: int | None = None) -> list[str]:
    """The test split, or ``max_test`` utterances evenly spread over it."""
    test = list(corpus.info.test)
    if max_test is not None and len(test) > max_test:
        test = [test[int(i)] for i in np.linspace(0, len(test) - 1, max_test)]
    return test


def evaluate_voices(corpus: Corpus, model: Model | None = None, spec: VoiceSpec | None = None,
                    train_config: TrainConfig | None = None, max_test: int | None = None,
                    progress: Callable[[float, str], None] | None = None) -> VoiceEval:
    """Train on the training split (unless ``model`` is given) and score acoustic-only synthesis
    of every voice and normalisation on the test split (module docstring)."""
    spec = spec or VoiceSpec()
    if model is None:
        if progress:
            progress(0.0, "training")
        model = train(corpus, config=train_config)
    test = held_out_ids(corpus, max_test)
    base = SynthConfig(mode="acoustic", closure=False)
    prepared, ratios = [], []
    for j, utt_id in enumerate(test):
        if progress:
            progress(0.5 * j / max(len(test), 1), f"second voice: {utt_id}")
        utt = corpus.utterance(utt_id)
        times = np.arange(utt.n_frames) / model.marker_rate
        other = second_voice(utt.audio, utt.sample_rate, spec)
        ratios.append(voice_ratios(utt.audio, other, utt.sample_rate))
        lsf = {"training": model.input_lsf(utt.audio, utt.sample_rate, times),
               "second": model.input_lsf(other, utt.sample_rate, times)}
        audio = {"training": utt.audio, "second": other}
        prepared.append((utt, lsf, audio))
    speaker = {v: choose_warp(np.concatenate([p[1][v] for p in prepared]), model.codebook.lsf,
                              max_frames=SPEAKER_FRAMES) for v in VOICES}
    spec_json = {**asdict(spec), "formant_factors": [list(p) for p in spec.formant_factors]}
    out = VoiceEval(voice={"spec": spec_json, "ratios": median_ratios(ratios),
                           "speaker_warps": speaker})
    for j, (utt, lsf, audio) in enumerate(prepared):
        if progress:
            progress(0.5 + 0.5 * j / max(len(prepared), 1), f"synthesis: {utt.name}")
        original = model.normalise_markers(utt.markers)
        speech = speech_mask(utt.audio, utt.sample_rate, utt.frame_times())  # the original's frames
        for v in VOICES:
            for norm, warp in (("none", 1.0), ("utterance", None), ("speaker", speaker[v])):
                cfg = base.with_(speaker_warp=warp)
                res = synthesize(model, audio[v], utt.sample_rate, None, cfg, n_frames=utt.n_frames,
                                 source=utt.name, lsf=lsf[v])
                name = condition(v, norm)
                out.warps.setdefault(name, {})[utt.name] = res.warp
                out.scores.setdefault(name, []).extend(replace(r, mode=name) for r in
                                                       evaluate_utterance(
                    model, utt, "test", cfg, ("triangular",), synthesis=res, original=original,
                    speech=speech))
    if progress:
        progress(1.0, "done")
    return out


def write_voice_eval(path: str | os.PathLike[str], result: VoiceEval) -> Path:
    """Save ``result`` as JSON (read by the report generator, ``facetraj_engine.report``)."""
    return write_json(path, result.to_json())


def read_voice_eval(path: str | os.PathLike[str]) -> VoiceEval | None:
    """The saved evaluation at ``path``, or ``None`` when there is none."""
    data = read_json(path)
    return None if data is None else VoiceEval.from_json(data)


# --------------------------------------------------------------------------- the report's text
def _factors(spec: dict) -> str:
    return ", ".join(f"x {k:g} at {f:g} Hz" for f, k in spec["formant_factors"])


def voice_paragraph(result: VoiceEval) -> str:
    """What the second voice is, how it was made and what was measured on it."""
    spec, r = result.voice.get("spec", {}), result.voice.get("ratios", {})
    text = ("**The second voice.** VocalTractLab could not make it (changing the JD3 speaker's "
            "anatomy crashed it or froze the vocal tract in one shape), so it is made from each "
            "test recording by signal processing (`facetraj_engine.evaluation.second_voice.second_voice`): LPC "
            "analysis-synthesis every 5 ms, the formants (LPC pole frequencies) moved by a "
            "nonuniform map, as Fant's female/male scale factors are ")
    if spec:
        text += (f"({_factors(spec)}, linear in between, back to the identity from "
                 f"{spec['top_hz']:g} Hz to the Nyquist frequency), and the excitation's pitch "
                 f"raised x {spec['f0_factor']:g} (resampling, then WSOLA back to its length)")
    text += (". The timing is kept sample for sample, so the original face markers still belong "
             "to it. It is the training talker's articulation with a shorter vocal tract's "
             "formants and a higher voice, not an independent speaker: it measures the formant "
             "and pitch mismatch alone.")
    if r:
        text += (f" Measured on the test sentences (median over utterances of the median over "
                 f"frames, LPC formants and autocorrelation F0 against the original): F1 x "
                 f"{r['F1']:.3f}, F2 x {r['F2']:.3f}, F3 x {r['F3']:.3f}, F0 x {r['F0']:.3f}; "
                 f"peak level {r['peak']:.2f} (no clipping), same length "
                 f"{'in every utterance' if r['same_length'] == 1.0 else 'NOT in every utterance'}.")
    return text


def table_lines(result: VoiceEval) -> list[str]:
    """The table: every voice and normalisation, whole face and both lips."""
    lines = ["| Voice | Normalisation | Whole face | Lower lip | Upper lip | Utterances |",
             "|---|---|---:|---:|---:|---:|"]
    for v in VOICES:
        for n in NORMALISATIONS:
            rows = result.scores.get(condition(v, n), [])
            if not rows:
                continue
            s = result.summary(condition(v, n))
            lines.append(f"| {v} | {NORMALISATION_NOTES[n]} | {mean_sd(s['whole_face'])} | "
                         f"{mean_sd(s['lower_lip'])} | {mean_sd(s['upper_lip'])} | {len(rows)} |")
    return lines


def warps_paragraph(result: VoiceEval) -> str:
    """The warps chosen, per utterance and per voice."""
    parts = []
    for v in VOICES:
        med, lo, hi, _ = result.warp_summary(condition(v, "utterance"))
        sp = result.voice.get("speaker_warps", {}).get(v)
        if np.isfinite(med):
            parts.append(f"the {v} voice: per utterance median {med:.2f} (range {lo:.2f} to "
                         f"{hi:.2f})" + (f", per voice {sp:.2f}" if sp is not None else ""))
    spec = result.voice.get("spec")
    ideal = ""
    if spec:
        ks = [k for _, k in spec["formant_factors"]]
        ideal = (f" The warp that would undo the second voice's formant map lies between "
                 f"1/{max(ks):g} = {1 / max(ks):.2f} and 1/{min(ks):g} = {1 / min(ks):.2f}.")
    return "**Warps chosen** (grid 0.76 ... 1.20): " + "; ".join(parts) + "." + ideal


def verdict_paragraph(result: VoiceEval) -> str:
    """What the normalisation buys on the second voice and costs on the training voice, said from
    the numbers."""
    def whole(v: str, n: str) -> float:
        return result.summary(condition(v, n))["whole_face"][0]

    tr, sn, su = whole("training", "none"), whole("second", "none"), whole("second", "utterance")
    ss = whole("second", "speaker")
    drop = tr - sn
    text = (f"**What it says.** Whole face, the second voice without normalisation scores "
            f"{sn:.4f} against the training voice's {tr:.4f} ({-drop:+.4f}). ")
    gains = [(su - sn, "per-utterance warp")]
    if np.isfinite(ss):
        gains.append((ss - sn, "per-voice warp"))
    said = []
    for g, name in gains:
        share = f", {100 * g / drop:.0f} % of the loss" if drop > 0 and g > 0 else ""
        said.append(f"the {name} {'adds' if g > 0 else 'changes it by'} {g:+.4f}{share}")
    text += "With normalisation " + "; ".join(said) + ". "
    best = max(gains)[0]
    if best <= 0:
        text += "Normalisation does not help this voice. "
    elif best < 0.01:
        text += "Normalisation helps this voice only slightly (less than 0.01). "
    else:
        text += "Normalisation recovers part of what the voice mismatch costs. "
    tn, tu = whole("training", "none"), whole("training", "utterance")
    text += (f"On the training voice itself the per-utterance warp changes the whole-face "
             f"correlation by {tu - tn:+.4f}.")
    return text


def format_markdown(result: VoiceEval) -> str:
    """The results.md section's body: one paragraph per function above and the table."""
    intro = ("Held-out (test) sentences only: acoustic-only synthesis (the default index search) "
             "by the model trained on the training split, from the training voice and from a "
             "second voice made from the same recordings, each without speaker normalisation, "
             "with a warp chosen per utterance and with one warp chosen per voice "
             "(`engine/method/speaker.py`), scored as in Table 2 (triangular smoothing, speech frames of "
             "the original recording), mean ± one standard deviation over utterances. Computed "
             "by `facetraj_engine.evaluation.voice_eval` (`facetraj report --second-voice`).")
    return "\n\n".join([intro, voice_paragraph(result), "\n".join(table_lines(result)),
                        warps_paragraph(result), verdict_paragraph(result)])
