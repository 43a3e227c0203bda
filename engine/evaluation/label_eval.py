"""Evaluation with automatic labels (issue 16): every mode and baseline on held-out sentences,
trained and tested with the corpus's exact labels, or with labels from the aligner or the
recognizer (``facetraj_engine.io.labelling``) -- the setting of a real user, who has no hand-checked labels.

For each label kind: a model trained on the training split with those labels; its robust-mode
settings cross-validated on the training split (``facetraj_engine.evaluation.tuning``); then on the test
split, with
the same kind of labels, the paper's phonetic mode (N = 3), acoustic-only (default index search),
the robust mode, and the two baselines of ``facetraj_engine.evaluation.baselines`` (viseme lookup, ridge
regression),
all scored as Table 2 (triangular smoothing, speech frames); and ``default``, what the documented
workflow does (``corpus align``, ``corpus init``, ``train``, ``eval``): the mode by the one rule
(:func:`facetraj_engine.method.modes.choose_mode`), with every default of synthesis (the chain, the label
weight by voice, the closure step). The same test sentences spoken by a second voice
(:mod:`facetraj_engine.evaluation.second_voice`; for automatic labels, labelled from its own audio) are
scored too, under ``"<kind>, second voice"``.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from ..config import SynthConfig, TrainConfig
from ..io.corpus import Corpus
from ..io.files import read_json, write_json
from ..io.labelling import label_utterance, relabelled, with_labels
from ..method.model import Model
from ..method.modes import choose_mode, tuned_config
from ..method.pipeline import synthesize
from ..method.training import train
from .baselines import fit_baselines, frame_data, score_baselines
from .scores import METRICS, UtteranceScore, evaluate_utterance, speech_mask
from .second_voice import second_voice
from .tuning import cross_validate

log = logging.getLogger(__name__)

#: The file of a saved evaluation, beside the report (``facetraj_engine.report``).
LABEL_EVAL_FILE = "label_eval.json"
#: Label kinds: the corpus's own (exact) labels, and the two automatic ones.
LABEL_KINDS = ("exact", "aligned", "recognized")
#: Methods compared, in table order.
METHODS = ("default", "robust", "phonetic", "phonetic-tuned", "acoustic", "ridge", "viseme")
#: The methods scored on the second voice too.
SECOND_VOICE_METHODS = ("default", "robust", "phonetic", "acoustic")
#: One line per method for the reader.
METHOD_NOTES = {
    "default": "the documented workflow: the mode the labels get, every default of synthesis, "
               "settings cross-validated at training",
    "robust": "issue 16's robust mode: eq 4 and acoustic candidates, label confidence weighting, "
              "acoustic context, cross-validated settings; frame by frame, no closure step",
    "phonetic": "the paper's method, N = 3",
    "phonetic-tuned": "the paper's method with the robust mode's cross-validated N and smoothing "
                      "width",
    "acoustic": "acoustic-only, default index search",
    "ridge": "ridge regression on +-5 stacked LSF frames (no labels)",
    "viseme": "mean face per phone label",
}


@dataclass
class LabelEval:
    """Per-utterance test scores of every method under each label kind, and the tunings."""

    scores: dict[str, list[UtteranceScore]] = field(default_factory=dict)
    tunings: dict[str, dict] = field(default_factory=dict)
    label_quality: dict[str, dict] = field(default_factory=dict)

    def rows(self, kind: str, method: str) -> list[UtteranceScore]:
        return [s for s in self.scores.get(kind, []) if s.mode == method]

    def summary(self, kind: str, method: str) -> dict[str, tuple[float, float]]:
        """Mean and standard deviation over test utterances of each measure."""
        rows = self.rows(kind, method)
        out = {}
        for m in METRICS:
            v = np.array([getattr(r, m) for r in rows], dtype=float)
            out[m] = (float(np.nanmean(v)), float(np.nanstd(v))) if len(v) else (np.nan, np.nan)
        return out

    def best(self, kind: str) -> str:
        """The method with the highest mean of the three measures under ``kind`` labels."""
        return max((m for m in METHODS if self.rows(kind, m)),
                   key=lambda m: np.mean([v[0] for v in self.summary(kind, m).values()]))

    def beats_all(self, kind: str, method: str = "robust") -> bool:
        """Whether ``method`` is above every other method on all three measures."""
        mine = self.summary(kind, method)
        return all(mine[m][0] > self.summary(kind, o)[m][0] for o in METHODS if o != method
                   and self.rows(kind, o) for m in METRICS)

    @classmethod
    def from_json(cls, obj: dict) -> LabelEval:
        """Read what :meth:`to_json` wrote."""
        return cls({k: [UtteranceScore(**r) for r in v] for k, v in obj["utterances"].items()},
                   dict(obj.get("tunings", {})), dict(obj.get("label_quality", {})))

    def to_json(self) -> dict:
        return {"summary": {k: {m: self.summary(k, m) for m in METHODS if self.rows(k, m)}
                            for k in self.scores},
                "tunings": self.tunings, "label_quality": self.label_quality,
                "utterances": {k: [asdict(s) for s in v] for k, v in self.scores.items()}}


def labelled_corpus(corpus: Corpus, kind: str,
                    progress: Callable[[float, str], None] | None = None) -> Corpus:
    """``corpus`` itself (``exact``), or relabelled by the aligner or the recognizer (cached)."""
    if kind == "exact":
        return corpus
    return relabelled(corpus, kind, progress=progress)


def evaluate_kind(corpus: Corpus, kind: str, train_config: TrainConfig | None = None,
                  model: Model | None = None, tune: bool = True, max_test: int | None = None,
                  progress: Callable[[float, str], None] | None = None, second: bool = False):
    """Train (unless ``model`` is given), cross-validate and score every method on the test split
    of ``corpus`` labelled by ``kind``: ``(scores, tuning)``, and with ``second`` the second
    voice's scores as a third item."""
    lab = labelled_corpus(corpus, kind)
    if model is None:
        if progress:
            progress(0.0, f"{kind}: training")
        model = train(lab, config=train_config)
    tuning = cross_validate(lab, train_config) if tune else None
    if tuning is not None:
        model = replace(model, tuned=tuning.to_json())       # as `facetraj train` stores it
    configs = method_configs(model)
    test = list(lab.info.test)
    if max_test is not None and len(test) > max_test:
        test = [test[int(i)] for i in np.linspace(0, len(test) - 1, max_test)]
    scores: list[UtteranceScore] = []
    baselines = fit_baselines(model, (frame_data(model, lab.utterance(u), keep_original=False)
                                      for u in lab.info.train), len(lab.info.train))
    baseline_scores: list[UtteranceScore] = []
    for j, utt_id in enumerate(test):
        if progress:
            progress(j / max(len(test), 1), f"{kind}: {utt_id}")
        utt = lab.utterance(utt_id)
        scores.extend(score_methods(model, utt, configs))
        baseline_scores.extend(score_baselines(model, baselines, frame_data(model, utt), "test",
                                               ("triangular",)))
    scores.extend(baseline_scores)
    if second:
        return scores, tuning, second_voice_scores(model, lab, kind, test, progress)
    return scores, tuning


def method_configs(model: Model) -> dict[str, SynthConfig | None]:
    """The synthesis of each method (``None``: the documented workflow's, by the mode rule)."""
    robust = tuned_config(SynthConfig(mode="robust", closure=False, chain_beta=0.0,   # issue 16's
                                      label_weight_by_voice=False), model.tuned, keep=("chain_beta",))
    return {"default": None, "robust": robust,
            "phonetic": SynthConfig(mode="phonetic", closure=False),
            "acoustic": SynthConfig(mode="acoustic", closure=False),
            "phonetic-tuned": phonetic_tuned(robust)}


def score_methods(model: Model, utt, configs: dict[str, SynthConfig | None]) -> list[UtteranceScore]:
    """One utterance's scores under every method of ``configs`` (triangular smoothing)."""
    original = model.normalise_markers(utt.markers)
    speech = speech_mask(utt.audio, utt.sample_rate, utt.frame_times())
    lsf = model.input_lsf(utt.audio, utt.sample_rate, np.arange(utt.n_frames) / model.marker_rate)
    out = []
    for name, cfg in configs.items():
        if cfg is None:
            cfg = choose_mode(SynthConfig(), utt.phones, utt.provenance, tuned=model.tuned).config
        res = synthesize(model, utt.audio, utt.sample_rate, utt.phones, cfg, n_frames=utt.n_frames,
                         source=utt.name, lsf=lsf, confidence=utt.confidence,
                         provenance=utt.provenance)
        out.extend(replace(r, mode=name) for r in evaluate_utterance(
            model, utt, "test", cfg, ("triangular",), synthesis=res, original=original,
            speech=speech))
    return out


def second_voice_scores(model: Model, lab: Corpus, kind: str, test: Sequence[str],
                        progress: Callable[[float, str], None] | None = None
                        ) -> list[UtteranceScore]:
    """The test sentences spoken by the second voice (same timing, so the same markers), labelled
    from their own audio as ``kind`` says (exact labels stay; a sentence that does not align is
    recognized, as ``corpus align`` does), under :data:`SECOND_VOICE_METHODS`."""
    configs = {k: v for k, v in method_configs(model).items() if k in SECOND_VOICE_METHODS}
    out = []
    for j, utt_id in enumerate(test):
        if progress:
            progress(j / max(len(test), 1), f"{kind}, second voice: {utt_id}")
        utt = lab.utterance(utt_id)
        utt = replace(utt, audio=second_voice(utt.audio, utt.sample_rate))
        if kind != "exact":
            utt = with_labels(utt, label_utterance(utt, kind)[0])
        out.extend(score_methods(model, utt, configs))
    return out


def phonetic_tuned(robust: SynthConfig) -> SynthConfig:
    """The paper's phonetic mode with the robust config's N and smoothing width (the ablation that
    separates what cross-validating N and the width gives from what the robust search gives).

    >>> c = phonetic_tuned(SynthConfig(mode="robust", n_context_phones=6, triangle_s=0.067))
    >>> (c.mode, c.n_context_phones, c.triangle_s, c.xi)
    ('phonetic', 6, 0.067, 20.0)
    """
    return SynthConfig(mode="phonetic", closure=False, n_context_phones=robust.n_context_phones,
                       triangle_s=robust.triangle_s, xi=robust.xi, gamma_max=robust.gamma_max)


def evaluate_labels(corpus: Corpus, kinds: Sequence[str] = LABEL_KINDS,
                    train_config: TrainConfig | None = None, exact_model: Model | None = None,
                    tune: bool = True, max_test: int | None = None,
                    progress: Callable[[float, str], None] | None = None) -> LabelEval:
    """:func:`evaluate_kind` for every label kind (``exact_model``: an already trained model for
    the exact labels)."""
    out = LabelEval()
    for k, kind in enumerate(kinds):
        if progress:
            progress(k / len(kinds), f"{kind} labels")
        scores, tuning, voice2 = evaluate_kind(corpus, kind, train_config,
                                               exact_model if kind == "exact" else None, tune,
                                               max_test, second=True)
        out.scores[kind] = scores
        out.scores[f"{kind}, second voice"] = voice2
        if tuning is not None:
            out.tunings[kind] = tuning.to_json()
    if progress:
        progress(1.0, "done")
    return out


def write_label_eval(path: str | os.PathLike[str], result: LabelEval) -> Path:
    """Save ``result`` as JSON (read by the report generator, ``facetraj_engine.report``)."""
    return write_json(path, result.to_json())


def read_label_eval(path: str | os.PathLike[str]) -> LabelEval | None:
    """The saved evaluation at ``path``, or ``None`` when there is none."""
    data = read_json(path)
    return None if data is None else LabelEval.from_json(data)


def mean_sd(v: tuple[float, float]) -> str:
    """A table cell: mean ± standard deviation.

    >>> mean_sd((0.87254, 0.0491))
    '0.8725 ± 0.05'
    """
    return f"{v[0]:.4f} ± {v[1]:.2f}"


def format_markdown(result: LabelEval) -> str:
    """The results.md section: one table per label kind and a plain recommendation."""
    lines = ["Held-out (test) sentences only. Exact labels are the corpus's own; aligned labels come "
             "from PocketSphinx forced alignment of each sentence's text, recognized ones from its "
             "phone recognizer without text (`facetraj_engine.io.labelling`, cached). For each kind of "
             "labels "
             "the model is trained on the training split labelled the same way, the robust mode's "
             "settings are cross-validated on the training split (`facetraj_engine.evaluation.tuning`), and "
             "every "
             "method is scored on the test split as in Table 2 (triangular smoothing, speech "
             "frames), mean ± one standard deviation over utterances (the corpus has one speaker, "
             "so the spread is over utterances). *Second voice*: the same test sentences spoken by "
             "a voice with a shorter vocal tract and a higher pitch "
             "(`facetraj_engine.evaluation.second_voice`, "
             "the same timing, so the same markers), its automatic labels made from its own audio, "
             "synthesized with the same model. Computed by `facetraj_engine.evaluation.label_eval` "
             "(`facetraj report --automatic-labels`)."]
    for kind in result.scores:
        lines += ["", f"**{kind.title()} labels** (train and test labelled the same way)", "",
                  "| Method | Whole face | Lower lip | Upper lip | Utterances |",
                  "|---|---:|---:|---:|---:|"]
        for m in METHODS:
            rows = result.rows(kind, m)
            if not rows:
                continue
            s = result.summary(kind, m)
            lines.append(f"| {m} ({METHOD_NOTES[m]}) | {mean_sd(s['whole_face'])} | "
                         f"{mean_sd(s['lower_lip'])} | {mean_sd(s['upper_lip'])} | {len(rows)} |")
        lines += tuning_lines(result.tunings.get(kind, {}))
    lines += ["", recommendation(result)]
    return "\n".join(lines)


def tuning_lines(tuning: dict) -> list[str]:
    """The settings cross-validation chose, and each one's curve: its held-out score at every
    value tried with the others at their chosen values (the chosen value in bold).

    >>> text = tuning_lines({"settings": {"chain_beta": 0.1, "triangle_s": 0.067},
    ...                      "curves": {"chain_beta": [[0.03, 0.91], [0.1, 0.92], [0.2, 0.915]]}})[1]
    >>> text.split(": ", 2)[2]
    'chain_beta 0.03: 0.9100, **0.1: 0.9200**, 0.2: 0.9150.'
    """
    settings = tuning.get("settings")
    if not settings:
        return []
    text = ("Settings chosen by cross-validation on the training split: "
            + ", ".join(f"{k} = {v:g}" for k, v in settings.items()) + ".")
    curves = tuning.get("curves") or {}
    if curves:
        text += " Cross-validation curves (mean held-out correlation): " + "; ".join(
            f"{name} " + ", ".join(f"**{v:g}: {s:.4f}**" if v == settings.get(name) else f"{v:g}: {s:.4f}"
                                   for v, s in curve) for name, curve in curves.items()) + "."
    if tuning.get("at_end"):
        text += f" At the end of their range: {', '.join(tuning['at_end'])}."
    return ["", text]


def plain_advice(result: LabelEval) -> str:
    """The advice in one sentence, with the numbers behind its last part (recognized labels
    against acoustic-only, on the training voice and on the second voice)."""
    text = ("Use the default, what every command does: hand-checked labels get the paper's "
            "phonetic mode, aligned or recognized labels the robust mode, and a recording without "
            "labels has its phones recognized first")
    vs = []
    for kind, voice in (("recognized", "the training voice"),
                        ("recognized, second voice", "the second voice")):
        if result.rows(kind, "default") and result.rows(kind, "acoustic"):
            d, a = (result.summary(kind, m)["whole_face"][0] for m in ("default", "acoustic"))
            vs.append(f"{d:.3f} against {a:.3f} on {voice}")
    return text + (f" (recognized labels and the default against acoustic-only, whole face: "
                   f"{'; '.join(vs)})." if vs else ".")


def recommendation(result: LabelEval) -> str:
    """Which mode to pick for which labels, said from the numbers, with how much of the robust
    mode's gain over the paper's mode the cross-validated N and smoothing alone give."""
    parts, gains = [], []
    for kind in result.scores:
        best = result.best(kind)
        beats = result.beats_all(kind)
        parts.append(f"with {kind} labels, **{best}**"
                     + (" (above every other method on whole face and both lips)" if beats
                        else " (best on the mean of the three measures, not on each)"))
        if result.rows(kind, "robust") and result.rows(kind, "phonetic") and \
                result.rows(kind, "phonetic-tuned"):
            r, p, t = (result.summary(kind, m)["whole_face"][0]
                       for m in ("robust", "phonetic", "phonetic-tuned"))
            gains.append(f"{kind}: robust {r - p:+.4f} over the paper's mode, of which "
                         f"{t - p:+.4f} from the cross-validated N and smoothing alone")
    joined = "; ".join(parts)
    text = "**Which mode to pick.** " + plain_advice(result) + " Best per table: " + joined + "."
    if gains:
        text += " Whole face, " + "; ".join(gains) + "."
    return text
