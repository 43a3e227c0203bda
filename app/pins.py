"""Results kept to compare (pins), without Qt.

A phonetician pins the result on screen, changes something (the search, the labels, N, the
smoothing, the model) and sees the next result beside the pinned one: the lip panels draw each
pin's curves in its colour with a legend naming how it was made, the 3-D view shows the pinned
face beside the current one, a panel draws the difference of the lip aperture (this result
minus each pin's), and the Measure readout gives both at the cursor. :class:`PinBoard` holds the
pins; a pin is shown with the utterance it was made of (same name and length), and with a model
of the same marker set.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from facetraj_engine.analysis.apertures import aperture

from .provenance import synthesis_parts
from .state import UtteranceView

#: the pins' colours, in turn: apart from the original's blue, the synthesis's oranges, the
#: cursor, the closed line and the loop range (a teal third was hard to tell from the original's
#: blue dashes; a brown one from the spline's dark orange, 16 CIEDE2000 units): green, purple,
#: cyan (33 units or more from each of them)
PIN_COLORS = ("#2f9e44", "#9c36b5", "#00b5d8")
#: the most pins kept at once (the oldest goes)
MAX_PINS = len(PIN_COLORS)


@dataclass(frozen=True, eq=False)
class Pin:
    """A result kept: its view (the synthesis and its tracks), its number and colour, how it was
    made (``parts``: every setting that changes the synthesis, :func:`~facetraj_app.provenance.
    synthesis_parts`), and the model it was made with (``model_name``: the corpus it was trained
    on; ``marker_names``: its marker set)."""

    number: int
    view: UtteranceView
    color: str
    parts: tuple[str, ...]
    model_name: str = ""
    marker_names: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        return f"pin {self.number}"

    @property
    def settings(self) -> str:
        """How it was made, in full (its model included)."""
        return ", ".join([*self.parts, *([f"model {self.model_name}"] if self.model_name else [])])

    def legend(self, model_name: str = "") -> str:
        """The pin and how it was made in full (its model too when it is not ``model_name``, the
        current one); :meth:`PinBoard.describe` says only what differs."""
        other = f"; model {self.model_name}" if self.model_name and self.model_name != model_name else ""
        return f"{self.name}: {', '.join(self.parts)}{other}"

    def matches(self, view: UtteranceView) -> bool:
        """Whether this pin is of ``view``'s utterance (same name, same length) and another
        result than ``view`` itself."""
        return (self.view is not view and self.view.utterance.name == view.utterance.name
                and self.view.n_frames == view.n_frames
                and len(self.view.utterance.audio) == len(view.utterance.audio))


@dataclass
class PinBoard:
    """The pins kept (at most :data:`MAX_PINS`, the oldest dropped first); ``model_name``: the
    current model's, for the legends; ``marker_names``: its marker set (pins of another are not
    shown)."""

    pins: list[Pin] = field(default_factory=list)
    model_name: str = ""
    marker_names: tuple[str, ...] = ()
    _count: int = 0

    def pinned(self, view: UtteranceView) -> Pin | None:
        """The pin of ``view`` itself (None: not pinned)."""
        return next((p for p in self.pins if p.view is view), None)

    def pin(self, view: UtteranceView) -> Pin:
        """Keep ``view`` (the result on screen) as a new pin (the same result is pinned once:
        its pin is returned)."""
        if (kept := self.pinned(view)) is not None:
            return kept
        used = {p.color for p in self.pins}
        if len(self.pins) >= MAX_PINS:
            used.discard(self.pins.pop(0).color)
        color = next(c for c in PIN_COLORS if c not in used)
        self._count += 1
        pin = Pin(self._count, view, color, tuple(synthesis_parts(view)), self.model_name,
                  self.marker_names)
        self.pins.append(pin)
        return pin

    def clear(self) -> None:
        self.pins.clear()

    def set_model(self, model_name: str, marker_names: Sequence[str]) -> None:
        self.model_name, self.marker_names = model_name, tuple(marker_names)

    def shown(self, view: UtteranceView | None) -> list[Pin]:
        """The pins to show with ``view``: of its utterance, with the current marker set."""
        if view is None:
            return []
        return [p for p in self.pins
                if p.matches(view) and (not p.marker_names or p.marker_names == self.marker_names)]

    def describe(self, view: UtteranceView, pins: Sequence[Pin]) -> list[str]:
        """What tells each of ``pins`` apart from ``view`` (the result on screen, made with the
        current model) and from each other: the settings, the labels or the model that differ
        (:func:`distinct_settings`); the toolbar's list and the lip panels' legend."""
        own = [*synthesis_parts(view), f"model {self.model_name}"]
        return distinct_settings([own, *([*p.parts, f"model {p.model_name or self.model_name}"]
                                         for p in pins)])[1:]

    def named(self, view: UtteranceView | None) -> list[tuple[Pin, str]]:
        """The pins shown with ``view``, each with its name and what tells it apart
        (:meth:`describe`): "pin 1: C=3" in the toolbar, the lip panels' legend and captions."""
        shown = self.shown(view)
        return [(p, f"{p.name}: {part}") for p, part in zip(shown, self.describe(view, shown), strict=True)] \
            if shown else []

    def __len__(self) -> int:
        return len(self.pins)


def distinct_settings(results: Sequence[Sequence[str] | str]) -> list[str]:
    """Of each result's settings (its parts, :func:`~facetraj_app.provenance.synthesis_parts`, or
    a text of parts joined by ", " or "; "), the parts not common to all (how each result differs
    from the others), or all its parts where nothing differs: the pins' list fits a laptop's
    toolbar.

    >>> distinct_settings(["robust, N=3, triangular; labels: aligned",
    ...                    "robust, N=3, triangular; labels: recognized"])
    ['labels: aligned', 'labels: recognized']
    >>> distinct_settings([["phonetic", "N=2", "C=3"], ["phonetic", "N=2", "C=2"]])
    ['C=3', 'C=2']
    """
    parts = [[p.strip() for chunk in r.split("; ") for p in chunk.split(", ")] if isinstance(r, str)
             else list(r) for r in results]
    common = set.intersection(*map(set, parts)) if parts else set()
    return [", ".join(p for p in ps if p not in common) or ", ".join(ps) for ps in parts]


def aperture_difference(view: UtteranceView, pin: Pin, upper: int, lower: int) -> np.ndarray:
    """Per frame, the lip aperture of ``view``'s synthesis (the 3-D view's) minus the pin's (mm)."""
    n = min(view.n_frames, pin.view.n_frames)
    return (aperture(view.shown[:n], upper, lower) - aperture(pin.view.shown[:n], upper, lower))


__all__ = ["MAX_PINS", "PIN_COLORS", "Pin", "PinBoard", "aperture_difference", "distinct_settings"]
