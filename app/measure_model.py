"""What the Measure readout and table show, without Qt: the numbers come from the engine
(:mod:`facetraj_engine.analysis.apertures`), this module picks them for the utterance on screen and
words them.

* :meth:`Measure.readout_text`: at the cursor, the phone and word there, the upper and lower lip
  y and the aperture of the synthesis shown in 3-D, the original's and the difference, and each
  pinned result's phone there (its own labels'), aperture and difference (mm); for articulograph
  sensors the tongue tip height, the lip aperture and the jaw opening instead
  (:mod:`facetraj_engine.analysis.articulators`).
* :meth:`Measure.rows`: the per-phone table (each phone's aperture at its minimum and at its
  midpoint, original, synthesized, error), filtered by phone, and :meth:`Measure.pin_minima`: a
  column per pinned result (its least aperture over the same segment); :meth:`Measure.write_csv`.
* :meth:`Measure.recipes`: how the result on screen and each pin were made, for the same
  comparison across the corpus (``facetraj_engine.analysis.phone_compare``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from facetraj_engine.analysis import articulators as art
from facetraj_engine.analysis.apertures import (
    LipReadout,
    PhoneAperture,
    aperture,
    frame_labels,
    phone_apertures,
    readout_at,
    write_phone_apertures_csv,
)
from facetraj_engine.analysis.phone_compare import LABEL_SOURCES, Recipe, minimum_within
from facetraj_engine.io.sensor_roles import SensorRoles

from .pins import Pin
from .provenance import settings_text
from .state import UtteranceView

#: the per-phone table's columns: (heading, value of a PhoneAperture, format)
TABLE_COLUMNS: tuple[tuple[str, str, str], ...] = (      # short: a laptop's dock shows the minima
    ("phone", "phone", "{}"), ("word", "word", "{}"), ("start (s)", "start", "{:.3f}"),
    ("min: orig.", "min_original", "{:.1f}"), ("min: synth.", "min_synthesized", "{:.1f}"),
    ("min: error", "min_error", "{:+.1f}"), ("mid: orig.", "mid_original", "{:.1f}"),
    ("mid: synth.", "mid_synthesized", "{:.1f}"), ("mid: error", "mid_error", "{:+.1f}"),
)


def mm(value: float, signed: bool = False) -> str:
    """A length in mm for the readout ("—" when there is none); a value that rounds to zero
    reads 0.0, whatever its sign (a jaw a hair above its highest position read "-0.0 mm").

    >>> mm(11.234), mm(-0.26, signed=True), mm(-0.04, signed=True), mm(float("nan"))
    ('11.2 mm', '-0.3 mm', '0.0 mm', '—')
    >>> mm(-0.04), mm(-0.049), mm(0.04, signed=True), mm(-0.06)
    ('0.0 mm', '0.0 mm', '0.0 mm', '-0.1 mm')
    """
    if not math.isfinite(value):
        return "—"
    text = f"{value:+.1f}" if signed else f"{value:.1f}"
    if float(text) == 0.0:                    # no "-0.0 mm" (nor "+0.0 mm")
        return "0.0 mm"
    return f"{text} mm"


@dataclass
class Measure:
    """The numbers of the utterance on screen: its ``view``, the model's lip markers
    (``upper``, ``lower``) and the ``pins`` shown with it; for articulograph sensors their
    ``roles`` and the talker's highest jaw position ``jaw_top``
    (:func:`facetraj_engine.analysis.articulators.jaw_top`)."""

    view: UtteranceView | None = None
    upper: int = 0
    lower: int = 0
    pins: list[Pin] = field(default_factory=list)
    roles: SensorRoles | None = None
    jaw_top: float = float("nan")
    _rows: list[PhoneAperture] | None = None

    def set_view(self, view: UtteranceView | None, upper: int, lower: int, pins: list[Pin],
                 roles: SensorRoles | None = None, jaw_top: float = float("nan")) -> None:
        self.view, self.upper, self.lower, self.pins = view, upper, lower, list(pins)
        self.roles = roles if roles is not None and roles.articulograph else None
        self.jaw_top = jaw_top
        self._rows = None

    def articulators_at(self, t: float) -> tuple[art.ArticulatorReadout, list] | None:
        """At ``t``: the articulators of the synthesis (and the original), and each pin's
        ``(pin, Articulators)``; None for a face."""
        v = self.view
        if v is None or self.roles is None:
            return None
        r = art.readout_at(t, v.times, v.shown, self.roles, self.jaw_top, v.original,
                           v.utterance.phones, v.utterance.words)
        pins = [(p, art.readout_at(t, p.view.times, p.view.shown, self.roles, self.jaw_top,
                                   phones=p.view.utterance.phones)) for p in self.pins]
        return r, pins

    def articulator_text(self, t: float) -> str:
        """The readout of articulograph sensors: where the cursor is, then the tongue tip
        height, the lip aperture and the jaw opening of the synthesis, each with the original's
        and the difference (synthesized − original), then each pin's."""
        r, pins = self.articulators_at(t)
        where = f"{t:.3f} s" + (f"  /{r.phone}/" + (f" in “{r.word}”" if r.word else "") if r.phone else "")
        parts = [where]
        names = ((f"tongue tip ({self.roles.names[self.roles.tongue[0]]}) height", "tongue_tip"),
                 ("lip aperture", "aperture"), ("jaw opening", "jaw_opening"))
        for label, key in names:
            value = getattr(r.synthesized, key)
            if not math.isfinite(value):
                continue
            text = f"{label} {mm(value)}"
            if r.original is not None:
                text += (f" (original {mm(getattr(r.original, key))}, "
                         f"{mm(value - getattr(r.original, key), signed=True)})")
            parts.append(text)
        for pin, pr in pins:
            parts.append(f"{pin.name}" + (f" /{pr.phone}/" if pr.phone else "") + ": " + ", ".join(
                f"{short} {mm(getattr(pr.synthesized, key))}" for short, key in
                (("tip", "tongue_tip"), ("aperture", "aperture"), ("jaw", "jaw_opening"))
                if math.isfinite(getattr(pr.synthesized, key))))
        return "  ·  ".join(parts)

    def readout(self, t: float) -> LipReadout | None:
        v = self.view
        if v is None:
            return None
        return readout_at(t, v.times, v.shown, self.upper, self.lower, v.original,
                          v.utterance.phones, v.utterance.words)

    def pin_readouts(self, t: float) -> list[tuple[Pin, LipReadout]]:
        return [(p, readout_at(t, p.view.times, p.view.shown, self.upper, self.lower,
                               phones=p.view.utterance.phones)) for p in self.pins]

    def readout_text(self, t: float) -> str:
        """One line: where the cursor is and how far apart the lips are there."""
        if self.roles is not None and self.view is not None:
            return self.articulator_text(t)
        r = self.readout(t)
        if r is None:
            return ""
        where = f"{t:.3f} s"
        if r.phone:
            where += f"  /{r.phone}/" + (f" in “{r.word}”" if r.word else "")
        parts = [where, f"upper lip y {mm(r.upper_y)}, lower lip y {mm(r.lower_y)}",
                 f"aperture {mm(r.aperture)}"]
        if r.has_original:
            parts.append(f"original {mm(r.original_aperture)} (synthesized − original "
                         f"{mm(r.difference, signed=True)})")
        for pin, pr in self.pin_readouts(t):     # with the pin's phone there (its labels')
            phone = f" /{pr.phone}/" if pr.phone else ""
            parts.append(f"{pin.name}{phone} {mm(pr.aperture)} (this − {pin.name} "
                         f"{mm(r.aperture - pr.aperture, signed=True)})")
        return "  ·  ".join(parts)

    def rows(self, phone_filter: str = "") -> list[PhoneAperture]:
        """The per-phone table, only the phones named in ``phone_filter`` (space separated;
        all when empty)."""
        v = self.view
        if v is None:
            return []
        if self._rows is None:
            self._rows = phone_apertures(v.times, v.shown, self.upper, self.lower,
                                         v.utterance.phones, v.utterance.words, v.original)
        wanted = set(phone_filter.lower().replace(",", " ").replace("/", " ").split())
        return [r for r in self._rows if not wanted or r.phone.lower() in wanted]

    def pin_minima(self, rows: list[PhoneAperture]) -> list[list[float]]:
        """Per row, each pin's least aperture over the row's segment (mm; the pin's own frames:
        a column per pin beside the result on screen's)."""
        tracks = [(p.view.times, aperture(p.view.shown, self.upper, self.lower)) for p in self.pins]
        return [[minimum_within(t, ap, r.start, r.end) for t, ap in tracks] for r in rows]

    def pin_columns(self) -> list[str]:
        """The table's headings of the pins' columns (two a pin)."""
        return [head for p in self.pins for head in (f"min: {p.name}", f"min: this − {p.name}")]

    def write_csv(self, path: str | os.PathLike[str], phone_filter: str = "") -> Path:
        """The rows shown as CSV (``APERTURE_COLUMNS``, then each pin's least aperture and this
        minus it: ``min_pin1_mm``, ``min_this_minus_pin1_mm``)."""
        rows = self.rows(phone_filter)
        mins = np.array(self.pin_minima(rows), dtype=float).reshape(len(rows), len(self.pins))
        this = np.array([r.min_synthesized for r in rows])
        extra = {}
        for k, pin in enumerate(self.pins):
            slug = pin.name.replace(" ", "")
            extra[f"min_{slug}_mm"] = mins[:, k]
            extra[f"min_this_minus_{slug}_mm"] = this - mins[:, k]
        return write_phone_apertures_csv(path, rows, extra=extra)

    def recipes(self) -> list[Recipe]:
        """How the result on screen (``this``) and each pin were made: their search and
        settings, and where their labels came from."""
        if self.view is None:
            return []
        return [Recipe("this", self.view.synthesis.config, label_key(self.view),
                       settings_text(self.view, short=True)),
                *(Recipe(p.name, p.view.synthesis.config, label_key(p.view), p.settings)
                  for p in self.pins)]

    def frame_labels(self) -> dict[str, list[str]]:
        """The phone and word of each frame (the trajectory table's label columns)."""
        return {} if self.view is None else view_frame_labels(self.view)


def label_key(view: UtteranceView) -> str:
    """The label source of ``view`` as a recipe names it (``file``: the utterance's own)."""
    source = view.label_origin.source
    return source if source in LABEL_SOURCES else "file"


def view_frame_labels(view: UtteranceView, times: np.ndarray | None = None) -> dict[str, list[str]]:
    """The phone and word of each frame of ``view`` (at ``times``, else at its frames): the
    trajectory table's label columns."""
    t = view.times if times is None else times
    return {"phone": frame_labels(view.utterance.phones, t),
            "word": frame_labels(view.utterance.words, t)}


__all__ = ["TABLE_COLUMNS", "Measure", "label_key", "mm", "view_frame_labels"]
