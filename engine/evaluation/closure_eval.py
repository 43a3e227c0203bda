"""Lips that close, measured for the report (issue 25): the closure of every synthesis mode and
label source on the default corpus's held-out sentences (with their correlations) and on real
voices the model was not trained on (CMU ARCTIC sentences, speech only), each synthesized the way
the commands do it (:func:`facetraj_engine.method.recording.synthesize_recording` is ``facetraj synth``;
:func:`facetraj_engine.streaming.live.stream_file` is ``facetraj live --from-file``, with phones
recognized as they are spoken or ``--acoustic-only``).

The measure is :mod:`facetraj_engine.evaluation.closure`: /p b m/ within 1 mm of the training talker's
closed aperture, the median minimum at /p b m/, the median vowel maximum and the median pause
aperture. On the corpus the reference labels are its exact ones; on the ARCTIC sentences, their
transcripts aligned, whatever labels the synthesis itself was given.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import SynthConfig
from ..data import PhoneSegment
from ..io.audio import read_audio
from ..io.corpus import Corpus
from ..io.files import read_json, write_json
from ..io.labelling import label_audio, read_transcript, relabelled
from ..method.model import Model
from ..method.modes import choose_mode
from ..method.pipeline import Synthesis, synthesize
from ..method.recording import LabelRequest, synthesize_recording
from ..streaming.live import LiveConfig, stream_file
from ..streaming.recognizer import RecognizerConfig, RunningCmn
from .closure import ClosureScore, closure_score, lip_aperture
from .scores import speech_mask, trajectory_correlations

CLOSURE_EVAL_FILE = "closure_eval.json"
#: The real voices of the report, read from ``../shared`` when present (never copied).
ARCTIC_DIR = "data/arctic_samples"
#: The aims of issue 25: /p b m/ within 1 mm, default mode.
AIMS = {"corpus exact": 0.9, "arctic aligned": 0.8, "arctic recognized": 0.7,
        "arctic acoustic": 0.5, "vowel max mm": 17.0}


@dataclass
class ClosureRow:
    """One condition: its data set, labels, how it was synthesized, the closure score and (on
    the corpus) the Table 2 correlations."""

    data: str
    labels: str
    synthesis: str
    score: dict
    correlations: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"data": self.data, "labels": self.labels, "synthesis": self.synthesis,
                **self.score, **{f"r_{k}": v for k, v in self.correlations.items()}}


@dataclass
class ClosureEval:
    """Every row, and the closed aperture they are measured against."""

    closed: float
    rows: list[ClosureRow] = field(default_factory=list)

    def to_json(self) -> dict:
        return {"closed": self.closed, "rows": [r.to_json() for r in self.rows]}


# --------------------------------------------------------------------------- the corpus
#: Corpus conditions: (labels, synthesis shown, config, mode chosen by the rule).
CORPUS_CONDITIONS = (
    ("exact", "default (phonetic + closure step)", SynthConfig(), True),
    ("exact", "the paper's phonetic mode", SynthConfig(closure=False), False),
    ("exact", "the paper's phonetic mode, spline", SynthConfig(closure=False, smoothing="spline"), False),
    ("exact", "the paper's phonetic mode, no smoothing", SynthConfig(closure=False, smoothing="none"), False),
    ("aligned", "default (robust + closure step)", SynthConfig(), True),
    ("aligned", "the paper's phonetic mode", SynthConfig(closure=False), False),
    ("recognized", "default (robust + closure step)", SynthConfig(), True),
    ("recognized", "the paper's phonetic mode", SynthConfig(closure=False), False),
    ("none", "acoustic-only (paper)", SynthConfig(mode="acoustic", closure=False), False),
    ("none", "acoustic-only + rest in pauses (--mode acoustic)", SynthConfig(mode="acoustic"), False),
)


def _scored(model: Model, res: Synthesis, reference: Sequence[PhoneSegment], utt=None
            ) -> tuple[ClosureScore, dict]:
    aperture = lip_aperture(res.markers, model.upper_lip, model.lower_lip)
    score = closure_score(aperture, res.times, reference, model.closure.closed)
    if utt is None or utt.markers is None:
        return score, {}
    mask = speech_mask(utt.audio, utt.sample_rate, res.times)
    return score, trajectory_correlations(model.normalise_markers(utt.markers), res.markers, mask,
                                          model)


def corpus_rows(model: Model, corpus: Corpus, progress: Callable[[float, str], None]
                ) -> list[ClosureRow]:
    """The held-out sentences under every condition of :data:`CORPUS_CONDITIONS`."""
    by_kind = {"exact": corpus, "none": corpus}
    rows = []
    for k, (kind, name, cfg, rule) in enumerate(CORPUS_CONDITIONS):
        progress(k / len(CORPUS_CONDITIONS), f"closure: {kind}, {name}")
        if kind not in by_kind:
            by_kind[kind] = relabelled(corpus, kind, split="test")
        lab = by_kind[kind]
        scores, cors = [], []
        for utt_id in lab.info.test:
            ref, utt = corpus.utterance(utt_id), lab.utterance(utt_id)
            phones = None if kind == "none" else utt.phones
            c = choose_mode(cfg, phones, utt.provenance, tuned=model.tuned).config if rule else cfg
            res = synthesize(model, utt.audio, utt.sample_rate, phones, c, n_frames=utt.n_frames,
                             source=utt.name, confidence=utt.confidence, provenance=utt.provenance)
            s, r = _scored(model, res, ref.phones, utt)
            scores.append(s)
            cors.append([r[m] for m in ("whole_face", "lower_lip", "upper_lip")])
        mean = np.nanmean(np.array(cors), axis=0)
        rows.append(ClosureRow(f"{corpus.root.name} test", kind, name,
                               ClosureScore.pooled(scores).to_json(),
                               dict(zip(("whole_face", "lower_lip", "upper_lip"), mean.tolist(),
                                        strict=True))))
    return rows


# --------------------------------------------------------------------------- real voices
#: ARCTIC conditions: (labels, synthesis shown, label request, config, explicit mode).
ARCTIC_CONDITIONS = (
    ("aligned", "default (robust + closure step)", "transcript", SynthConfig(), False),
    ("aligned", "the paper's phonetic mode", "transcript", SynthConfig(closure=False), True),
    ("recognized", "default (robust + closure step)", "recognize", SynthConfig(), False),
    ("recognized", "the paper's phonetic mode", "recognize", SynthConfig(closure=False), True),
    ("none", "default: synth with the recording alone (recognizes its phones)", "alone",
     SynthConfig(), False),
    ("none", "acoustic-only + rest in pauses (--mode acoustic)", "none",
     SynthConfig(mode="acoustic"), True),
    ("none", "acoustic-only (paper)", "none", SynthConfig(mode="acoustic", closure=False), True),
)


#: Live mode's conditions on the ARCTIC samples: (synthesis shown, its settings, synthesis
#: settings, the recordings as takes of one session). The three after the first take one running
#: adaptation away each (issue 27: live mode adapts only where that helps real voices).
LIVE_CONDITIONS = (
    ("live mode (facetraj live --from-file): phones + acoustics", LiveConfig(), SynthConfig(),
     False),
    ("live mode, the label weight not scaled by the running voice ratio", LiveConfig(),
     SynthConfig(label_weight_by_voice=False), False),
    ("live mode, the plain running cepstral mean", LiveConfig(
        recognizer=RecognizerConfig(cmn_speech_share=None)), SynthConfig(), False),
    ("live mode, PocketSphinx's own live cepstral mean", LiveConfig(
        recognizer=RecognizerConfig(cmn_every=None)), SynthConfig(), False),
    ("live mode, the six as takes of one Live window (cepstral mean kept)", LiveConfig(),
     SynthConfig(), True),
    ("live mode, acoustic-only (--acoustic-only)", LiveConfig(phones=False), SynthConfig(), False),
)
#: Live mode's audio blocks (a typical audio callback).
LIVE_BLOCK_S = 0.01


def arctic_references(folder: Path) -> dict[Path, tuple[np.ndarray, int, list[PhoneSegment]]]:
    """Each recording of ``folder`` (with its ``.txt``): its audio, rate and reference phones
    (the transcript aligned)."""
    refs = {}
    for w in sorted(folder.glob("*.wav")):
        audio, rate = read_audio(w)
        refs[w] = (audio, rate, label_audio(audio, rate, "aligned",
                                            read_transcript(w.with_suffix(".txt")), source=w).phones)
    return refs


def live_closure(model: Model, refs: dict[Path, tuple[np.ndarray, int, list[PhoneSegment]]],
                 config: LiveConfig, block_s: float = LIVE_BLOCK_S,
                 synth: SynthConfig | None = None, session: bool = False) -> ClosureScore:
    """The closure of the recordings of ``refs`` streamed as ``facetraj live --from-file
    --as-fast-as-possible`` streams them (blocks of ``block_s``), each from a cold start, or
    (``session``) one after the other as takes of one Live window, which keeps the recognizer's
    running cepstral mean from take to take."""
    scores = []
    cmn = RunningCmn(prior_frames=config.recognizer.cmn_prior_frames,
                     speech_share=config.recognizer.cmn_speech_share) if session else None
    for audio, rate, ref in refs.values():
        frames = stream_file(model, audio, rate, block_s, synth, config, cmn=cmn).frames
        aperture = lip_aperture(frames.markers, model.upper_lip, model.lower_lip)
        scores.append(closure_score(aperture, frames.times, ref, model.closure.closed))
    return ClosureScore.pooled(scores)


def arctic_rows(model: Model, folder: Path, progress: Callable[[float, str], None]) -> list[ClosureRow]:
    """The recordings of ``folder`` (each with its ``.txt``) under every condition of
    :data:`ARCTIC_CONDITIONS`, through ``facetraj synth``'s path, and through live mode's
    (:data:`LIVE_CONDITIONS`)."""
    refs = arctic_references(folder)
    rows = []
    steps = len(ARCTIC_CONDITIONS) + len(LIVE_CONDITIONS)
    for k, (kind, name, how, cfg, explicit) in enumerate(ARCTIC_CONDITIONS):
        progress(k / steps, f"closure: ARCTIC {kind}, {name}")
        scores = []
        for w, (audio, rate, ref) in refs.items():
            request = LabelRequest(transcript=w.with_suffix(".txt") if how == "transcript" else None,
                                   recognize=how == "recognize")
            with tempfile.TemporaryDirectory() as alone:     # the recording without its .txt
                path = Path(alone) / w.name if how == "alone" else w
                if how == "alone":
                    shutil.copyfile(w, path)
                done = synthesize_recording(model, path, cfg, request, explicit=explicit,
                                            audio=(audio, rate))
            scores.append(_scored(model, done.synthesis, ref)[0])
        rows.append(ClosureRow(folder.name, kind, name, ClosureScore.pooled(scores).to_json()))
    for k, (name, config, synth, session) in enumerate(LIVE_CONDITIONS):
        progress((len(ARCTIC_CONDITIONS) + k) / steps, f"closure: ARCTIC, {name}")
        score = live_closure(model, refs, config, synth=synth, session=session)
        rows.append(ClosureRow(folder.name, "recognized, streamed" if config.phones else "none",
                               name, score.to_json()))
    return rows


def evaluate_closure(model: Model, corpus: Corpus, arctic: str | os.PathLike[str] | None = None,
                     progress: Callable[[float, str], None] | None = None) -> ClosureEval:
    """Every condition on ``corpus``'s test split, and on the recordings of ``arctic`` when
    given (a folder of ``.wav`` with their ``.txt``)."""
    progress = progress or (lambda f, m: None)
    if model.closure is None:
        raise ValueError("the model has no closure statistics: train it again")
    out = ClosureEval(model.closure.closed, corpus_rows(model, corpus, lambda f, m: progress(0.7 * f, m)))
    if arctic is not None and Path(arctic).is_dir():
        out.rows += arctic_rows(model, Path(arctic), lambda f, m: progress(0.7 + 0.3 * f, m))
    progress(1.0, "closure: done")
    return out


def write_closure_eval(path: str | os.PathLike[str], result: ClosureEval) -> Path:
    return write_json(path, result.to_json())


def read_closure_eval(path: str | os.PathLike[str]) -> dict | None:
    """The saved evaluation (its JSON) at ``path``, or ``None``."""
    return read_json(path)


# --------------------------------------------------------------------------- the report section
def format_markdown(data: dict) -> list[str]:
    """The report's section "Lips that close"."""
    lines = ["## Lips that close (issue 25)", "",
             f"The lip aperture (upper-lip centre y minus lower-lip centre y) at its smallest inside "
             f"each /p b m/, against the training talker's closed aperture, "
             f"{data['closed']:.1f} mm (the median of the original markers' minima at the "
             f"training /p b m/). *Within 1 mm*: the share of /p b m/ that close to within 1 mm; "
             f"beside it the median minimum, the median over vowels of each vowel's largest "
             f"aperture (lips that stay shut cannot pass) and the median aperture in pauses over "
             f"150 ms. The *closure step* (`engine/method/closure.py`) runs after eq 8 and the "
             f"smoothing: the lips close at the labelled /p b m/ (recognized ones trusted as far "
             f"as the voice is not the training voice) and the face rests in pauses. Computed by "
             f"`facetraj report --closure` (`engine/evaluation/closure_eval.py`).", "",
             "| Data | Labels | Synthesis | /p b m/ | Within 1 mm | Median min (mm) | "
             "Vowel max (mm) | Pause (mm) | Whole face | Lower lip | Upper lip |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in data["rows"]:
        cor = [f"{r[k]:.3f}" if f"{k}" in r else "–" for k in ("r_whole_face", "r_lower_lip",
                                                                  "r_upper_lip")]
        lines.append(f"| {r['data']} | {r['labels']} | {r['synthesis']} | {r['n']} | "
                     f"{100 * r['within']:.0f} % | {r['median_min']:.1f} | {r['vowel_max']:.1f} | "
                     f"{r['pause']:.1f} | " + " | ".join(cor) + " |")
    lines.append("")
    return lines
