"""The phone set: ARPAbet and silence, label normalisation, and mapping labels onto a model's
phones (a user's label map first, then the nearest CMU phone for extended ARPAbet / TIMIT)."""

from __future__ import annotations

import functools
import logging
import re
from collections.abc import Mapping, Sequence

from ..data import PhoneSegment
from ..errors import InputError, warn_file

log = logging.getLogger(__name__)

SILENCE = "sil"

#: The 39 ARPAbet phones of the CMU Pronouncing Dictionary, plus silence.
ARPABET = (
    "aa ae ah ao aw ay b ch d dh eh er ey f g hh ih iy jh k l m n ng ow oy p r s sh t th "
    "uh uw v w y z zh"
).split()

#: Labels read as silence.
SILENCE_LABELS = frozenset({"", "sil", "sp", "pau", "h#", "#", "spn", "breath", "<p:>", "silence"})

#: Extended ARPAbet / TIMIT symbols and the nearest CMU phone used when the model lacks them.
FALLBACK = {
    "ax": "ah", "axr": "er", "ax-h": "ah", "ix": "ih", "ux": "uw", "el": "l", "em": "m",
    "en": "n", "eng": "ng", "nx": "n", "dx": "t", "hv": "hh", "q": "t",
    "bcl": "b", "dcl": "d", "gcl": "g", "pcl": "p", "tcl": "t", "kcl": "k",
}


@functools.lru_cache(maxsize=4096)
def normalise_label(label: str) -> str:
    """Lower-case, strip ARPAbet stress digits, map silence labels to ``sil`` (remembered: a
    phone set has a few dozen labels, met again in every file).

    Examples
    --------
    >>> [normalise_label(x) for x in ["AH0", "sp", "T", ""]]
    ['ah', 'sil', 't', 'sil']
    """
    lab = re.sub(r"[012]$", "", label.strip().lower())
    return SILENCE if lab in SILENCE_LABELS else lab


def apply_label_map(label: str, table: Mapping[str, str] | None = None) -> str:
    """A label normalised and mapped through ``table`` (looked up as written, then normalised).

    Examples
    --------
    >>> apply_label_map("@", {"@": "AH0"}), apply_label_map("IY1", {"@": "ah"}), apply_label_map("T")
    ('ah', 'iy', 't')
    """
    lab = normalise_label(label)
    if table:
        lab = normalise_label(table.get(label, table.get(lab, lab)))
    return lab


def map_labels(phones: Sequence[PhoneSegment], known: Sequence[str],
               table: Mapping[str, str] | None = None, path: str | None = None,
               strict: bool = False, unknown_as: str | None = None,
               warn_unknown: bool = True) -> list[PhoneSegment]:
    """Normalise labels and map those the model does not know.

    ``table`` (a user's label map, e.g. MOCHA -> ARPAbet) is applied first, then
    :data:`FALLBACK`. A label still unknown raises :class:`InputError` listing the known phones,
    or, when it is an ARPAbet phone, with ``unknown_as`` becomes that label (the model never saw
    it; a warning per label unless ``warn_unknown`` is off,
    the caller saying it once: labels from a recognizer, or a small model, may meet a phone the
    training labels never had). With ``strict`` a fallback is an error too.
    Each fallback is logged as a warning.

    >>> [s.label for s in map_labels([PhoneSegment(0, 1, "zh"), PhoneSegment(1, 2, "AA1")],
    ...                              ["aa", "sil"], unknown_as="sil")]
    ['sil', 'aa']
    """
    known_set = set(known)
    out = []
    for seg in phones:
        raw = seg.label
        lab = apply_label_map(raw, table)
        if lab not in known_set and unknown_as is not None and FALLBACK.get(lab) not in known_set \
                and lab in ARPABET:
            if warn_unknown:
                warn_file(log, path or "labels", "phones not in the model, synthesized as unlabelled",
                          f"phone {lab!r} is not in the model; its frames are synthesized as "
                          f"unlabelled")
            lab = unknown_as
        if lab not in known_set:
            alt = FALLBACK.get(lab)
            if alt in known_set and not strict:
                warn_file(log, path or "labels", "phones not in the model, the nearest used",
                          f"phone {lab!r} is not in the model; using {alt!r}")
                lab = alt
            elif table and (raw in table or normalise_label(raw) in table):
                raise InputError(getattr(table, "source", None) or "the label map",
                                 f"maps {raw!r} (at {seg.start:.3f} s in {path or 'the labels'}) "
                                 f"to {lab!r}, which is not in the model; known phones: "
                                 f"{' '.join(sorted(known_set))}")
            else:
                raise InputError(path, f"phone {raw!r} at {seg.start:.3f} s is not in the model; "
                                       f"known phones: {' '.join(sorted(known_set))}")
        out.append(PhoneSegment(seg.start, seg.end, lab))
    return out
