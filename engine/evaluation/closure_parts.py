"""Each part of the closure step earns its default (issue 46): measured on lips, with and without.

The closure step (:mod:`facetraj_engine.method.closure`) has four parts, each a setting of
:class:`~facetraj_engine.config.SynthConfig`: closing the lips at the labelled /p b m/
(``closure_labels``), resting the face in pauses (``rest``), the bilabial-closure detector without
phones (``closure_detector``) and its closures beside recognized phones (``closure_second_opinion``).
A part beyond the paper is on by default only where it does not lower the lip correlation on lips
that were measured: its cost is the correlation without it minus with it (whole face, lower lip y,
upper lip y, on speech frames as Table 2), beside the closures' precision and recall against the
talker's own closed lips (:mod:`facetraj_engine.evaluation.closed_lips`).

Where it is measured:

- the held-out sentences of a corpus with lip markers (the default corpus: its exact labels, the
  same sentences' recognized labels, and no labels), each part switched alone from the defaults;
- a real talker the model was not trained on, with the talker's own lips: the MOCHA-TIMIT sample
  (``../shared``; real speech and EMA lips). Its lips are coils, not the model's markers, so the
  measure there is the correlation of the synthesized lip aperture (upper-lip y minus lower-lip y)
  and lower-lip y with the talker's, on its speech frames: how the shapes move together, not the
  distances.
"""

from __future__ import annotations

import logging
import os
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config import EvalConfig, SynthConfig
from ..io.corpus import Corpus, init_corpus, load_corpus
from ..io.labelling import relabelled
from ..method.model import Model
from ..method.speech import speech_mask
from ..workflow.recording import LabelRequest, synthesize_recording
from .closure import lip_aperture
from .scores import METRICS, evaluate, pearson

log = logging.getLogger(__name__)

#: The parts: (setting, what it does), in the order the report lists them.
PARTS = (
    ("closure_labels", "close the lips at the labelled /p b m/"),
    ("rest", "rest the face in pauses"),
    ("closure_detector", "the detector's closures without phones"),
    ("closure_second_opinion", "the detector's closures beside recognized phones"),
)
#: A part may cost at most this much correlation where it is on by default (issue 46: whole face
#: 0.005, a lip 0.01; the real talker's lip aperture as a lip).
MAX_COST = {"whole_face": 0.005, "lower_lip": 0.01, "upper_lip": 0.01, "aperture": 0.01}
#: Where each part is measured on a corpus: the labels (exact, recognized, none) whose synthesis
#: it acts in.
CORPUS_LABELS = {"closure_labels": ("exact", "recognized"), "rest": ("exact", "recognized", "none"),
                 "closure_detector": ("none",), "closure_second_opinion": ("recognized",)}
#: The MOCHA-TIMIT sample in the reference material, and its roles.
MOCHA_DIR = "data/mocha_fsew0_001"


@dataclass
class PartRow:
    """One part measured on one set of lips: ``on`` and ``off`` (the correlations and closure
    scores with and without it), and whether it is on by default."""

    part: str
    data: str
    labels: str
    on: dict
    off: dict
    default: bool

    @property
    def cost(self) -> dict:
        """Per correlation, without the part minus with it (what the part costs; negative: gains)."""
        return {k: self.off[k] - self.on[k] for k in self.on if k in self.off and k.startswith("r_")}

    @property
    def earns(self) -> bool:
        """Whether it costs no more than :data:`MAX_COST`."""
        return all(self.cost.get(f"r_{k}", 0.0) <= v + 1e-12 for k, v in MAX_COST.items())

    def to_json(self) -> dict:
        return {"part": self.part, "data": self.data, "labels": self.labels, "on": self.on,
                "off": self.off, "default": self.default, "cost": self.cost, "earns": self.earns}


def _switched(part: str, value: bool, base: SynthConfig | None = None) -> SynthConfig:
    return (base or SynthConfig()).with_(**{part: value})


def _row_scores(result, split: str = "test") -> dict:
    row = result.mean(split, "triangular", result.scores[0].mode)
    return {**{f"r_{k}": row[k] for k in METRICS}, "closure_precision": row["closure_precision"],
            "closure_recall": row["closure_recall"]}


def corpus_rows(model: Model, corpus: Corpus, workers: int = 1,
                progress: Callable[[float, str], None] | None = None) -> list[PartRow]:
    """Every part on ``corpus``'s held-out sentences, with each labels it acts in, switched alone
    from the defaults (the mode by the labels, as every command chooses it)."""
    progress = progress or (lambda f, m: None)
    by_kind: dict[str, Corpus] = {"exact": corpus, "none": corpus}
    jobs = [(part, kind) for part, _ in PARTS for kind in CORPUS_LABELS[part]]
    rows = []
    for k, (part, kind) in enumerate(jobs):
        progress(k / len(jobs), f"closure parts: {part}, {kind} labels")
        if kind not in by_kind:
            by_kind[kind] = relabelled(corpus, kind, split="test")
        default = getattr(SynthConfig(), part)
        base = SynthConfig(mode="acoustic") if kind == "none" else SynthConfig()
        scores = []
        for value in (True, False):
            cfg = _switched(part, value, base)
            res = evaluate(model, by_kind[kind], ("test",), [cfg], ("triangular",),
                           EvalConfig(by_labels=kind != "none"), workers=workers)
            scores.append(_row_scores(res))
        rows.append(PartRow(part, f"{corpus.root.name} test", kind, *scores, default))
    return rows


def mocha_corpus(folder: str | os.PathLike[str], where: str | os.PathLike[str]) -> Corpus:
    """The MOCHA-TIMIT sample ``folder`` as a corpus (read in place; its description written in
    ``where``): the upper incisor and the bridge of the nose fixed, the lips UL and LL."""
    path, _ = init_corpus(folder, Path(where) / "mocha.json", ["UI", "BN"], "UL", "LL",
                          label_map="mocha", test_fraction=0)
    return load_corpus(path)


def real_talker_rows(model: Model, folder: str | os.PathLike[str]) -> list[PartRow]:
    """Every part on the real talker of the MOCHA-TIMIT sample ``folder``, synthesized by
    ``model`` (not trained on it) with each labels it acts in (the sample's hand labels,
    recognized ones, none): the synthesized lip aperture and lower-lip y against the talker's."""
    with tempfile.TemporaryDirectory() as tmp:
        corpus = mocha_corpus(folder, tmp)
        utt = corpus.utterance(corpus.info.train[0])
        wav = next(Path(folder).glob(f"{utt.name}.wav"))
        lab = Path(folder) / f"{utt.name}.lab"
        requests = {"hand-checked": LabelRequest(labels=lab), "recognized": LabelRequest(recognize=True),
                    "none": None}
        kinds = {"closure_labels": ("hand-checked", "recognized"),
                 "rest": ("hand-checked", "recognized", "none"), "closure_detector": ("none",),
                 "closure_second_opinion": ("recognized",)}
        talker = _talker_lips(corpus, utt)
        rows = []
        for part, _ in PARTS:
            for kind in kinds[part]:
                base = SynthConfig(mode="acoustic") if kind == "none" else SynthConfig()
                scores = [_real_scores(model, wav, utt, _switched(part, v, base), requests[kind],
                                       talker) for v in (True, False)]
                rows.append(PartRow(part, f"{utt.name} (MOCHA-TIMIT, a real talker)", kind,
                                    *scores, getattr(SynthConfig(), part)))
        return rows


@dataclass
class _Talker:
    """The real talker's lips: frame times, aperture and lower-lip y (the corpus's markers)."""

    times: np.ndarray
    aperture: np.ndarray
    lower: np.ndarray


def _talker_lips(corpus: Corpus, utt) -> _Talker:
    ul, ll = (corpus.info.marker_index(corpus.info.upper_lip),
              corpus.info.marker_index(corpus.info.lower_lip))
    m = utt.markers
    return _Talker(np.arange(len(m)) / corpus.info.marker_rate, lip_aperture(m, ul, ll), m[:, ll, 1])


def _real_scores(model: Model, wav: Path, utt, config: SynthConfig, request: LabelRequest | None,
                 talker: _Talker) -> dict:
    """The correlations of a synthesis of the real talker's ``wav`` with the talker's lips."""
    done = synthesize_recording(model, wav, config, request, explicit=request is None,
                                audio=(utt.audio, utt.sample_rate))
    res = done.synthesis
    t = res.times
    own_a = np.interp(t, talker.times, talker.aperture, left=np.nan, right=np.nan)
    own_l = np.interp(t, talker.times, talker.lower, left=np.nan, right=np.nan)
    ok = speech_mask(utt.audio, utt.sample_rate, t) & np.isfinite(own_a) & np.isfinite(own_l)
    a = lip_aperture(res.markers, model.upper_lip, model.lower_lip)
    return {"r_aperture": pearson(own_a[ok], a[ok]),
            "r_lower_lip": pearson(own_l[ok], res.markers[ok, model.lower_lip, 1]),
            "mode": res.config.mode, "frames": int(ok.sum())}


def format_markdown(rows: Sequence[dict]) -> list[str]:
    """The report's table of the parts."""
    if not rows:
        return []
    names = dict(PARTS)
    lines = ["### Each part earns its default (issue 46)", "",
             "Each part of the closure step switched alone from the defaults, on lips that were "
             "measured: the correlations with it and without it (on the talker's speech frames), "
             "and its cost (without minus with; negative: it gains). A part beyond the paper is "
             f"on by default only where it costs at most {MAX_COST['whole_face']} of whole-face r "
             f"and {MAX_COST['lower_lip']} of a lip's r. On the corpus, beside them, the "
             "closures' precision and recall against the talker's own closed lips; on the real "
             "talker (MOCHA-TIMIT, EMA coils: another marker set than the model's), the "
             "correlation of the synthesized lip aperture and lower lip with the talker's.", "",
             "| Part | Default | Data | Labels | With | Without | Cost | Earns it |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        keys = [k for k in r["on"] if k.startswith("r_")]
        fmt = "; ".join
        short = {"r_whole_face": "face", "r_lower_lip": "lower lip", "r_upper_lip": "upper lip",
                 "r_aperture": "aperture"}
        with_ = fmt(f"{short[k]} {r['on'][k]:.3f}" for k in keys)
        without = fmt(f"{short[k]} {r['off'][k]:.3f}" for k in keys)
        cost = fmt(f"{short[k]} {r['cost'][k]:+.3f}" for k in keys)
        extra = ""
        if "closure_precision" in r["on"]:
            extra = (f" (closed P/R {_pct(r['on']['closure_precision'])}/"
                     f"{_pct(r['on']['closure_recall'])} vs {_pct(r['off']['closure_precision'])}/"
                     f"{_pct(r['off']['closure_recall'])})")
        lines.append(f"| {names[r['part']]} | {'on' if r['default'] else 'off'} | {r['data']} | "
                     f"{r['labels']} | {with_}{extra} | {without} | {cost} | "
                     f"{'yes' if r['earns'] else 'no'} |")
    return [*lines, ""]


def _pct(x: float) -> str:
    return "–" if x is None or not np.isfinite(x) else f"{100 * x:.0f} %"
