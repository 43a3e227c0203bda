"""Automatic labels for whole corpora (cached) and folders.

- :func:`label_corpus` labels every utterance of a :class:`~facetraj_engine.io.corpus.Corpus`;
  :func:`relabelled` gives a corpus whose utterances carry those labels, which
  :func:`facetraj_engine.method.training.train` and :func:`facetraj_engine.evaluation.scores.evaluate` take as
  they are (the paper trained and tested on aligner labels, section 3).
- :func:`label_folder` writes a TextGrid beside every recording of a folder.

One recording's labels, and THE rule for where they come from, are
:mod:`facetraj_engine.io.label_rule`'s.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..data import Utterance
from ..errors import InputError
from ..fanout import Skips, fan_out
from ..labels.provenance import Labels
from ..progress import Progress
from .corpus import Corpus
from .label_rule import METHODS, label_audio, made_from, read_transcript

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- corpora
@dataclass
class CorpusLabels:
    """Automatic labels of a corpus's utterances.

    ``labels`` maps utterance id -> :class:`Labels` (``source`` says aligned or recognized: an
    utterance without transcript, or whose alignment failed, is recognized when ``method`` is
    ``"aligned"``); ``failed`` maps utterance id -> the error of an alignment that fell back to
    recognition, or of an utterance left without labels (``missing``).
    """

    method: str
    labels: dict[str, Labels] = field(default_factory=dict)
    failed: dict[str, str] = field(default_factory=dict)

    @property
    def missing(self) -> list[str]:
        """Utterances with no automatic labels at all."""
        return [u for u in self.failed if u not in self.labels]


def label_utterance(utt: Utterance, method: str = "aligned",
                    extra_dict: Mapping[str, Sequence[str]] | None = None,
                    use_cache: bool = True) -> tuple[Labels, str | None]:
    """Labels of one utterance and the alignment error that made it fall back to recognition."""
    if method == "aligned" and utt.text:
        try:
            return label_audio(utt.audio, utt.sample_rate, "aligned", utt.text, extra_dict,
                               utt.name, use_cache), None
        except InputError as exc:
            log.warning("%s; recognizing its phones instead", exc)
            return label_audio(utt.audio, utt.sample_rate, "recognized", source=utt.name,
                               use_cache=use_cache), str(exc)
    return label_audio(utt.audio, utt.sample_rate, "recognized", source=utt.name,
                       use_cache=use_cache), None


def label_corpus(corpus: Corpus, method: str = "aligned", split: str = "all",
                 extra_dict: Mapping[str, Sequence[str]] | None = None,
                 progress: Progress | None = None, use_cache: bool = True,
                 workers: int = 1) -> CorpusLabels:
    """Label every utterance of ``split`` by ``method`` (cached per utterance: a second call
    costs only reading the corpus), in ``workers`` processes. An utterance that cannot be
    labelled is left out and named in ``failed``."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    ids = {"train": corpus.info.train, "test": corpus.info.test, "all": corpus.info.ids}[split]
    out = CorpusLabels(method)
    failed = Skips()

    def label_one(utt_id: str) -> tuple[Labels, str | None]:
        return label_utterance(corpus.utterance(utt_id), method, extra_dict, use_cache)

    done = fan_out(label_one, list(ids), workers, skip=failed, progress=progress,
                   describe=lambda u: f"labelling {u}")
    for utt_id, (labels, error) in done:
        out.labels[utt_id] = labels
        if error:
            out.failed[utt_id] = error
    out.failed.update(failed.bad)     # each logged as it was skipped
    if progress:
        progress(1.0, f"{len(out.labels)} utterances labelled")
    return out


def with_labels(utt: Utterance, labels: Labels) -> Utterance:
    """``utt`` with its phones (and words, when any) replaced by ``labels``."""
    return replace(utt, phones=list(labels.phones), words=list(labels.words) or utt.words,
                   label_source=labels.source, provenance=labels.provenance,
                   confidence=labels.trust(), checked=labels.checked)


@dataclass
class RelabelledCorpus(Corpus):
    """A corpus whose utterances carry automatic labels instead of their label files; utterances
    left without labels are dropped from its splits."""

    auto: CorpusLabels = field(default_factory=lambda: CorpusLabels("aligned"))

    def utterance(self, utt_id: str) -> Utterance:
        return with_labels(super().utterance(utt_id), self.auto.labels[utt_id])

    def fingerprint(self) -> str:
        h = hashlib.sha256(super().fingerprint().encode())
        h.update(json.dumps({u: lab.to_json() for u, lab in sorted(self.auto.labels.items())},
                            sort_keys=True).encode())
        return h.hexdigest()[:16]


def relabelled(corpus: Corpus, method: str = "aligned",
               extra_dict: Mapping[str, Sequence[str]] | None = None,
               progress: Progress | None = None, use_cache: bool = True,
               split: str = "all") -> RelabelledCorpus:
    """``corpus`` with every utterance of ``split`` labelled by ``method`` (see
    :func:`label_corpus`); the other split is left out."""
    auto = label_corpus(corpus, method, split, extra_dict, progress, use_cache)
    keep = set(auto.labels)
    info = replace(corpus.info, train=[u for u in corpus.info.train if u in keep],
                   test=[u for u in corpus.info.test if u in keep])
    if auto.missing:
        log.warning("%d utterances without automatic labels left out: %s", len(auto.missing),
                    ", ".join(auto.missing))
    return RelabelledCorpus(corpus.root, info, auto=auto)


# --------------------------------------------------------------------------- folders
@dataclass
class FolderLabelling:
    """What :func:`label_folder` did: TextGrids written (and their source), existing ones kept,
    files not labelled (``failed``) and transcripts that did not align (``fell_back``: recognized
    instead), each with its error message."""

    written: dict[str, Path] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)
    kept: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    fell_back: dict[str, str] = field(default_factory=dict)

    def summary(self) -> str:
        n_al = sum(s == "aligned" for s in self.sources.values())
        n_rec = sum(s == "recognized" for s in self.sources.values())
        text = (f"{len(self.written)} TextGrids written ({n_al} aligned, {n_rec} recognized), "
                f"{len(self.kept)} existing kept, {len(self.failed)} could not be labelled")
        return text + "".join(f"\n  recognized instead: {why}" for why in self.fell_back.values())


def write_labels(path: str | os.PathLike[str], labels: Labels, duration: float,
                 overwrite: bool = False) -> None:
    """Write ``labels`` as a TextGrid: ``words`` when any, ``phones``, and for automatic labels
    their record (``provenance``, ``confidence``: :meth:`Labels.tiers`)."""
    from .labelfiles import write_textgrid

    write_textgrid(path, labels.tiers(), duration, overwrite)


def label_folder(folder: str | os.PathLike[str], method: str = "aligned",
                 extra_dict: Mapping[str, Sequence[str]] | None = None, overwrite: bool = False,
                 progress: Progress | None = None, use_cache: bool = True, workers: int = 1,
                 skip: Skips | None = None) -> FolderLabelling:
    """Write ``<stem>.TextGrid`` beside every audio file of ``folder``: aligned from ``<stem>.txt``
    (``method="aligned"``; recognized where the transcript is missing or does not align), or
    recognized for all (``"recognized"``). Existing TextGrids are kept unless ``overwrite``.

    The recordings are labelled in ``workers`` processes (:func:`facetraj_engine.fanout.fan_out`). A
    recording that cannot be labelled (a bad audio file or transcript, silence) stops the work
    with its error, the TextGrids already written staying; with ``skip`` it is left out, recorded
    there and in ``failed``."""
    from .audio import AUDIO_SUFFIXES

    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(folder, "not a folder")
    audio_files = sorted(p for p in folder.iterdir() if p.suffix.lower() in AUDIO_SUFFIXES)
    if not audio_files:
        raise InputError(folder, "no .wav or .flac audio files")
    out = FolderLabelling()
    todo = []
    for apath in audio_files:
        if apath.with_suffix(".TextGrid").exists() and not overwrite:
            out.kept.append(apath.stem)
        else:
            todo.append(apath)
    by_stem = {p.stem: p for p in todo}

    def label_one(stem: str) -> tuple[str, str | None]:
        return _label_file(by_stem[stem], method, extra_dict, overwrite, use_cache)

    done = fan_out(label_one, list(by_stem), workers, skip=skip, progress=progress)
    for stem, (source, error) in done:
        out.written[stem] = by_stem[stem].with_suffix(".TextGrid")
        out.sources[stem] = source
        if error:
            out.fell_back[stem] = error
    if skip is not None:
        out.failed.update({stem: msg for stem, msg in skip.bad.items() if stem in by_stem})
    return out


def _label_file(apath: Path, method: str, extra_dict: Mapping[str, Sequence[str]] | None,
                overwrite: bool, use_cache: bool) -> tuple[str, str | None]:
    """Label one recording and write its TextGrid: the labels' source and the alignment error
    that made it fall back to recognition."""
    from .audio import read_audio

    try:
        audio, rate = read_audio(apath)
        text = read_transcript(apath.with_suffix(".txt")) \
            if method == "aligned" and apath.with_suffix(".txt").is_file() else ""
        labels, error = label_utterance(Utterance(apath.stem, audio, rate, text=text), method,
                                        extra_dict, use_cache)
        labels = made_from(labels, apath.with_suffix(".txt").name if labels.source == "aligned"
                            else apath.name)
        write_labels(apath.with_suffix(".TextGrid"), labels, len(audio) / rate, overwrite)
    except InputError:
        raise
    except OSError as exc:  # not one of ours: still the file and the problem
        raise InputError(exc.filename or apath, exc.strerror or str(exc)) from exc
    return labels.source, error
