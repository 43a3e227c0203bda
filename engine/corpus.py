"""A corpus folder: ``corpus.json`` plus ``<id>.flac|wav``, ``<id>.TextGrid`` and ``<id>.c3d``.

See ``docs/data-format.md`` for the full description.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .data import Utterance
from .errors import InputError
from .formats import (
    AUDIO_SUFFIXES,
    atomic_write,
    read_audio,
    read_c3d,
    read_textgrid,
    read_textgrid_tiers,
    validate_phones,
)

log = logging.getLogger(__name__)

CORPUS_FORMAT = "facetraj-corpus"
CORPUS_VERSION = 1


@dataclass
class CorpusInfo:
    """The contents of ``corpus.json``.

    Attributes
    ----------
    marker_names : names of the markers, in the order of the C3D files.
    marker_rate : marker frames per second.
    fixed_markers : markers that move only with the head (used to remove head motion).
    upper_lip, lower_lip : the upper and lower lip centre markers (evaluation, lip panels).
    lip_corners : right and left lip corner markers (lip width), optional.
    train, test : utterance ids of the two splits.
    units, axes : always mm and x right / y up / z forward in this format.
    label_set : the phone alphabet of the ``phones`` tier (``arpabet``).
    name, description : free text.
    """

    marker_names: list[str]
    marker_rate: float
    fixed_markers: list[str]
    upper_lip: str
    lower_lip: str
    train: list[str]
    test: list[str]
    lip_corners: list[str] = field(default_factory=list)
    units: str = "mm"
    axes: dict[str, str] = field(
        default_factory=lambda: {"x": "right", "y": "up", "z": "forward"})
    label_set: str = "arpabet"
    name: str = ""
    description: str = ""

    def marker_index(self, name: str) -> int:
        """Index of a marker by name."""
        try:
            return self.marker_names.index(name)
        except ValueError:
            raise KeyError(f"no marker named {name!r}") from None

    @property
    def ids(self) -> list[str]:
        """All utterance ids, train first."""
        return list(self.train) + list(self.test)

    def to_json(self) -> dict:
        return {"format": CORPUS_FORMAT, "version": CORPUS_VERSION, **asdict(self)}

    @classmethod
    def from_json(cls, obj: dict, path: str | os.PathLike[str] | None = None) -> CorpusInfo:
        if obj.get("format") != CORPUS_FORMAT:
            raise InputError(path, f"not a facetraj corpus description (format {obj.get('format')!r})")
        if int(obj.get("version", 0)) > CORPUS_VERSION:
            raise InputError(path, f"corpus format version {obj['version']} is newer than this "
                                   f"facetraj understands ({CORPUS_VERSION})")
        known = set(cls.__dataclass_fields__)
        kwargs = {k: v for k, v in obj.items() if k in known}
        missing = [k for k in ("marker_names", "marker_rate", "fixed_markers", "upper_lip",
                               "lower_lip", "train", "test") if k not in kwargs]
        if missing:
            raise InputError(path, f"missing entries: {', '.join(missing)}")
        info = cls(**kwargs)
        for m in [*info.fixed_markers, info.upper_lip, info.lower_lip, *info.lip_corners]:
            if m not in info.marker_names:
                raise InputError(path, f"marker {m!r} is not among marker_names")
        if len(info.fixed_markers) < 3:
            raise InputError(path, "at least 3 fixed markers are needed to remove head motion")
        return info


def save_corpus_info(root: str | os.PathLike[str], info: CorpusInfo) -> Path:
    """Write ``root/corpus.json``."""
    path = Path(root) / "corpus.json"
    with atomic_write(path) as tmp:
        tmp.write_text(json.dumps(info.to_json(), indent=2) + "\n", encoding="utf-8")
    return path


def load_corpus_info(root: str | os.PathLike[str]) -> CorpusInfo:
    """Read ``root/corpus.json``."""
    path = Path(root) / "corpus.json"
    if not path.exists():
        raise InputError(path, "no corpus.json in this folder")
    try:
        obj = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(path, f"not valid JSON ({exc})") from exc
    return CorpusInfo.from_json(obj, path)


def audio_path(root: str | os.PathLike[str], utt_id: str) -> Path:
    """The audio file of an utterance (FLAC or WAV)."""
    for suffix in AUDIO_SUFFIXES[::-1]:
        p = Path(root) / f"{utt_id}{suffix}"
        if p.exists():
            return p
    raise InputError(Path(root) / f"{utt_id}.flac", "no audio file (.flac or .wav) for this utterance")


@dataclass
class Corpus:
    """A corpus folder: its description and lazy access to its utterances."""

    root: Path
    info: CorpusInfo

    def utterance(self, utt_id: str) -> Utterance:
        """Load one utterance, with labels checked against the audio and markers against the info."""
        return load_utterance(self.root, utt_id, self.info)

    def utterances(self, split: str = "all") -> Iterator[Utterance]:
        """Iterate over ``train``, ``test`` or ``all`` utterances."""
        ids = {"train": self.info.train, "test": self.info.test, "all": self.info.ids}[split]
        for utt_id in ids:
            yield self.utterance(utt_id)

    def fingerprint(self) -> str:
        """A hash of every file of the corpus (names, sizes, contents), for caching models."""
        h = hashlib.sha256()
        for p in sorted(self.root.iterdir()):
            if p.is_file():
                h.update(p.name.encode())
                h.update(p.read_bytes())
        return h.hexdigest()[:16]


def load_corpus(root: str | os.PathLike[str]) -> Corpus:
    """Open a corpus folder (reads only ``corpus.json``; utterances load on demand)."""
    root = Path(root)
    if not root.is_dir():
        raise InputError(root, "not a folder")
    return Corpus(root, load_corpus_info(root))


def load_utterance(root: str | os.PathLike[str], utt_id: str, info: CorpusInfo) -> Utterance:
    """Load ``<id>`` audio, TextGrid ``phones`` (and ``words`` if present) and C3D markers."""
    root = Path(root)
    apath = audio_path(root, utt_id)
    audio, rate = read_audio(apath)
    tg_path = root / f"{utt_id}.TextGrid"
    tiers = read_textgrid_tiers(tg_path) if tg_path.exists() else None
    if tiers is None:
        raise InputError(tg_path, "no TextGrid for this utterance")
    phones = validate_phones(read_textgrid(tg_path, "phones"), len(audio) / rate, tg_path)
    words = [w for w in tiers.get("words", []) if w.label]
    mdata = read_c3d(root / f"{utt_id}.c3d")
    if mdata.names != info.marker_names:
        raise InputError(root / f"{utt_id}.c3d",
                         f"marker set differs from corpus.json ({len(mdata.names)} markers, "
                         f"{len(info.marker_names)} expected)")
    if abs(mdata.rate - info.marker_rate) > 1e-6:
        raise InputError(root / f"{utt_id}.c3d",
                         f"marker rate {mdata.rate} Hz differs from corpus.json ({info.marker_rate})")
    text = ""
    txt = root / f"{utt_id}.txt"
    if txt.exists():
        text = txt.read_text(encoding="utf-8").strip()
    return Utterance(name=utt_id, audio=audio, sample_rate=rate, phones=phones,
                     markers=mdata.markers, marker_rate=mdata.rate,
                     marker_names=list(mdata.names), words=words, text=text)


def marker_coverage(markers: np.ndarray) -> float:
    """Fraction of finite marker samples."""
    return float(np.isfinite(markers).all(axis=2).mean())
