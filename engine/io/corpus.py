"""A corpus folder: ``corpus.json`` plus ``<id>.flac|wav``, ``<id>.TextGrid`` and ``<id>.c3d``.

See ``docs/data-format.md`` for the full description.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import os
from collections.abc import Iterable, Iterator
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from ..data import LABEL_KINDS, PhoneSegment, Utterance
from ..errors import InputError, warn_file
from .audio import read_audio
from .files import atomic_write, check_output_path
from .hash_memo import folder_key, memoized_hash
from .labelfiles import LABEL_SUFFIXES, held_labels, label_file_provenance, read_labels, read_textgrid
from .markerfiles import read_markers
from .markerformats import NAMES_FILE, check_names, format_for, marker_suffixes, read_names_file
from .sensor_roles import overrides_problem

log = logging.getLogger(__name__)

CORPUS_FORMAT = "facetraj-corpus"
#: The share of a folder's recordings ``corpus init`` puts in the test split by default.
DEFAULT_TEST_FRACTION = 1 / 3
CORPUS_VERSION = 1
MAX_DESCRIPTION_BYTES = 64 << 20


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
    label_map : ``""`` (labels are ARPAbet), ``"mocha"`` or a label map file (relative to the
        description) mapping the labels onto ARPAbet when utterances are loaded.
    label_provenance : how label files without a record of their own (any file facetraj did not
        write) were made: ``hand-checked``, ``aligned`` or ``recognized``
        (``facetraj_engine.labels.provenance``); ``""`` (the default): not said, so an aligner's
        conventions make them aligned, and anything else hand-checked.
    data_dir : where the utterance files are, relative to the description's folder (``""``: the
        same folder). Lets a description point at a read-only folder of someone else's data.
    dimensions : 3, or 2 for midsagittal data (x = 0 for every marker).
    head_corrected : the data is already corrected for head motion (no fixed markers needed;
        any given are still used).
    channel_names : how the marker files' channels map onto the names used here: ``OLD=NEW``
        renames (``NEW`` = ``-`` leaves a channel out), a plain list names every channel in file
        order (:mod:`facetraj_engine.io.markerformats.channels`); ``[]``: the files' own names.
    sensor_roles : articulograph sensors' roles where their names do not say them (tongue tip to
        rear, jaw, palate, velum, reference, other: :mod:`facetraj_engine.io.sensor_roles`);
        ``{}``: from the names.
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
    label_map: str = ""
    label_provenance: str = ""
    data_dir: str = ""
    dimensions: int = 3
    head_corrected: bool = False
    channel_names: list[str] = field(default_factory=list)
    sensor_roles: dict[str, list[str]] = field(default_factory=dict)
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
        """The description in ``obj`` (parsed JSON), its schema (:data:`SCHEMA`) and its marker
        roles checked; any problem is an :class:`InputError` naming ``path``."""
        if not isinstance(obj, dict):
            raise InputError(path, f"not a facetraj corpus description (a JSON "
                                   f"{type(obj).__name__}, not an object)")
        if obj.get("format") != CORPUS_FORMAT:
            raise InputError(path, f"not a facetraj corpus description (format {obj.get('format')!r})")
        version = obj.get("version", 1)
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise InputError(path, f"'version' is {version!r:.40}, not a whole number")
        if version > CORPUS_VERSION:
            raise InputError(path, f"corpus format version {obj['version']} is newer than this "
                                   f"facetraj understands ({CORPUS_VERSION})")
        known = set(cls.__dataclass_fields__)
        kwargs = {k: v for k, v in obj.items() if k in known}
        missing = [k for k in ("marker_names", "marker_rate", "fixed_markers", "upper_lip",
                               "lower_lip", "train", "test") if k not in kwargs]
        if missing:
            raise InputError(path, f"missing entries: {', '.join(missing)}")
        for key, value in kwargs.items():
            check, what = SCHEMA[key]
            if not check(value):
                raise InputError(path, f"{key!r} is {json.dumps(value)[:60]}, not {what}")
        info = cls(**kwargs)
        if len(set(info.marker_names)) != len(info.marker_names):
            raise InputError(path, "marker_names lists a marker twice")
        if set(info.train) & set(info.test):
            raise InputError(path, f"utterances in both train and test: "
                                   f"{' '.join(sorted(set(info.train) & set(info.test))[:5])}")
        for m in [*info.fixed_markers, info.upper_lip, info.lower_lip, *info.lip_corners]:
            if m not in info.marker_names:
                raise InputError(path, f"marker {m!r} is not among marker_names")
        need = 2 if info.dimensions == 2 else 3
        if len(info.fixed_markers) < need and not (info.head_corrected and not info.fixed_markers):
            raise InputError(path, f"at least {need} fixed markers are needed to remove head motion "
                                   f"from {info.dimensions}-D data"
                                   + ("" if info.head_corrected else
                                      " (none for data already head-corrected: head_corrected)"))
        check_names(info.channel_names, path)
        problem = overrides_problem(info.sensor_roles, info.marker_names)
        if problem:
            raise InputError(path, problem)
        return info


def _names(v) -> bool:
    return isinstance(v, list) and all(isinstance(x, str) and x.strip() for x in v)


def _ids(v) -> bool:
    """Utterance ids: plain file stems (no folders, nothing hidden)."""
    return _names(v) and all("/" not in x and "\\" not in x and not x.startswith(".") for x in v)


def _text(v) -> bool:
    return isinstance(v, str)


def _rate(v) -> bool:
    return (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            and 1 <= v <= 10000)


#: corpus.json fields: a check of the value and what it must be (for the message).
SCHEMA: dict[str, tuple] = {
    "marker_names": (lambda v: _names(v) and len(v) >= 2, "a list of at least 2 marker names"),
    "marker_rate": (_rate, "a number of frames per second from 1 to 10000"),
    "fixed_markers": (_names, "a list of marker names"),
    "upper_lip": (lambda v: isinstance(v, str) and bool(v), "a marker name"),
    "lower_lip": (lambda v: isinstance(v, str) and bool(v), "a marker name"),
    "train": (lambda v: _ids(v) and len(v) >= 1, "a list of at least one utterance id (file stem)"),
    "test": (_ids, "a list of utterance ids (file stems)"),
    "lip_corners": (lambda v: _names(v) and len(v) in (0, 2), "a list of 2 marker names (or [])"),
    "units": (lambda v: v == "mm", '"mm"'),
    "axes": (lambda v: isinstance(v, dict) and all(isinstance(x, str) for x in v.values()),
             "an object of axis names"),
    "label_set": (_text, "text"),
    "label_map": (_text, "text (\"\", \"mocha\" or a label map file)"),
    "label_provenance": (lambda v: v in ("", *LABEL_KINDS),
                         " or ".join(f'"{k}"' for k in ("", *LABEL_KINDS))),
    "data_dir": (_text, "text (a folder relative to the description)"),
    "dimensions": (lambda v: v in (2, 3) and not isinstance(v, bool), "2 or 3"),
    "head_corrected": (lambda v: isinstance(v, bool), "true or false"),
    "channel_names": (_names, "a list of channel names (OLD=NEW, or one per channel)"),
    "sensor_roles": (lambda v: isinstance(v, dict), "an object of role lists (tongue, jaw, ...)"),
    "name": (_text, "text"),
    "description": (_text, "text"),
}


def _json_path(root: str | os.PathLike[str]) -> Path:
    root = Path(root)
    return root if root.suffix.lower() == ".json" else root / "corpus.json"


def save_corpus_info(root: str | os.PathLike[str], info: CorpusInfo,
                     overwrite: bool = True) -> Path:
    """Write ``root/corpus.json`` (or ``root`` itself when it names a ``.json`` file)."""
    path = _json_path(root)
    with atomic_write(path, overwrite) as tmp:
        tmp.write_text(json.dumps(info.to_json(), indent=2) + "\n", encoding="utf-8")
    return path


def load_corpus_info(root: str | os.PathLike[str]) -> CorpusInfo:
    """Read ``root/corpus.json`` (or ``root`` itself when it names a ``.json`` file)."""
    path = _json_path(root)
    if not path.exists():
        raise InputError(path, "no corpus.json in this folder" if path.name == "corpus.json"
                         else "no such corpus description")
    if path.is_dir():
        raise InputError(path, "is a folder, not a corpus description")
    if path.stat().st_size > MAX_DESCRIPTION_BYTES:
        raise InputError(path, f"is {path.stat().st_size} bytes, too large for a corpus description")
    try:
        obj = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(path, f"not valid JSON ({exc})") from exc
    except RecursionError:
        raise InputError(path, "not valid JSON (nested too deeply)") from None
    return CorpusInfo.from_json(obj, path)


def _find(root: Path, utt_id: str, suffixes: tuple[str, ...], what: str) -> Path:
    for suffix in suffixes:
        for cand in (suffix, suffix.upper()):
            p = root / f"{utt_id}{cand}"
            if p.exists():
                return p
    raise InputError(root / f"{utt_id}{suffixes[0]}",
                     f"no {what} file ({', '.join(suffixes)}) for this utterance")


def audio_path(root: str | os.PathLike[str], utt_id: str) -> Path:
    """The audio file of an utterance (FLAC or WAV)."""
    return _find(Path(root), utt_id, (".flac", ".wav"), "audio")


def label_path(root: str | os.PathLike[str], utt_id: str) -> Path:
    """The label file of an utterance (TextGrid, HTK/MOCHA .lab or TIMIT .phn)."""
    return _find(Path(root), utt_id, (".TextGrid", ".lab", ".phn"), "label")


def marker_path(root: str | os.PathLike[str], utt_id: str) -> Path:
    """The marker file of an utterance (any format of :mod:`facetraj_engine.io.markerformats`)."""
    return _find(Path(root), utt_id, marker_suffixes(), "marker")


def _beside(find, root: Path, utt_id: str) -> tuple[Path | None, InputError | None]:
    """``find(root, utt_id)``, or ``None`` and why not."""
    try:
        return find(root, utt_id), None
    except InputError as exc:
        return None, exc


def label_source(root: str | os.PathLike[str], utt_id: str) -> Path:
    """Where an utterance's labels are: its label file, else its marker file (MVIEW's PHONES)."""
    found, missing = _beside(label_path, Path(root), utt_id)
    if found is not None:
        return found
    mpath = marker_path(root, utt_id)
    if not format_for(mpath).carries_labels:
        raise missing
    return mpath


@dataclass
class Corpus:
    """A corpus: its description and lazy access to its utterances.

    ``root`` is the folder of the description; ``data_root`` the folder of the utterance files.
    """

    root: Path
    info: CorpusInfo
    _memo: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def data_root(self) -> Path:
        return (self.root / self.info.data_dir).resolve() if self.info.data_dir else self.root

    def label_map(self) -> dict[str, str] | None:
        """The label map named in the description, or ``None`` (read once per corpus)."""
        if not self.info.label_map:
            return None
        if "label_map" not in self._memo:
            from ..labels.labelmap import read_label_map

            lm = self.info.label_map
            self._memo["label_map"] = read_label_map(lm if lm.lower() == "mocha" else self.root / lm)
        return self._memo["label_map"]

    def utterance(self, utt_id: str) -> Utterance:
        """Load one utterance, with labels checked against the audio and markers against the info."""
        return load_utterance(self.data_root, utt_id, self.info, self.label_map())

    def markers(self, utt_id: str, n_frames: int) -> np.ndarray:
        """One utterance's markers alone, as :meth:`utterance` gives them for its ``n_frames``
        marker frames of audio (:func:`fitted_frames`): what training reads again, after a first
        pass that loaded the whole utterance, instead of holding every utterance's markers."""
        mdata = read_markers(marker_path(self.data_root, utt_id), self.info.marker_rate,
                             self.info.channel_names or None)
        return fitted_frames(mdata.markers, n_frames)

    def utterances(self, split: str = "all") -> Iterator[Utterance]:
        """Iterate over ``train``, ``test`` or ``all`` utterances."""
        ids = {"train": self.info.train, "test": self.info.test, "all": self.info.ids}[split]
        for utt_id in ids:
            yield self.utterance(utt_id)

    def without(self, ids: Iterable[str]) -> Corpus:
        """This corpus without the utterances ``ids`` (those skipped as bad, say)."""
        drop = set(ids)
        if not drop:
            return self
        return replace(self, info=replace(self.info,
                                          train=[u for u in self.info.train if u not in drop],
                                          test=[u for u in self.info.test if u not in drop]))

    def fingerprint(self) -> str:
        """A hash of the description and every data file (names and contents), for caching
        models; computed once per corpus object, and known from the files' stamps alone when
        they are unchanged since an earlier computation (:mod:`facetraj_engine.io.hash_memo`)."""
        if "fingerprint" not in self._memo:
            description = json.dumps(self.info.to_json(), sort_keys=True)
            files = [p for p in sorted(self.data_root.iterdir())
                     if p.is_file() and p.name != "corpus.json"]

            def contents() -> str:
                h = hashlib.sha256(description.encode())
                for p in files:
                    h.update(p.name.encode())
                    h.update(p.read_bytes())
                return h.hexdigest()[:16]

            self._memo["fingerprint"] = memoized_hash(folder_key(self.data_root), files, contents,
                                                      extra=description)
        return self._memo["fingerprint"]


def load_corpus(root: str | os.PathLike[str]) -> Corpus:
    """Open a corpus folder, or a corpus description ``.json`` (utterances load on demand)."""
    root = Path(root)
    if root.suffix.lower() == ".json" and root.is_file():
        corpus = Corpus(root.parent, load_corpus_info(root))
    elif not root.is_dir():
        raise InputError(root, "not a folder")
    else:
        corpus = Corpus(root, load_corpus_info(root))
    if not corpus.data_root.is_dir():
        raise InputError(_json_path(root), f"its data folder {corpus.info.data_dir!r} "
                                           f"({corpus.data_root}) is not a folder")
    return corpus


def fitted_frames(markers: np.ndarray, n_frames: int) -> np.ndarray:
    """``markers`` ``(T, M, 3)`` cut or padded with NaN (unseen) to ``n_frames`` frames: those of
    the utterance's audio.

    >>> fitted_frames(np.zeros((2, 1, 3)), 3)[:, 0, 0].tolist()
    [0.0, 0.0, nan]
    """
    if markers.shape[0] < n_frames:
        pad = np.full((n_frames - markers.shape[0], *markers.shape[1:]), np.nan)
        markers = np.concatenate([markers, pad])
    return markers[:n_frames]


def load_utterance(root: str | os.PathLike[str], utt_id: str, info: CorpusInfo,
                   label_map: dict[str, str] | None = None) -> Utterance:
    """Load ``<id>`` audio, labels (``phones`` and ``words`` tiers of a TextGrid, or a .lab /
    .phn file, read by the one rule, :func:`facetraj_engine.io.label_rule.resolve_labels`) and
    markers (any format of
    :mod:`facetraj_engine.io.markerformats`, its channels named by
    the description's ``channel_names``, resampled to the corpus rate). A marker file that holds
    the speech and its labels (MVIEW) provides them when no audio or label file is beside it.

    Labels are mapped onto ARPAbet with ``label_map``, or without one from the alphabet they are
    in (:func:`facetraj_engine.labels.alphabets.to_arpabet`: labels in none is an error naming them).
    Markers shorter than the audio are padded with NaN (a warning); longer ones are cut at the
    audio's end.
    """
    from ..labels.phoneset import apply_label_map
    from .label_rule import LabelRequest, resolve_labels

    root = Path(root)
    apath, no_audio = _beside(audio_path, root, utt_id)
    lpath, no_labels = _beside(label_path, root, utt_id)
    if apath is not None:
        audio, rate = read_audio(apath)
    mpath = marker_path(root, utt_id)
    mdata = read_markers(mpath, info.marker_rate, info.channel_names or None)
    if apath is None:
        if mdata.audio is None:
            raise no_audio
        audio, rate = mdata.audio, mdata.audio_rate
    if lpath is not None:
        labels = resolve_labels(apath or mpath, audio, rate, LabelRequest(
            labels=lpath, declared=info.label_provenance or None,
            label_map="corpus" if label_map else None), quiet=True).labels
    elif mdata.phones:
        labels = held_labels(mdata.phones, mdata.words, len(audio) / rate, mpath,
                             detect_alphabet=not label_map)
    else:
        raise no_labels
    phones = labels.phones
    if label_map:
        phones = [PhoneSegment(s.start, s.end, apply_label_map(s.label, label_map)) for s in phones]
    if mdata.names != info.marker_names:
        raise InputError(mpath, f"marker set differs from the corpus description "
                                f"({marker_set_difference(mdata.names, info.marker_names)})")
    markers = _fit_to_audio(mpath, mdata.markers, info.marker_rate, len(audio) / rate)
    return Utterance(name=utt_id, audio=audio, sample_rate=rate, phones=phones,
                     markers=markers, marker_rate=info.marker_rate,
                     marker_names=list(mdata.names), words=labels.words,
                     text=_transcript(root, utt_id) or mdata.transcript,
                     provenance=labels.provenance, confidence=labels.trust(),
                     checked=labels.checked)


def _fit_to_audio(mpath: Path, markers: np.ndarray, marker_rate: float, duration: float
                  ) -> np.ndarray:
    """Markers of the audio's length: padded with NaN (a warning) or cut."""
    n_audio = int(np.floor(duration * marker_rate + 1e-9)) + 1
    if markers.shape[0] < n_audio - 1:
        warn_file(log, mpath, "markers shorter than the audio (later frames are treated as unseen)",
                  f"markers end at {(markers.shape[0] - 1) / marker_rate:.2f} s but the audio "
                  f"at {duration:.2f} s; later frames are treated as unseen")
    markers = fitted_frames(markers, n_audio)
    seen = marker_coverage(markers)
    if seen < 0.5:
        warn_file(log, mpath, "markers mostly missing (frames with gaps are left out)",
                  f"only {100 * seen:.0f} % of the marker samples are seen; frames with gaps over "
                  f"100 ms are left out of training and evaluation")
    return markers


def held_transcript(root: str | os.PathLike[str], utt_id: str) -> str:
    """The sentence an utterance's marker file holds (MVIEW's SENTENCE), ``""`` when it holds none
    or cannot be read (reading the utterance reports why)."""
    try:
        mpath = marker_path(root, utt_id)
        return read_markers(mpath).transcript if format_for(mpath).carries_labels else ""
    except InputError:
        return ""


def _transcript(root: Path, utt_id: str) -> str:
    txt = root / f"{utt_id}.txt"
    if not txt.is_file():
        return ""
    try:
        return txt.read_text(encoding="utf-8").strip()
    except UnicodeDecodeError:
        raise InputError(txt, "the transcript is not UTF-8 text") from None


@dataclass
class FolderScan:
    """What a folder of recordings holds: usable utterances, the marker set, the labels used,
    and what the first marker file says (its format, whether its data is head-corrected)."""

    ids: list[str]
    marker_names: list[str]
    marker_rate: float
    dimensions: int
    labels: list[str]
    first_marker_file: Path
    left_out: list[str] = field(default_factory=list)
    format: str = ""
    head_corrected: bool | None = None
    channel_names: list[str] = field(default_factory=list)


def _complete(data_dir: Path, stem: str) -> bool:
    """Whether ``stem`` has markers, and audio and labels (in files, or in its marker file)."""
    mpath, _ = _beside(marker_path, data_dir, stem)
    if mpath is None:
        return False
    fmt = None
    for find, carried in ((audio_path, "carries_audio"), (label_path, "carries_labels")):
        if _beside(find, data_dir, stem)[0] is None:
            try:
                fmt = fmt or format_for(mpath)
            except InputError:
                return False
            if not getattr(fmt, carried):
                return False
    return True


def _label_set(data_dir: Path, ids: list[str], names: list[str]) -> set[str]:
    """The distinct labels of these utterances' label files (or marker files' PHONES)."""
    labels: set[str] = set()
    for utt_id in ids:
        lpath = label_source(data_dir, utt_id)
        if lpath.suffix.lower() == ".textgrid":
            segs = read_textgrid(lpath)
        elif lpath.suffix.lower() in (".lab", ".phn"):
            segs = read_labels(lpath)
        else:
            segs = read_markers(lpath, channel_names=names or None).phones
        labels.update(s.label for s in segs)
    return labels


def scan_folder(data_dir: str | os.PathLike[str], read_labels_of: int = 50,
                channel_names: list[str] | None = None) -> FolderScan:
    """List the utterances (stems with markers, audio and labels, in files of their own or in the
    marker file) of a folder, its marker set (from the first marker file, its channels named by
    ``channel_names``, else by a ``channel-names.txt`` in the folder) and the distinct labels of
    the first ``read_labels_of`` utterances (for building a label map)."""
    data_dir = Path(data_dir)
    if not data_dir.is_dir():
        raise InputError(data_dir, "not a folder")
    names = list(channel_names or [])
    if not names and (data_dir / NAMES_FILE).is_file():
        names = read_names_file(data_dir / NAMES_FILE)
    suffixes = {".wav", ".flac", *marker_suffixes()}
    stems = sorted({p.stem for p in data_dir.iterdir() if p.suffix.lower() in suffixes
                    and not p.name.startswith(".")})
    ids = [s for s in stems if _complete(data_dir, s)]
    left_out = [s for s in stems if s not in ids]
    if not ids:
        raise InputError(data_dir, "no utterance with audio, labels and markers")
    mfile = marker_path(data_dir, ids[0])
    first = read_markers(mfile, channel_names=names or None)
    labels = _label_set(data_dir, ids[:read_labels_of], names)
    return FolderScan(ids, first.names, first.rate, first.dimensions, sorted(labels), mfile,
                      left_out, first.format, first.head_corrected, names)


def _head_correction(scan: FolderScan, fixed: list[str], head_corrected: bool) -> bool:
    """Whether the data is head-corrected, said in the log; no fixed markers for data that is not
    (by its files' word or the user's) is an error naming what to give."""
    corrected = bool(scan.head_corrected) or head_corrected
    why = (f"its {scan.format} files say so" if scan.head_corrected else "as declared")
    if fixed and corrected:
        log.info("data head-corrected (%s); the fixed markers given are used as well", why)
    elif corrected:
        log.info("data already head-corrected (%s): no fixed markers needed", why)
    elif not fixed:
        need = 2 if scan.dimensions == 2 else 3
        raise InputError(scan.first_marker_file,
                         f"no fixed markers: name {need} or more sensors that move only with the "
                         f"head (--fixed, among {' '.join(scan.marker_names)}), or pass "
                         f"--head-corrected if the data is already corrected ({scan.format} files "
                         f"do not say)")
    return corrected


def init_corpus(data_dir: str | os.PathLike[str], output: str | os.PathLike[str] | None = None,
                fixed: list[str] | None = None, upper_lip: str = "", lower_lip: str = "",
                lip_corners: list[str] | None = None, label_map: str = "",
                marker_rate: float = 60.0, test: list[str] | None = None,
                test_fraction: float | None = None, name: str = "",
                overwrite: bool = True, label_provenance: str = "",
                channel_names: list[str] | None = None, head_corrected: bool = False
                ) -> tuple[Path, CorpusInfo]:
    """Describe a folder of someone's own recordings as a corpus and write the description.

    Utterances are the file stems that have markers, audio and labels (:func:`scan_folder`). The
    marker roles (fixed references, lip centres) are given by name, the channels named by
    ``channel_names`` (or the folder's ``channel-names.txt``); data that its files say (or
    ``head_corrected`` says) is head-corrected needs no fixed markers. The test split is ``test``
    or every ``round(1 / test_fraction)``-th utterance (by default a third, and at least one of
    two or more utterances). ``output`` defaults to
    ``data_dir/corpus.json``; when it lies elsewhere (a read-only data folder), the description
    records ``data_dir`` relative to it. An existing description is replaced only with
    ``overwrite``. ``label_provenance`` says how label files without a record of their own were
    made.
    """
    data_dir = Path(data_dir).resolve()
    out = Path(output) if output else data_dir / "corpus.json"
    out = out if out.suffix.lower() == ".json" else out / "corpus.json"
    check_output_path(out, overwrite)
    if channel_names:
        check_names(channel_names, "--channel-names")
    scan = scan_folder(data_dir, channel_names=channel_names)
    ids, names = scan.ids, scan.marker_names
    for role in [*(fixed or []), upper_lip, lower_lip, *(lip_corners or [])]:
        if role not in names:
            raise InputError(scan.first_marker_file,
                             f"no marker named {role!r}; markers: {' '.join(names)}")
    corrected = _head_correction(scan, list(fixed or []), head_corrected)
    if test is None:
        fraction = DEFAULT_TEST_FRACTION if test_fraction is None else test_fraction
        # a fraction of 1e-320 gave 1 / 0-ish = inf (found by make fuzz); any step past the
        # utterances' count means no test utterance, as 1e9 does
        step = max(2, round(1 / max(fraction, 1e-9))) if fraction > 0 else 0
        test = [u for i, u in enumerate(ids) if step and i % step == step - 1]
        if test_fraction is None and not test and len(ids) > 1:
            test = ids[-1:]     # two recordings: one to train on, one to evaluate
    train_ids = [u for u in ids if u not in test]
    if not train_ids:
        train_ids, test = ids, [u for u in test if u in ids]
    rel = "" if out.parent.resolve() == data_dir else os.path.relpath(data_dir, out.parent.resolve())
    info = CorpusInfo(marker_names=names, marker_rate=float(marker_rate), fixed_markers=list(fixed or []),
                      upper_lip=upper_lip, lower_lip=lower_lip, train=train_ids, test=list(test),
                      lip_corners=list(lip_corners or []), label_map=label_map, data_dir=rel,
                      dimensions=scan.dimensions, name=name or data_dir.name,
                      label_provenance=label_provenance, head_corrected=corrected,
                      channel_names=scan.channel_names)
    CorpusInfo.from_json(info.to_json(), out)  # the same checks as on loading
    save_corpus_info(out, info, overwrite)
    return out, info


def label_kinds(corpus: Corpus) -> dict[str, int]:
    """How the labels of a corpus were made: utterances per kind (the record of each label file,
    else the corpus's ``label_provenance``, else its conventions, as the labels are read:
    :func:`facetraj_engine.io.labelfiles.label_file_provenance`), read from the label files alone
    (labels inside marker files are aligned)."""
    counts: dict[str, int] = {}
    for utt_id in corpus.info.ids:
        source = label_source(corpus.data_root, utt_id)
        if source.suffix.lower() in LABEL_SUFFIXES:
            kind = label_file_provenance(source, corpus.info.label_provenance or None).kind
        else:
            kind = "aligned"
        counts[kind] = counts.get(kind, 0) + 1
    return counts


def marker_set_difference(found: list[str], expected: list[str]) -> str:
    """How a marker set differs from the expected one, in words (for error messages).

    >>> marker_set_difference(["a", "b", "x"], ["a", "b", "c"])
    "3 markers, 3 expected; 'c' missing; 'x' not expected"
    >>> marker_set_difference(["b", "a"], ["a", "b"])
    '2 markers, 2 expected; the same names in another order'
    """
    parts = [f"{len(found)} markers, {len(expected)} expected"]
    missing = [n for n in expected if n not in found]
    extra = [n for n in found if n not in expected]
    if missing:
        parts.append(f"{', '.join(map(repr, missing[:5]))}{' ...' if len(missing) > 5 else ''} missing")
    if extra:
        parts.append(f"{', '.join(map(repr, extra[:5]))}{' ...' if len(extra) > 5 else ''} not expected")
    if not missing and not extra and found != expected:
        parts.append("the same names in another order")
    return "; ".join(parts)


def marker_coverage(markers: np.ndarray) -> float:
    """Fraction of finite marker samples."""
    return float(np.isfinite(markers).all(axis=2).mean())
