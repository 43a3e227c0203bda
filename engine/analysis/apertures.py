"""How far apart the lips are: the numbers of the app's Measure readout and its per-phone table.

The **aperture** is the distance (mm) between the upper and the lower lip centre markers, as the
kinematics panels measure it (:func:`facetraj_engine.evaluation.kinematics.lip_measures`: the same
definition, tested equal; this module imports nothing heavy, for the window's first frame); the
markers sit on the outside of the lips, so a closed mouth still has an aperture of about a lip's
thickness (:func:`facetraj_engine.analysis.lips.closed_lips` says how much for the talker).

* :func:`readout_at`: at one time, the upper and lower lip y and the aperture, synthesized and
  (where there is one) original, their difference, and the phone and word there.
* :func:`phone_apertures`: for every phone segment, the aperture at its minimum and at its
  midpoint, original and synthesized, and the error (synthesized - original);
  :func:`write_phone_apertures_csv` writes them.
* :func:`frame_labels`: the label (phone, word) of each frame, for trajectory tables.

Plain arrays in, plain numbers out: the app draws them (``app/measure.py``).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..data import PhoneSegment
from ..labels.phoneset import SILENCE

NAN = float("nan")
#: labels that are silence in a tier (left out of the per-phone table by default)
SILENT_LABELS = frozenset({SILENCE, "", "sp", "pau", "h#"})


def aperture(markers: np.ndarray, upper: int, lower: int) -> np.ndarray:
    """Per-frame lip aperture (mm) of ``(T, M, 3)`` markers: the distance between the upper and
    the lower lip centre markers; NaN where either is missing.

    >>> m = np.zeros((2, 2, 3)); m[:, 0, 1] = [6.0, 5.5]; m[:, 1, 1] = -6.0
    >>> aperture(m, 0, 1).tolist()
    [12.0, 11.5]
    """
    m = np.asarray(markers, dtype=np.float64)
    return np.linalg.norm(m[:, upper] - m[:, lower], axis=-1)


def label_at(segments: Sequence[PhoneSegment], t: float) -> str:
    """The label of the segment holding ``t`` seconds ("" outside every segment).

    >>> label_at([PhoneSegment(0.0, 0.1, "b"), PhoneSegment(0.1, 0.3, "oy")], 0.15)
    'oy'
    """
    for seg in segments:
        if seg.start <= t < seg.end:
            return seg.label
    return ""


def frame_labels(segments: Sequence[PhoneSegment], times: np.ndarray) -> list[str]:
    """The label of the segment holding each frame time ("" outside every segment).

    >>> frame_labels([PhoneSegment(0.0, 0.1, "b"), PhoneSegment(0.1, 0.3, "oy")], np.array([0.05, 0.2, 0.4]))
    ['b', 'oy', '']
    """
    starts = np.array([s.start for s in segments], dtype=np.float64)
    ends = np.array([s.end for s in segments], dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    if not len(segments):
        return [""] * len(times)
    k = np.searchsorted(starts, times, side="right") - 1
    inside = (k >= 0) & (times < ends[np.clip(k, 0, None)])
    return [segments[i].label if ok else "" for i, ok in zip(k.tolist(), inside.tolist(), strict=True)]


@dataclass(frozen=True)
class LipReadout:
    """The lips at one time (mm, the model's head frame). ``original_*`` are NaN without
    original markers; ``difference`` is the synthesized aperture minus the original's."""

    time: float
    frame: int
    phone: str
    word: str
    upper_y: float
    lower_y: float
    aperture: float
    original_upper_y: float = NAN
    original_lower_y: float = NAN
    original_aperture: float = NAN

    @property
    def difference(self) -> float:
        return self.aperture - self.original_aperture

    @property
    def has_original(self) -> bool:
        return bool(np.isfinite(self.original_aperture))


def readout_at(t: float, times: np.ndarray, synthesized: np.ndarray, upper: int, lower: int,
               original: np.ndarray | None = None, phones: Sequence[PhoneSegment] = (),
               words: Sequence[PhoneSegment] = ()) -> LipReadout:
    """The :class:`LipReadout` at ``t`` seconds: the frame nearest ``t`` of ``synthesized`` (and
    ``original``) ``(T, M, 3)`` with frame times ``times``; the phone and word labels at ``t``.

    >>> syn = np.zeros((3, 2, 3)); syn[:, 0, 1] = 6.0; syn[:, 1, 1] = -5.0
    >>> org = syn.copy(); org[:, 1, 1] = -6.0
    >>> r = readout_at(0.02, np.array([0.0, 1 / 60, 2 / 60]), syn, 0, 1, org, [PhoneSegment(0, 1, "b")])
    >>> r.frame, r.phone, r.aperture, r.original_aperture, r.difference
    (1, 'b', 11.0, 12.0, -1.0)
    """
    times = np.asarray(times, dtype=np.float64)
    k = int(np.clip(np.argmin(np.abs(times - t)), 0, len(times) - 1)) if len(times) else 0
    syn = np.asarray(synthesized, dtype=np.float64)[k]
    values = dict(upper_y=float(syn[upper, 1]), lower_y=float(syn[lower, 1]),
                  aperture=float(aperture(syn[None], upper, lower)[0]))
    if original is not None and k < len(original):
        org = np.asarray(original, dtype=np.float64)[k]
        values.update(original_upper_y=float(org[upper, 1]), original_lower_y=float(org[lower, 1]),
                      original_aperture=float(aperture(org[None], upper, lower)[0]))
    return LipReadout(float(t), k, label_at(phones, t), label_at(words, t), **values)


@dataclass(frozen=True)
class PhoneAperture:
    """One phone segment's aperture (mm): at its minimum (each track's own minimum within the
    segment, at ``min_time`` for the synthesized one) and at its midpoint; the errors are
    synthesized - original (NaN without an original)."""

    phone: str
    word: str
    start: float
    end: float
    frames: int
    min_time: float
    min_synthesized: float
    min_original: float
    mid_synthesized: float
    mid_original: float

    @property
    def min_error(self) -> float:
        return self.min_synthesized - self.min_original

    @property
    def mid_error(self) -> float:
        return self.mid_synthesized - self.mid_original


def phone_apertures(times: np.ndarray, synthesized: np.ndarray, upper: int, lower: int,
                    phones: Sequence[PhoneSegment], words: Sequence[PhoneSegment] = (),
                    original: np.ndarray | None = None,
                    silence: frozenset[str] = SILENT_LABELS) -> list[PhoneAperture]:
    """The :class:`PhoneAperture` of every phone segment (silence left out) in time order. A
    segment shorter than a frame is measured at the frame nearest its midpoint; the word is the
    one holding the segment's midpoint.

    >>> t = np.arange(6) / 60
    >>> syn = np.zeros((6, 2, 3)); syn[:, 0, 1] = [9, 8, 6, 7, 9, 9]; syn[:, 1, 1] = -5.0
    >>> [(p.phone, p.min_synthesized, p.mid_synthesized) for p in
    ...  phone_apertures(t, syn, 0, 1, [PhoneSegment(0, 0.045, "b"), PhoneSegment(0.045, 0.09, "oy")])]
    [('b', 11.0, 13.0), ('oy', 12.0, 14.0)]
    """
    times = np.asarray(times, dtype=np.float64)
    syn_ap = aperture(synthesized, upper, lower)
    org_ap = aperture(original, upper, lower) if original is not None else None
    out = []
    for seg in phones:
        if seg.label in silence or not len(times):
            continue
        mid = 0.5 * (seg.start + seg.end)
        inside = np.flatnonzero((times >= seg.start) & (times < seg.end))
        k_mid = int(np.argmin(np.abs(times - mid)))
        if not len(inside):
            inside = np.array([k_mid])
        k_min = int(inside[np.nanargmin(syn_ap[inside])]) if np.isfinite(syn_ap[inside]).any() \
            else k_mid
        min_org = mid_org = NAN
        if org_ap is not None:
            seen = inside[inside < len(org_ap)]
            finite = seen[np.isfinite(org_ap[seen])] if len(seen) else seen
            min_org = float(org_ap[finite].min()) if len(finite) else NAN
            mid_org = float(org_ap[k_mid]) if k_mid < len(org_ap) else NAN
        out.append(PhoneAperture(seg.label, label_at(words, mid), float(seg.start), float(seg.end),
                                 len(inside), float(times[k_min]), float(syn_ap[k_min]), min_org,
                                 float(syn_ap[k_mid]), mid_org))
    return out


APERTURE_COLUMNS = ("phone", "word", "start_s", "end_s", "frames", "min_time_s",
                    "min_original_mm", "min_synthesized_mm", "min_error_mm",
                    "mid_original_mm", "mid_synthesized_mm", "mid_error_mm")


def aperture_row(p: PhoneAperture) -> list:
    """One :class:`PhoneAperture` as the values of :data:`APERTURE_COLUMNS`."""
    return [p.phone, p.word, p.start, p.end, p.frames, p.min_time, p.min_original,
            p.min_synthesized, p.min_error, p.mid_original, p.mid_synthesized, p.mid_error]


def write_phone_apertures_csv(path: str | os.PathLike[str], rows: Sequence[PhoneAperture],
                              overwrite: bool = True,
                              extra: dict[str, Sequence[float]] | None = None) -> Path:
    """Write the per-phone apertures (:data:`APERTURE_COLUMNS`, then the ``extra`` columns: a
    value per row each, e.g. a pinned result's) as CSV, atomically; NaN where there is no
    original."""
    from .common import write_csv  # (the csv writer's package: not for the first frame)

    extra = extra or {}
    lines = ([*aperture_row(p), *(float(v[i]) for v in extra.values())] for i, p in enumerate(rows))
    return write_csv(path, [*APERTURE_COLUMNS, *extra], lines, overwrite)


__all__ = ["APERTURE_COLUMNS", "LipReadout", "PhoneAperture", "aperture", "aperture_row",
           "frame_labels", "label_at", "phone_apertures", "readout_at", "write_phone_apertures_csv"]
