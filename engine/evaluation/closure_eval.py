"""Lips that close, measured for the report (issues 25 and 40): the closure of every synthesis
mode and label source on the default corpus's held-out sentences (with their correlations), on
their second voice (:mod:`facetraj_engine.evaluation.second_voice`: the same articulation, another
voice's formants and pitch) and on real voices the model was not trained on (CMU ARCTIC
sentences, speech only), each synthesized the way the commands do it
(:func:`facetraj_engine.workflow.recording.synthesize_recording` is ``facetraj synth``;
:func:`facetraj_engine.streaming.live.stream_file` is ``facetraj live --from-file``, with phones
recognized as they are spoken or ``--acoustic-only``).

The measure is :mod:`facetraj_engine.evaluation.closure`: /p b m/ within 1 mm of the training talker's
closed aperture, the median minimum at /p b m/, the median vowel maximum, the median pause
aperture, and the vowels and other consonants shut. On the corpus (and its second voice) the
reference labels are its exact ones; on the ARCTIC sentences, their transcripts aligned, whatever
labels the synthesis itself was given. Where the bilabial-closure detector made the closures
(no phone labels), its own score too: the /p b m/ its closures reach and the closures that reach
none (:func:`facetraj_engine.evaluation.closure.detector_score`).
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
from ..io.label_rule import label_audio, read_transcript
from ..io.labelling import relabelled
from ..method.model import Model
from ..method.modes import choose_mode
from ..method.pipeline import Synthesis, synthesize
from ..streaming.live import FileTake, LiveConfig, stream_file
from ..streaming.recognizer import RecognizerConfig, RunningCmn
from ..workflow.recording import LabelRequest, synthesize_recording
from .closed_lips import ClosureAgreement, TalkerClosed, TalkerLips, agreements, talker_closed, talker_lips
from .closure import ClosureScore, DetectorScore, closure_score, detector_score, lip_aperture
from .closure_parts import PartRow, real_talker_rows
from .closure_parts import corpus_rows as part_rows
from .closure_parts import format_markdown as parts_markdown
from .scores import speech_mask, trajectory_correlations
from .second_voice import second_voice

CLOSURE_EVAL_FILE = "closure_eval.json"
#: The real voices of the report, read from ``../shared`` when present (never copied).
ARCTIC_DIR = "data/arctic_samples"
#: The aims of issues 25 and 40: /p b m/ within 1 mm, default mode; without phones at most 5 %
#: of the vowels shut.
AIMS = {"corpus exact": 0.9, "arctic aligned": 0.8, "arctic recognized": 0.7,
        "arctic acoustic": 0.5, "vowel max mm": 17.0, "vowels shut": 0.05}
#: How the report names the acoustic-only synthesis with the closure step, and live mode's.
ACOUSTIC_STEP = ("acoustic-only + closure step with the detector: its closures, rest in pauses "
                 "(--mode acoustic --closure-detector)")
LIVE_ACOUSTIC = "live mode, acoustic-only with the detector (--acoustic-only --closure-detector)"
#: The acoustic-only synthesis with the detector asked for.
DETECTING = SynthConfig(mode="acoustic", closure_detector=True)
#: Live mode's audio blocks (a typical audio callback).
LIVE_BLOCK_S = 0.01


@dataclass
class ClosureRow:
    """One condition: its data set, labels, how it was synthesized, the closure score and (on
    the corpus) the Table 2 correlations and the closures against the talker's own lips
    (``lips``: their :class:`~facetraj_engine.evaluation.closed_lips.TalkerLips`, judged once the
    talker's closed value is known, :func:`judge_rows`)."""

    data: str
    labels: str
    synthesis: str
    score: dict
    correlations: dict = field(default_factory=dict)
    detector: dict | None = None
    lips: list[TalkerLips] = field(default_factory=list)
    closed: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"data": self.data, "labels": self.labels, "synthesis": self.synthesis,
                **self.score, **{f"r_{k}": v for k, v in self.correlations.items()},
                **self.closed,
                **({"detector": self.detector} if self.detector is not None else {})}


def judge_rows(rows: Sequence[ClosureRow]) -> TalkerClosed | None:
    """The talker's closed value over the first row's utterances with lips (every row of a data
    set holds the same originals), and each row's closures judged by it: precision and recall
    (``closed_precision``, ``closed_recall``)."""
    first = next((r for r in rows if r.lips), None)
    if first is None:
        return None
    talker = talker_closed(first.lips)
    for r in rows:
        if r.lips:
            pooled = ClosureAgreement.pooled([c[0] for c in agreements(r.lips, talker)])
            r.closed = {"closed_precision": pooled.precision, "closed_recall": pooled.recall}
    return talker


@dataclass
class ClosureEval:
    """Every row, the closed aperture they are measured against, and each part of the closure
    step with and without it (:mod:`facetraj_engine.evaluation.closure_parts`)."""

    closed: float
    rows: list[ClosureRow] = field(default_factory=list)
    parts: list[PartRow] = field(default_factory=list)

    def to_json(self) -> dict:
        return {"closed": self.closed, "rows": [r.to_json() for r in self.rows],
                "parts": [r.to_json() for r in self.parts]}


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
    ("none", ACOUSTIC_STEP, DETECTING, False),
)


def _aperture_scored(model: Model, markers: np.ndarray, times: np.ndarray,
                     reference: Sequence[PhoneSegment], utt=None
                     ) -> tuple[ClosureScore, dict, TalkerLips | None]:
    """The closure of ``markers`` at the ``reference`` phones, and (``utt`` with markers: its
    original face, speech and audio) their correlations with the original face and the lips of
    both (:func:`~facetraj_engine.evaluation.closed_lips.talker_lips`)."""
    aperture = lip_aperture(markers, model.upper_lip, model.lower_lip)
    score = closure_score(aperture, times, reference, model.closure.closed)
    if utt is None or utt.markers is None:
        return score, {}, None
    mask = speech_mask(utt.audio, utt.sample_rate, times)
    original = model.normalise_markers(utt.markers)
    lips = talker_lips(original, times, reference, mask, model.upper_lip, model.lower_lip)
    lips.add(markers)
    return score, trajectory_correlations(original, markers, mask, model), lips


def _detected(res: Synthesis, reference: Sequence[PhoneSegment]) -> DetectorScore | None:
    """The detector's score on one synthesis, when its closures were the detector's."""
    if res.closure is None or res.closure.probability is None:
        return None
    return detector_score(res.closure.intervals, res.times, reference)


def _take_detected(model: Model, take: FileTake,
                   reference: Sequence[PhoneSegment]) -> DetectorScore | None:
    """The detector's score on one streamed take (its closures, as the stream found them)."""
    stream = take.stream
    p = stream.closure_probability if stream is not None else None
    if p is None or not len(p):
        return None
    return detector_score(stream.detected_closures, np.arange(len(p)) / model.marker_rate,
                          reference)


def _pooled_detector(parts: Sequence[DetectorScore | None]) -> dict | None:
    found = [p for p in parts if p is not None]
    return DetectorScore.pooled(found).to_json() if found else None


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
        scores, cors, found, lips = [], [], [], []
        for utt_id in lab.info.test:
            ref, utt = corpus.utterance(utt_id), lab.utterance(utt_id)
            phones = None if kind == "none" else utt.phones
            c = choose_mode(cfg, phones, utt.provenance, tuned=model.tuned).config if rule else cfg
            res = synthesize(model, utt.audio, utt.sample_rate, phones, c, n_frames=utt.n_frames,
                             source=utt.name, confidence=utt.confidence, provenance=utt.provenance)
            s, r, lip = _aperture_scored(model, res.markers, res.times, ref.phones, ref)
            scores.append(s)
            cors.append(r)
            lips.append(lip)
            found.append(_detected(res, ref.phones))
        rows.append(ClosureRow(f"{corpus.root.name} test", kind, name,
                               ClosureScore.pooled(scores).to_json(), _mean_correlations(cors),
                               _pooled_detector(found), lips))
    judge_rows(rows)
    return rows


def _mean_correlations(cors: Sequence[dict]) -> dict:
    """The correlations of utterances, averaged (as Table 2 averages them)."""
    keys = ("whole_face", "lower_lip", "upper_lip")
    mean = np.nanmean(np.array([[r[m] for m in keys] for r in cors]), axis=0)
    return dict(zip(keys, mean.tolist(), strict=True))


# --------------------------------------------------------------------------- streamed, second voice
#: The acoustic-only conditions of the corpus's held-out sentences in their own voice and in the
#: second voice: (synthesis shown, config offline or ``None`` for live mode's stream).
ACOUSTIC_CONDITIONS = (
    ("acoustic-only (paper)", SynthConfig(mode="acoustic", closure=False)),
    (ACOUSTIC_STEP, DETECTING),
    (LIVE_ACOUSTIC, None),
)


def acoustic_rows(model: Model, corpus: Corpus, progress: Callable[[float, str], None],
                  voices: Sequence[str] = ("training", "second")) -> list[ClosureRow]:
    """The held-out sentences in the training voice, streamed acoustic-only (``facetraj live
    --acoustic-only``), and in the second voice (:func:`second_voice`) under every condition of
    :data:`ACOUSTIC_CONDITIONS`: the detector on a voice it was not trained on."""
    conditions = [(v, name, cfg) for v in voices for name, cfg in ACOUSTIC_CONDITIONS
                  if v == "second" or cfg is None]
    parts: dict[tuple[str, str], tuple[list, list, list, list]] = {c[:2]: ([], [], [], [])
                                                                    for c in conditions}
    test = list(corpus.info.test)
    for j, utt_id in enumerate(test):
        progress(j / len(test), f"closure: acoustic-only, {utt_id}")
        utt = corpus.utterance(utt_id)
        audio = {"training": utt.audio}
        if "second" in voices:
            audio["second"] = second_voice(utt.audio, utt.sample_rate)
        for voice, name, cfg in conditions:
            if cfg is None:
                take = stream_file(model, audio[voice], utt.sample_rate, LIVE_BLOCK_S, DETECTING,
                                   LiveConfig(phones=False))
                markers, found = take.frames.markers, _take_detected(model, take, utt.phones)
            else:
                res = synthesize(model, audio[voice], utt.sample_rate, None, cfg,
                                 n_frames=utt.n_frames, source=utt.name)
                markers, found = res.markers, _detected(res, utt.phones)
            s, r, lips = _aperture_scored(model, markers, utt.frame_times(len(markers)), utt.phones,
                                          utt)
            for part, x in zip(parts[(voice, name)], (s, r, found, lips), strict=True):
                part.append(x)
    data = {"training": f"{corpus.root.name} test", "second": f"{corpus.root.name} test, second voice"}
    rows = [ClosureRow(data[voice], "none", name, ClosureScore.pooled(scores).to_json(),
                       _mean_correlations(cors), _pooled_detector(found), lips)
            for (voice, name), (scores, cors, found, lips) in parts.items()]
    judge_rows(rows)
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
    ("none", "acoustic-only + closure step as by default: rest in pauses (--mode acoustic)", "none",
     SynthConfig(mode="acoustic"), True),
    ("none", ACOUSTIC_STEP, "none", DETECTING, True),
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
    (LIVE_ACOUSTIC, LiveConfig(phones=False), DETECTING, False),
)


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
    return live_scores(model, refs, config, block_s, synth, session)[0]


def live_scores(model: Model, refs: dict[Path, tuple[np.ndarray, int, list[PhoneSegment]]],
                config: LiveConfig, block_s: float = LIVE_BLOCK_S,
                synth: SynthConfig | None = None, session: bool = False
                ) -> tuple[ClosureScore, DetectorScore | None]:
    """:func:`live_closure`, and the detector's score where the stream's closures were its."""
    scores, found = [], []
    cmn = RunningCmn(prior_frames=config.recognizer.cmn_prior_frames,
                     speech_share=config.recognizer.cmn_speech_share) if session else None
    for audio, rate, ref in refs.values():
        take = stream_file(model, audio, rate, block_s, synth, config, cmn=cmn)
        aperture = lip_aperture(take.frames.markers, model.upper_lip, model.lower_lip)
        scores.append(closure_score(aperture, take.frames.times, ref, model.closure.closed))
        found.append(_take_detected(model, take, ref))
    det = [f for f in found if f is not None]
    return ClosureScore.pooled(scores), (DetectorScore.pooled(det) if det else None)


def arctic_rows(model: Model, folder: Path, progress: Callable[[float, str], None]) -> list[ClosureRow]:
    """The recordings of ``folder`` (each with its ``.txt``) under every condition of
    :data:`ARCTIC_CONDITIONS`, through ``facetraj synth``'s path, and through live mode's
    (:data:`LIVE_CONDITIONS`)."""
    refs = arctic_references(folder)
    rows = []
    steps = len(ARCTIC_CONDITIONS) + len(LIVE_CONDITIONS)
    for k, (kind, name, how, cfg, explicit) in enumerate(ARCTIC_CONDITIONS):
        progress(k / steps, f"closure: ARCTIC {kind}, {name}")
        scores, found = [], []
        for w, (audio, rate, ref) in refs.items():
            request = LabelRequest(transcript=w.with_suffix(".txt") if how == "transcript" else None,
                                   recognize=how == "recognize")
            with tempfile.TemporaryDirectory() as alone:     # the recording without its .txt
                path = Path(alone) / w.name if how == "alone" else w
                if how == "alone":
                    shutil.copyfile(w, path)
                done = synthesize_recording(model, path, cfg, request, explicit=explicit,
                                            audio=(audio, rate))
            res = done.synthesis
            scores.append(_aperture_scored(model, res.markers, res.times, ref)[0])
            found.append(_detected(res, ref))
        rows.append(ClosureRow(folder.name, kind, name, ClosureScore.pooled(scores).to_json(),
                               detector=_pooled_detector(found)))
    for k, (name, config, synth, session) in enumerate(LIVE_CONDITIONS):
        progress((len(ARCTIC_CONDITIONS) + k) / steps, f"closure: ARCTIC, {name}")
        score, det = live_scores(model, refs, config, synth=synth, session=session)
        rows.append(ClosureRow(folder.name, "recognized, streamed" if config.phones else "none",
                               name, score.to_json(),
                               detector=det.to_json() if det is not None else None))
    return rows


def evaluate_closure(model: Model, corpus: Corpus, arctic: str | os.PathLike[str] | None = None,
                     progress: Callable[[float, str], None] | None = None,
                     mocha: str | os.PathLike[str] | None = None, workers: int = 1) -> ClosureEval:
    """Every condition on ``corpus``'s test split, and on the recordings of ``arctic`` when
    given (a folder of ``.wav`` with their ``.txt``); each part of the closure step with and
    without it on the corpus and, when given, on the real talker of the MOCHA-TIMIT sample
    folder ``mocha`` (:mod:`facetraj_engine.evaluation.closure_parts`)."""
    progress = progress or (lambda f, m: None)
    if model.closure is None:
        raise ValueError("the model has no closure statistics: train it again")
    out = ClosureEval(model.closure.closed, corpus_rows(model, corpus, lambda f, m: progress(0.4 * f, m)))
    out.rows += acoustic_rows(model, corpus, lambda f, m: progress(0.4 + 0.2 * f, m))
    if arctic is not None and Path(arctic).is_dir():
        out.rows += arctic_rows(model, Path(arctic), lambda f, m: progress(0.6 + 0.2 * f, m))
    if mocha is not None and Path(mocha).is_dir():
        out.parts += real_talker_rows(model, mocha)
    out.parts += part_rows(model, corpus, workers, lambda f, m: progress(0.8 + 0.2 * f, m))
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
    lines = ["## Lips that close (issues 25 and 40)", "",
             f"The lip aperture (upper-lip centre y minus lower-lip centre y) at its smallest inside "
             f"each /p b m/, against the training talker's closed aperture, "
             f"{data['closed']:.1f} mm (the median of the original markers' minima at the "
             f"training /p b m/). *Within 1 mm*: the share of /p b m/ that close to within 1 mm; "
             f"beside it the median minimum, the median over vowels of each vowel's largest "
             f"aperture (lips that stay shut cannot pass), the median aperture in pauses over "
             f"150 ms, and where the lips shut with no /p b m/ there: the share of vowels whose "
             f"largest aperture is within 1 mm of closed (*vowels shut*), and of the non-labial "
             f"consonants (not /p b m f v w/) whose smallest aperture over the middle half of "
             f"the segment is (*consonants shut*). The *closure step* "
             f"(`engine/method/closure.py`) runs after eq 8 and the smoothing: by default the "
             f"lips close at the labelled /p b m/ (recognized ones trusted as far as the voice "
             f"is not the training voice) and the face rests in pauses; asked for "
             f"(`--closure-detector`), without labels the lips close where the bilabial-closure "
             f"detector finds a closure (`engine/method/closure_detector.py`), and "
             f"(`--closure-second-opinion`) beside recognized labels too, trusted by the voice "
             f"match. The "
             f"*second voice* is each held-out sentence made to sound as a shorter vocal tract "
             f"and a higher voice (`engine/evaluation/second_voice.py`), its face the original's. "
             f"*Closed P, R*: the synthesized closures judged by the talker's own lips, where "
             f"there are lips (`engine/evaluation/closed_lips.py`): a frame is closed within 1 mm "
             f"of the talker's closed aperture (the median of its lips' minima at the labelled "
             f"/p b m/), and of the synthesized closed frames the share closed in the original "
             f"(precision), of the original's the share closed in the synthesis (recall), on "
             f"speech frames. "
             f"Computed by `facetraj report --closure` (`engine/evaluation/closure_eval.py`).", "",
             "| Data | Labels | Synthesis | /p b m/ | Within 1 mm | Median min (mm) | "
             "Vowel max (mm) | Pause (mm) | Vowels shut | Consonants shut | Whole face | "
             "Lower lip | Upper lip | Closed P | Closed R |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in data["rows"]:
        cor = [f"{r[k]:.3f}" if f"{k}" in r else "–" for k in ("r_whole_face", "r_lower_lip",
                                                                  "r_upper_lip")]
        lines.append(f"| {r['data']} | {r['labels']} | {r['synthesis']} | {r['n']} | "
                     f"{100 * r['within']:.0f} % | {r['median_min']:.1f} | {r['vowel_max']:.1f} | "
                     f"{r['pause']:.1f} | {_percent(r, 'vowels_shut')} | "
                     f"{_percent(r, 'consonants_shut')} | " + " | ".join(cor) + " | "
                     f"{_percent(r, 'closed_precision')} | {_percent(r, 'closed_recall')} |")
    return [*lines, "", *parts_markdown(data.get("parts", [])), *detector_markdown(data)]


def _percent(row: dict, key: str) -> str:
    v = row.get(key)
    return "–" if v is None or not np.isfinite(v) else f"{100 * v:.1f} %"


def detector_markdown(data: dict) -> list[str]:
    """The detector's own table: where its closures fell, per data set and mode."""
    rows = [r for r in data["rows"] if r.get("detector")]
    if not rows:
        return []
    lines = ["### The bilabial-closure detector", "",
             "Where the closures of the detector (`engine/method/closure_detector.py`) fall, "
             "against the reference labels: the /p b m/ a closure reaches (*found*), and the "
             "closures that reach none (*false*), by what most of their frames are. Without phone "
             "labels it makes every closure; beside recognized ones it adds its closures where "
             "none is recognized, trusted by the voice match (the training voice's sentences "
             "only: other voices match 0). Streamed (`facetraj live --acoustic-only`), its "
             "probabilities are the offline ones frame for frame at one voice match.", "",
             "| Data | Labels | Synthesis | /p b m/ found | Closures | Reaching a /p b m/ | "
             "False per minute | False on a vowel | on another consonant | in silence |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        d = r["detector"]
        lines.append(f"| {r['data']} | {r['labels']} | {r['synthesis']} | {d['found']} of {d['n']} "
                     f"({100 * d['recall']:.0f} %) | {d['closures']} | "
                     f"{_percent(d, 'precision')} | {d['false_per_minute']:.1f} | "
                     f"{d['false_vowel']} | {d['false_consonant']} | {d['false_silence']} |")
    return [*lines, ""]
