"""How far apart the lips are at each phone, for several results side by side: the app's pinned
results compared per phone on the utterance shown, and the same comparison run across a corpus.

A result is a :class:`Recipe`: the synthesis settings it used and where its phone labels came
from (``file``: the utterance's own, ``aligned`` from its sentence, ``recognized`` from its
speech, ``none``). :func:`labels_of` makes a recording's labels of a source by the one rule
(``facetraj_engine.io.label_rule.resolve_labels``; the app's labels box uses it too).
:func:`minimum_within` is each row's minimum of another result's aperture track over the row's
segment; :func:`corpus_comparison` synthesizes every utterance of a corpus with each recipe and
gives a :class:`ComparedPhone` per phone segment of the utterance's own labels (the corpus's:
the reference), with the original's minimum and each result's; :func:`phone_means` sums them up
per phone; :func:`write_comparison_csv` writes them (one row per segment and result).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..config import SynthConfig
from ..data import Provenance, Utterance
from ..errors import FacetrajError
from ..io.corpus import Corpus, audio_path
from ..progress import Progress
from .apertures import NAN, SILENT_LABELS, aperture, label_at

log = logging.getLogger(__name__)

#: the label sources a result can have (``Utterance.label_source`` for the own: ``file``)
LABEL_SOURCES = ("file", "aligned", "recognized", "none")


@dataclass(frozen=True)
class Recipe:
    """How one result was made: ``name`` (``this``, ``pin 1``), its synthesis ``config`` (the
    search it used) and its ``labels`` source (:data:`LABEL_SOURCES`); ``settings``: the
    settings in words (a CSV column)."""

    name: str
    config: SynthConfig
    labels: str = "file"
    settings: str = ""


def labels_of(source: str, path: str | os.PathLike[str], audio: np.ndarray, rate: int,
              text: str = "", label_file: Path | None = None,
              extra_dict: Mapping[str, Sequence[str]] | None = None):
    """The labels of a recording from ``source`` (``file``: ``label_file``; ``aligned``:
    ``text``; ``recognized``; ``none``: None), by the one rule; alignment and recognition are
    cached, slow the first time."""
    from ..io.label_rule import LabelRequest, resolve_labels

    if source == "none":
        return None
    request = {"file": LabelRequest(labels=label_file),
               "aligned": LabelRequest(text=text, extra_dict=extra_dict)}.get(
        source, LabelRequest(recognize=True))
    return resolve_labels(path, audio, rate, request, quiet=True).labels


def relabelled(utt: Utterance, labels) -> Utterance:
    """``utt`` with ``labels`` (a :class:`~facetraj_engine.labels.provenance.Labels` or None)."""
    return replace(utt, phones=list(labels.phones) if labels else [],
                   words=list(labels.words) if labels else [],
                   label_source=labels.source if labels else "none",
                   provenance=labels.provenance if labels else Provenance(),
                   confidence=labels.trust() if labels else None,
                   checked=labels.checked if labels else None)


def minimum_within(times: np.ndarray, values: np.ndarray, start: float, end: float) -> float:
    """The least finite value of ``values`` (per frame at ``times``) over ``[start, end)``; a
    segment shorter than a frame: the frame nearest its middle (NaN if none).

    >>> minimum_within(np.arange(5) / 10, np.array([5.0, 3.0, 4.0, 1.0, 2.0]), 0.1, 0.3)
    3.0
    """
    times = np.asarray(times, dtype=np.float64)
    inside = np.flatnonzero((times >= start) & (times < end))
    if not len(inside) and len(times):
        inside = np.array([int(np.argmin(np.abs(times - 0.5 * (start + end))))])
    inside = inside[inside < len(values)]
    finite = np.asarray(values, dtype=np.float64)[inside]
    finite = finite[np.isfinite(finite)]
    return float(finite.min()) if len(finite) else NAN


@dataclass(frozen=True)
class ResultMinimum:
    """One result at one phone segment: its labels' phone there (its middle) and its least
    aperture over the segment (mm)."""

    name: str
    phone: str
    min_mm: float


@dataclass(frozen=True)
class ComparedPhone:
    """One phone segment of an utterance's own labels, the original's least aperture over it and
    each result's (:class:`ResultMinimum`, in the recipes' order)."""

    utterance: str
    split: str
    phone: str
    word: str
    start: float
    end: float
    min_original: float
    results: tuple[ResultMinimum, ...]


def compare_utterance(model, utt: Utterance, split: str, recipes: Sequence[Recipe],
                      audio_file: Path, text: str = "") -> list[ComparedPhone]:
    """:class:`ComparedPhone` rows of one utterance: its own phone segments (silence left out),
    each recipe synthesized with its labels (made from ``audio_file``'s audio)."""
    from ..method.pipeline import synthesize

    tracks: list[tuple[Recipe, Utterance, np.ndarray, np.ndarray]] = []
    for recipe in recipes:
        u = utt if recipe.labels == "file" else relabelled(utt, labels_of(
            recipe.labels, audio_file, utt.audio, utt.sample_rate, text or utt.text))
        res = synthesize(model, u.audio, u.sample_rate, u.phones or None, recipe.config,
                         n_frames=u.n_frames or None, source=u.name, confidence=u.confidence,
                         provenance=u.provenance, voice=True)
        tracks.append((recipe, u, res.times, aperture(res.markers, model.upper_lip, model.lower_lip)))
    times = utt.frame_times()
    original = (aperture(model.normalise_markers(utt.markers), model.upper_lip, model.lower_lip)
                if utt.markers is not None else np.full(len(times), NAN))
    out = []
    for seg in utt.phones:
        if seg.label in SILENT_LABELS:
            continue
        mid = 0.5 * (seg.start + seg.end)
        results = tuple(ResultMinimum(recipe.name, label_at(u.phones, mid),
                                      minimum_within(t, ap, seg.start, seg.end))
                        for recipe, u, t, ap in tracks)
        out.append(ComparedPhone(utt.name, split, seg.label, label_at(utt.words, mid), seg.start,
                                 seg.end, minimum_within(times, original, seg.start, seg.end),
                                 results))
    return out


def corpus_comparison(model, corpus: Corpus, recipes: Sequence[Recipe],
                      ids: Sequence[tuple[str, str]], texts: Mapping[str, str] | None = None,
                      progress: Progress | None = None) -> Iterator[ComparedPhone]:
    """:func:`compare_utterance` for each ``(split, id)`` of ``ids``; an utterance that cannot
    be read or labelled is logged and left out."""
    for k, (split, utt_id) in enumerate(ids):
        if progress is not None:
            progress(k / max(len(ids), 1), f"comparing the results on {utt_id}")
        try:
            utt = corpus.utterance(utt_id)
            yield from compare_utterance(model, utt, split, recipes,
                                         audio_path(corpus.data_root, utt_id),
                                         (texts or {}).get(utt_id, utt.text))
        except FacetrajError as exc:
            log.warning("%s", exc)


@dataclass(frozen=True)
class PhoneMeans:
    """One phone over many segments: how many, and the mean least aperture (mm) of the original
    and of each result (in the recipes' order)."""

    phone: str
    segments: int
    original: float
    results: tuple[float, ...]


def phone_means(rows: Sequence[ComparedPhone], phones: Sequence[str] = ()) -> list[PhoneMeans]:
    """Per phone (only ``phones``, all when empty; in the order given, else alphabetical), the
    mean of each column of ``rows``."""
    wanted = list(phones) or sorted({r.phone for r in rows} - SILENT_LABELS)
    out = []
    for phone in wanted:
        mine = [r for r in rows if r.phone == phone]
        if not mine:
            continue
        n = len(mine[0].results)
        table = np.array([[r.min_original, *(x.min_mm for x in r.results)] for r in mine])
        means = [float(np.nanmean(c)) if np.isfinite(c).any() else NAN for c in table.T]
        out.append(PhoneMeans(phone, len(mine), means[0], tuple(means[1:n + 1])))
    return out


COMPARISON_COLUMNS = ("utterance", "split", "phone", "word", "start_s", "end_s", "result",
                      "settings", "result_phone", "min_mm", "min_original_mm", "difference_mm")


def write_comparison_csv(path: str | os.PathLike[str], rows: Sequence[ComparedPhone],
                         recipes: Sequence[Recipe], overwrite: bool = True) -> Path:
    """The rows as CSV (:data:`COMPARISON_COLUMNS`), one line per segment and result, with the
    result's settings and its labels' phone there; ``difference_mm``: result − original."""
    from .common import write_csv  # (the csv writer's package: not for the first frame)

    settings = {r.name: r.settings for r in recipes}
    lines = ([r.utterance, r.split, r.phone, r.word, r.start, r.end, x.name, settings.get(x.name, ""),
              x.phone, x.min_mm, r.min_original, x.min_mm - r.min_original]
             for r in rows for x in r.results)
    return write_csv(path, COMPARISON_COLUMNS, lines, overwrite)


__all__ = ["COMPARISON_COLUMNS", "LABEL_SOURCES", "ComparedPhone", "PhoneMeans", "Recipe",
           "ResultMinimum", "compare_utterance", "corpus_comparison", "labels_of",
           "minimum_within", "phone_means", "relabelled", "write_comparison_csv"]
