"""Which phone labels a recording gets: THE rule (:func:`resolve_labels`, asked by a
:class:`LabelRequest`), used by every command that takes audio and by the app -- a label file
given, else a sentence given (aligned), else recognition asked for, else a label file beside the
audio (same stem), else the phones the audio's own file holds (MVIEW), else a ``.txt``
transcript beside it (aligned), else recognition (or none:
:func:`facetraj_engine.method.modes.choose_mode` then switches to acoustic-only synthesis);
:class:`FoundLabels` says which step gave them.

Automatic labels of one recording (:func:`label_audio`: ``"aligned"`` from its text or
``"recognized"``) go through a cache outside the repository (``facetraj_engine.io.cachedir``),
keyed by the audio as the labeller hears it, the method, the text, extra pronunciations and the
PocketSphinx version. Corpora and folders are labelled in :mod:`facetraj_engine.io.labelling`.
"""

from __future__ import annotations

import functools
import json
import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..labels.provenance import Labels
from ..progress import Progress
from .cachedir import cache_dir
from .files import atomic_write
from .labelfiles import LABEL_SUFFIXES, AudioExtent, held_labels, read_label_file

log = logging.getLogger(__name__)

#: Automatic labelling methods (the :attr:`Labels.source` they produce).
METHODS = ("aligned", "recognized")
#: Bumped when this module's output for the same input changes (part of the cache key).
LABELLER_VERSION = 3     # 2: the all-phone search's lw 4 (issue 25); 3: the level (issue 38)


# --------------------------------------------------------------------------- one recording
def label_cache_key(audio: np.ndarray, rate: int, method: str, text: str = "",
                    extra_dict: Mapping[str, Sequence[str]] | None = None) -> str:
    """A hash of the audio samples (as 16-bit PCM at the labeller's level), the rate, the method,
    the text, extra pronunciations, the PocketSphinx version and :data:`LABELLER_VERSION`."""
    import hashlib  # here: a label file read needs no hashing

    from ..labels.alignment import pcm16, pocketsphinx_version

    h = hashlib.sha256()
    h.update(pcm16(audio).tobytes())            # what the labeller hears: the same at any gain
    meta = {"rate": int(rate), "method": method, "text": text if method == "aligned" else "",
            "dict": {k: list(v) for k, v in sorted((extra_dict or {}).items())},
            "pocketsphinx": pocketsphinx_version(), "labeller": LABELLER_VERSION}
    h.update(json.dumps(meta, sort_keys=True).encode())
    return h.hexdigest()[:24]


def label_cache_path(key: str) -> Path:
    """The cache file of a label key."""
    return cache_dir() / "labels" / f"labels-{key}.json"


def label_audio(audio: np.ndarray, rate: int, method: str, text: str = "",
                extra_dict: Mapping[str, Sequence[str]] | None = None,
                source: str | os.PathLike[str] | None = None, use_cache: bool = True,
                progress: Progress | None = None) -> Labels:
    """Labels of one recording by ``method`` (``"aligned"`` needs ``text``), from the cache when
    the same audio was labelled the same way before (``progress``: told as each decoding pass
    starts). Errors are not cached."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    path = label_cache_path(label_cache_key(audio, rate, method, text, extra_dict)) \
        if use_cache else None
    if path is not None and path.exists():
        try:
            return Labels.from_json(json.loads(path.read_text(encoding="utf-8")))
        except (ValueError, KeyError, TypeError) as exc:
            log.warning("ignoring unreadable cached labels %s: %s", path, exc)
    # PocketSphinx's side, imported when labels are made (reading label files does not need it)
    from ..labels import alignment

    if method == "aligned":
        labels = alignment.align(audio, rate, text, extra_dict, source, progress=progress)
    else:
        labels = alignment.recognize(audio, rate, source, progress)
    if path is not None:
        try:
            with atomic_write(path) as tmp:
                tmp.write_text(json.dumps(labels.to_json()), encoding="utf-8")
        except OSError as exc:
            log.warning("could not cache labels in %s: %s", path, exc)
    return labels


# --------------------------------------------------------------------------- the label source rule
def beside(audio_path: str | os.PathLike[str]) -> tuple[Path | None, Path | None]:
    """The label file (``.TextGrid``, ``.lab``, ``.phn``) and the ``.txt`` transcript beside an
    audio file (same stem), each ``None`` when absent."""
    audio_path = Path(audio_path)
    label = next((p for suf in LABEL_SUFFIXES for p in audio_path.parent.glob(f"{audio_path.stem}.*")
                  if p.suffix.lower() == suf and p.is_file()), None)
    txt = audio_path.with_suffix(".txt")
    return label, (txt if txt.is_file() else None)


def read_transcript(path: str | os.PathLike[str]) -> str:
    """The sentence of a ``.txt`` transcript (UTF-8)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "no such transcript file")
    try:
        return path.read_text(encoding="utf-8-sig").strip()
    except UnicodeDecodeError:
        raise InputError(path, "the transcript is not UTF-8 text") from None


@dataclass(frozen=True)
class LabelRequest:
    """Where a recording's labels come from (the options of every command that takes audio): a
    label file, the sentence (``text`` or a ``transcript`` file), recognition, else what lies
    beside the audio, else recognition when ``fallback``; ``declared``: how label files from
    elsewhere were made (``--label-provenance``); ``label_map``: a label map (file or an
    alphabet's name) for label files; ``extra_dict``: extra pronunciations."""

    labels: Path | None = None
    text: str | None = None
    transcript: Path | None = None
    recognize: bool = False
    declared: str | None = None
    label_map: str | None = None
    extra_dict: Mapping[str, Sequence[str]] | None = None
    fallback: bool = True


@dataclass(frozen=True)
class FoundLabels:
    """A recording's labels (``None``: none) and ``where`` they came from, in words: the step of
    the rule that gave them (:func:`resolve_labels`); ``file``: the label file read, if any."""

    labels: Labels | None
    where: str
    file: Path | None = None

    def describe(self) -> str:
        """``"aligned from a.txt (PocketSphinx 5.1.1) [a.txt beside the audio]"``, ``"none [...]"``."""
        what = self.labels.provenance.describe() if self.labels is not None else "none"
        return f"{what} [{self.where}]"


#: where the labels come from when nothing was given and nothing lies beside the audio
NOTHING_BESIDE = "no label file, sentence or .txt beside the audio"


def resolve_labels(audio_path: str | os.PathLike[str], audio: np.ndarray, rate: int,
                   request: LabelRequest | None = None, *, use_cache: bool = True,
                   quiet: bool = False, progress: Progress | None = None) -> FoundLabels:
    """THE rule for the phone labels of a recording (every command that takes audio: ``synth``
    and its batch, ``video``, ``gui`` and the app's Open audio, ``live --from-file``, ``align``,
    and the corpus commands through :func:`facetraj_engine.io.corpus.load_utterance`); the first
    that applies:

    1. ``request.labels`` (a label file) -> ``source="file"``;
    2. ``request.text``, or the sentence of ``request.transcript`` -> aligned;
    3. ``request.recognize`` -> recognized;
    4. a label file beside the audio (same stem) -> file; else the labels the audio's own file
       holds (an MVIEW file's PHONES) -> aligned;
    5. a ``.txt`` beside the audio -> aligned;
    6. otherwise, with ``request.fallback``, recognized (synthesis: on every voice measured the
       robust mode with recognized labels beats acoustic-only, and only labels can close the
       lips); when recognition fails, or without ``fallback``, none:
       :func:`facetraj_engine.method.modes.choose_mode` then synthesizes acoustic-only.

    A label file's provenance is the record it holds (a TextGrid facetraj wrote), else
    ``request.declared`` (``--label-provenance``), else what its conventions say (an aligner's:
    :func:`facetraj_engine.labels.provenance.aligner_conventions`), else hand-checked. A label file's
    alphabet is recognised and mapped onto ARPAbet unless a ``label_map`` is given (it maps them
    later: :func:`facetraj_engine.io.labelfiles.read_label_file`).

    Alignment and recognition are logged as they start (``quiet``: at debug level, for a
    corpus's every utterance), and tell ``progress`` as each decoding pass starts (on 300 s of
    speech, recognition takes half a minute); the caller says where the labels came from
    (:meth:`FoundLabels.describe`). Errors of alignment (missing words, text that does not fit)
    propagate.
    """
    request = request or LabelRequest()
    say = functools.partial(log.log, logging.DEBUG if quiet else logging.INFO)
    label = functools.partial(label_audio, use_cache=use_cache, progress=progress)
    found = _resolve(Path(audio_path), audio, rate, request, label, say)
    log.debug("%s: phone labels %s", Path(audio_path).name, found.describe())
    return found


def _resolve(audio_path: Path, audio: np.ndarray, rate: int, request: LabelRequest,
             label, say) -> FoundLabels:
    """:func:`resolve_labels`'s steps (``label``: :func:`label_audio` with the caller's cache and
    progress settings)."""
    duration = len(audio) / float(rate)
    detect = not request.label_map
    extent = AudioExtent(audio_path, len(audio), int(rate))
    if request.labels is not None:
        return FoundLabels(read_label_file(request.labels, rate, duration, request.declared, detect,
                                           extent),
                           f"{Path(request.labels).name}, given", Path(request.labels))
    text, transcript = request.text, request.transcript
    if text is None and transcript is not None:
        text = read_transcript(transcript)
    if text is not None:
        origin = Path(transcript).name if transcript else "the sentence given"
        say("aligning the phones of %s to %r", audio_path.name, text)
        labels = label(audio, rate, "aligned", text, request.extra_dict, transcript or audio_path)
        return FoundLabels(made_from(labels, origin), f"{origin}, given" if transcript else origin)
    if request.recognize:
        say("recognizing the phones of %s (no text)", audio_path.name)
        labels = label(audio, rate, "recognized", source=audio_path)
        return FoundLabels(made_from(labels, audio_path.name), "recognition, as asked")
    label_file, txt = beside(audio_path)
    if label_file is not None:
        return FoundLabels(read_label_file(label_file, rate, duration, request.declared, detect,
                                           extent),
                           f"{label_file.name} beside the audio", label_file)
    held = _held_by(audio_path)
    if held is not None:
        return FoundLabels(held_labels(held.phones, held.words, duration, audio_path, detect),
                           f"{audio_path.name}'s PHONES", audio_path)
    if txt is not None:
        sentence = read_transcript(txt)
        say("aligning the phones of %s to %r (%s beside it)", audio_path.name, sentence, txt.name)
        labels = label(audio, rate, "aligned", sentence, request.extra_dict, txt)
        return FoundLabels(made_from(labels, txt.name), f"{txt.name} beside the audio")
    if not request.fallback:
        return FoundLabels(None, NOTHING_BESIDE)
    say("%s: %s: recognizing its phones", audio_path.name, NOTHING_BESIDE)
    try:
        labels = label(audio, rate, "recognized", source=audio_path)
    except InputError as exc:
        log.warning("%s; acoustic-only synthesis", exc)
        return FoundLabels(None, f"recognition failed: {NOTHING_BESIDE}")
    return FoundLabels(made_from(labels, audio_path.name), f"recognition: {NOTHING_BESIDE}")


def _held_by(audio_path: Path):
    """The recording of a marker file that holds the speech and its phones (MVIEW), else ``None``."""
    from .audio import AUDIO_SUFFIXES
    from .markerformats import held_recording

    if audio_path.suffix.lower() in AUDIO_SUFFIXES or not audio_path.is_file():
        return None
    rec = held_recording(audio_path, "carries_labels")
    return rec if rec is not None and rec.phones else None


def made_from(labels: Labels, origin: str) -> Labels:
    """``labels`` with what they were made from in their provenance."""
    labels.provenance = replace(labels.provenance, origin=origin)
    return labels
