"""Phone label files: Praat TextGrid, HTK/MOCHA ``.lab`` and TIMIT ``.phn``; their checks."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..data import PhoneSegment, Provenance
from ..errors import InputError
from ..labels.alphabets import to_arpabet
from ..labels.provenance import PROVENANCE_TIER, Labels, labels_from_tiers, parse_provenance
from .files import atomic_write, read_text
from .textgrid import TextGridSyntaxError, Tier, parse_textgrid

LABEL_SUFFIXES = (".textgrid", ".lab", ".phn")
#: Sample rates a recording is commonly made at (a header's rate that makes the labels fit is
#: suggested only when it is one of these).
COMMON_RATES = (8000, 11025, 16000, 22050, 24000, 32000, 44100, 48000, 88200, 96000)


@dataclass(frozen=True)
class AudioExtent:
    """The recording labels are checked against, as its file's header gives it: its ``path``,
    ``samples`` and ``rate`` (issue 46: labels that do not fit a header with the wrong rate name
    the audio too, and blame it where a common rate would make them fit)."""

    path: Path
    samples: int
    rate: int

    @property
    def duration(self) -> float:
        return self.samples / float(self.rate)

    def fitting_rate(self, labels_end: float) -> int | None:
        """The common rate (:data:`COMMON_RATES`) at which the audio would last as long as labels
        ending at ``labels_end``, if there is one other than its header's.

        >>> AudioExtent(Path("r0.wav"), 54400, 8000).fitting_rate(3.4)
        16000
        >>> AudioExtent(Path("r0.wav"), 54400, 16000).fitting_rate(1.0) is None
        True
        """
        if labels_end <= 0:
            return None
        return next((r for r in COMMON_RATES if r != self.rate and
                     abs(self.samples / r - labels_end) <= max(0.05, 0.02 * labels_end)), None)

    def lasts(self) -> str:
        """What the audio lasts by its header.

        >>> AudioExtent(Path("r0.wav"), 54400, 16000).lasts()
        'lasts 3.400 s by its header (54400 samples at 16000 Hz)'
        """
        return f"lasts {self.duration:.3f} s by its header ({self.samples} samples at {self.rate} Hz)"


def _labels_off_the_end(path, end: float, duration: float, audio: AudioExtent | None) -> InputError:
    """The error for labels ending at ``end`` but audio of ``duration``: blaming the audio where
    its header's rate looks wrong (a common rate would make them fit), else the labels, naming
    the audio."""
    if audio is None:
        return InputError(path, f"labels end at {end:.3f} s but the audio lasts {duration:.3f} s")
    fit = audio.fitting_rate(end)
    if fit is None:
        return InputError(path, f"labels end at {end:.3f} s but the audio {audio.path.name} "
                                f"{audio.lasts()}")
    return InputError(audio.path, f"{audio.lasts()} but its labels {Path(path).name} end at "
                                  f"{end:.3f} s; at {fit} Hz it would last "
                                  f"{audio.samples / fit:.3f} s, as the labels do: is the rate in "
                                  f"its header wrong?")


def read_textgrid_tiers(path: str | os.PathLike[str]) -> dict[str, list[PhoneSegment]]:
    """Read every interval tier of a Praat TextGrid (long or short text form,
    :mod:`facetraj_engine.io.textgrid`); intervals out of order or overlapping are refused."""
    path = Path(path)
    try:
        parsed = parse_textgrid(read_text(path))
    except TextGridSyntaxError as exc:
        raise InputError(path, f"not a readable TextGrid ({exc})") from None
    tiers: dict[str, list[PhoneSegment]] = {}
    for tier in parsed:
        if tier.kind != "IntervalTier":
            continue
        _check_interval_order(path, tier)
        tiers[tier.name] = [PhoneSegment(s, e, lab.strip()) for s, e, lab in tier.entries]
    return tiers


def _check_interval_order(path: Path, tier: Tier) -> None:
    """Refuse an interval tier whose intervals are out of order or overlap."""
    prev_end = -np.inf
    for i, (start, end, label) in enumerate(tier.entries):
        if start < prev_end - 1e-6:
            raise InputError(path, f"tier {tier.name!r}: interval {i + 1} ({label!r}) at "
                                   f"{start:.3f} s overlaps or precedes the one before, "
                                   f"ending {prev_end:.3f} s")
        prev_end = max(prev_end, end)


def read_textgrid(path: str | os.PathLike[str], tier: str = "phones") -> list[PhoneSegment]:
    """Read one interval tier of a TextGrid; empty intervals become ``sil``."""
    tiers = read_textgrid_tiers(path)
    if tier not in tiers:
        raise InputError(path, f"no interval tier named {tier!r} (tiers: {sorted(tiers)})")
    return [PhoneSegment(s.start, s.end, s.label or "sil") for s in tiers[tier]]


def write_textgrid(path: str | os.PathLike[str], tiers: dict[str, Sequence[PhoneSegment]],
                   duration: float, overwrite: bool = True) -> None:
    """Write interval tiers (name -> segments) as a long-form TextGrid."""
    from praatio import textgrid

    tg = textgrid.Textgrid()
    duration = round(float(duration), 6)
    for name, segs in tiers.items():
        entries = [(round(s.start, 6), round(s.end, 6), s.label) for s in segs]
        if entries and abs(entries[-1][1] - duration) < 1e-3:  # no rounding sliver at the end
            entries[-1] = (entries[-1][0], duration, entries[-1][2])
        tg.addTier(textgrid.IntervalTier(name, entries, 0.0, duration))
    with atomic_write(path, overwrite) as tmp:
        tg.save(str(tmp), format="long_textgrid", includeBlankSpaces=True)


def _parse_columns(path: Path) -> list[list[str]]:
    rows = []
    for lineno, line in enumerate(read_text(path).splitlines(), 1):
        parts = line.split()
        if not parts or parts[0].startswith(("#", "!")) or parts[0] in {".", "MillisecondsPerFrame:"}:
            continue
        if len(parts) < 3:
            raise InputError(path, f"line {lineno}: expected 'start end label', got {line!r}")
        rows.append(parts)
    return rows


def read_lab(path: str | os.PathLike[str]) -> list[PhoneSegment]:
    """Read an HTK label file (times in 100 ns units) or a MOCHA ``.lab`` (times in seconds).

    The unit is told apart by the magnitude: integers above 10^4 are HTK units.
    """
    path = Path(path)
    rows = _parse_columns(path)
    try:
        times = np.array([[float(r[0]), float(r[1])] for r in rows])
    except ValueError as exc:
        raise InputError(path, f"a start or end time is not a number ({exc})") from exc
    if times.size and not np.all(np.isfinite(times)):
        row = int(np.flatnonzero(~np.isfinite(times).all(axis=1))[0])
        raise InputError(path, f"segment {row + 1} has a time that is not a finite number "
                               f"({rows[row][0]} {rows[row][1]})")
    scale = 1e-7 if times.size and times.max() > 1e4 else 1.0
    return [PhoneSegment(a * scale, b * scale, r[2]) for (a, b), r in zip(times, rows, strict=True)]


def read_phn(path: str | os.PathLike[str], sample_rate: int = 16000) -> list[PhoneSegment]:
    """Read a TIMIT ``.phn`` file (sample indices at ``sample_rate``); ``h#``/``pau`` -> ``sil``."""
    path = Path(path)
    segs = []
    for r in _parse_columns(path):
        try:
            a, b = int(r[0]), int(r[1])
        except ValueError as exc:
            raise InputError(path, f"sample index is not an integer ({exc})") from exc
        lab = "sil" if r[2] in {"h#", "pau", "epi"} else r[2]
        segs.append(PhoneSegment(a / sample_rate, b / sample_rate, lab))
    return segs


def read_labels(path: str | os.PathLike[str], sample_rate: int = 16000,
                tier: str = "phones") -> list[PhoneSegment]:
    """Read phone labels from a TextGrid, an HTK/MOCHA ``.lab`` or a TIMIT ``.phn``."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".textgrid":
        segs = read_textgrid(path, tier)
    elif suffix == ".lab":
        segs = read_lab(path)
    elif suffix == ".phn":
        segs = read_phn(path, sample_rate)
    else:
        raise InputError(path, f"unknown label format {suffix!r} (use .TextGrid, .lab or .phn)")
    if not segs:
        raise InputError(path, "the label file holds no segments")
    return segs


def validate_phones(phones: Sequence[PhoneSegment], duration: float,
                    path: str | os.PathLike[str] | None = None,
                    tolerance: float = 0.05, audio: AudioExtent | None = None) -> list[PhoneSegment]:
    """Check labels are sorted, do not overlap and cover ``[0, duration]``; return them tidied.

    Gaps between segments are filled with ``sil``; slivers shorter than 1 ms (rounding left-overs)
    are absorbed by the segment before; the first segment is extended to 0 and the last to
    ``duration`` when they fall short by at most ``tolerance`` seconds. Labels that end elsewhere
    are refused naming ``path`` and, when given, the ``audio`` file with its header's rate (the
    audio first where that rate looks wrong).
    """
    if not phones:
        raise InputError(path, "the label file holds no segments")
    out: list[PhoneSegment] = []
    for i, seg in enumerate(phones):
        if out and 0 <= seg.end - seg.start < 1e-3 and seg.start >= out[-1].end - 1e-6:
            out[-1] = PhoneSegment(out[-1].start, seg.end, out[-1].label)
            continue
        if not seg.end > seg.start:
            raise InputError(path, f"segment {i + 1} ({seg.label!r}) ends at {seg.end:.3f} s, "
                                   f"not after its start {seg.start:.3f} s")
        if out and seg.start < out[-1].end - 1e-6:
            raise InputError(path, f"segment {i + 1} ({seg.label!r}) at {seg.start:.3f} s overlaps "
                                   f"or precedes the one before, ending {out[-1].end:.3f} s")
        if out and seg.start > out[-1].end + 1e-6:
            out.append(PhoneSegment(out[-1].end, seg.start, "sil"))
        out.append(seg)
    if out[0].start > tolerance:
        raise InputError(path, f"labels start at {out[0].start:.3f} s, not at 0")
    if abs(out[-1].end - duration) > max(tolerance, 0.02 * duration):
        raise _labels_off_the_end(path, out[-1].end, duration, audio)
    out[0] = PhoneSegment(0.0, out[0].end, out[0].label)
    out[-1] = PhoneSegment(out[-1].start, max(duration, out[-1].start + 1e-3), out[-1].label)
    return out


def write_label_map(path: str | os.PathLike[str], table: dict[str, str]) -> None:
    """Write a label map file (tab separated)."""
    with atomic_write(path) as tmp:
        tmp.write_text("".join(f"{k}\t{v}\n" for k, v in table.items()), encoding="utf-8")


def read_label_file(path: str | os.PathLike[str], rate: int, duration: float,
                    declared: str | None = None, detect_alphabet: bool = True,
                    audio: AudioExtent | None = None) -> Labels:
    """The labels of a label file, checked against the audio's ``duration``: its phones, a
    TextGrid's ``words`` tier, and where they came from (the record a TextGrid written by
    facetraj holds, :func:`facetraj_engine.labels.provenance.labels_from_tiers`; else ``declared``;
    else aligned when the labels follow an aligner's conventions, saying why; else hand-checked).
    The phones are mapped onto ARPAbet from the alphabet they are in
    (:func:`facetraj_engine.labels.alphabets.to_arpabet`) unless ``detect_alphabet`` is off (a label
    map given by the user maps them later). Labels that do not fit the duration name the
    ``audio`` too, when given."""
    path = Path(path)
    if path.suffix.lower() != ".textgrid":
        read = read_labels(path, rate)
        phones = validate_phones(read, duration, path, audio=audio)
        if detect_alphabet:
            phones = to_arpabet(phones, str(path))
        return labels_from_tiers(phones, [], {}, declared, [s.label for s in read])
    tiers = read_textgrid_tiers(path)                     # read once: phones, words, record
    if "phones" not in tiers:
        raise InputError(path, f"no interval tier named 'phones' (tiers: {sorted(tiers)})")
    raw = [PhoneSegment(s.start, s.end, s.label or "sil") for s in tiers["phones"]]
    if not raw:
        raise InputError(path, "the label file holds no segments")
    phones = validate_phones(raw, duration, path, audio=audio)
    if detect_alphabet:
        phones = to_arpabet(phones, str(path))
    words = [w for w in tiers.get("words", []) if w.label]
    return labels_from_tiers(phones, words, tiers, declared, [s.label for s in tiers["phones"]])


def label_file_provenance(path: str | os.PathLike[str], declared: str | None = None) -> Provenance:
    """How a label file's labels were made, as :func:`read_label_file` tells it (the record a
    TextGrid facetraj wrote holds; else ``declared``; else an aligner's conventions; else
    hand-checked), from the file alone; a missing or unreadable file counts as ``declared`` or
    hand-checked (reading it for synthesis says why)."""
    path = Path(path)
    try:
        if path.suffix.lower() == ".textgrid":
            tiers = read_textgrid_tiers(path)
            raw = [s.label for s in tiers.get("phones", [])]
        else:
            tiers, raw = {}, [s.label for s in read_labels(path)]
    except InputError:
        return Provenance(declared or "hand-checked")
    return labels_from_tiers([], [], tiers, declared, raw).provenance


def held_labels(phones: Sequence[PhoneSegment], words: Sequence[PhoneSegment], duration: float,
                path: str | os.PathLike[str], detect_alphabet: bool = True) -> Labels:
    """The labels a marker file holds (MVIEW's PHONES and WORDS), checked against the audio's
    ``duration`` and mapped onto ARPAbet like a label file's; forced-aligned by convention (HPRC's
    are), so their provenance is ``aligned``."""
    checked = validate_phones(list(phones), duration, path)
    if detect_alphabet:
        checked = to_arpabet(checked, f"{path} (PHONES)")
    return labels_from_tiers(checked, list(words), {}, "aligned")


def recorded_provenance(path: str | os.PathLike[str]) -> Provenance | None:
    """The provenance a label file records (a TextGrid facetraj wrote), ``None`` when it records
    none; a missing or unreadable file records none either (reading it for synthesis says why)."""
    path = Path(path)
    if path.suffix.lower() != ".textgrid" or not path.is_file():
        return None
    try:
        tier = read_textgrid_tiers(path).get(PROVENANCE_TIER)
    except InputError:
        return None
    return parse_provenance(tier[0].label) if tier else None
