"""Labels of time spans (phones, words) that are drawn only where they fit.

A phone tier at a narrow width (a laptop screen, an analysis dock open) cannot show every label:
drawn anyway they run together ("taorn", "dowz"). :class:`FittedLabels` is one matplotlib
artist for a whole row of labels; at every draw (any size, zoom or export resolution) it
measures each label and draws it centred on its span only if it fits inside the span and clear
of the label before it, shortened with "…" (words) or left out (phones) when it does not.
``drawn`` lists what the last draw put where (display pixels) and for which span, for tests.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from matplotlib.artist import Artist
from matplotlib.font_manager import FontProperties
from matplotlib.text import Text
from matplotlib.transforms import Bbox, IdentityTransform

#: the least room between two labels, and between a label and its span's edges (px at 72 dpi)
MARGIN_PT = 1.5
ELLIPSIS = "…"


@dataclass(frozen=True)
class Span:
    """One label to draw over ``[start, end]`` (seconds) at height ``y`` (data units)."""

    start: float
    end: float
    label: str
    y: float
    color: str = "black"
    style: str = "normal"


class FittedLabels(Artist):
    """A row of span labels of ``ax`` drawn where they fit (see the module docstring);
    ``shorten``: a label too wide is cut to fit with "…" (at least ``min_chars`` letters)
    instead of being left out."""

    def __init__(self, ax, spans: Sequence[Span], fontsize: float = 8.0, shorten: bool = False,
                 min_chars: int = 2):
        super().__init__()
        self.axes = ax
        self.spans = list(spans)
        self.fontsize = fontsize
        self.shorten = shorten
        self.min_chars = min_chars
        self.drawn: list[tuple[str, Bbox, tuple[float, float]]] = []   # text, extent, span (px)
        self.set_zorder(3)

    def _width(self, renderer, text: str, prop: FontProperties) -> float:
        w, _h, _d = renderer.get_text_width_height_descent(text, prop, ismath=False)
        return w

    def _fit(self, renderer, label: str, room: float, prop: FontProperties) -> str | None:
        """``label``, or as much of it as fits in ``room`` px with "…", or None."""
        if self._width(renderer, label, prop) <= room:
            return label
        if not self.shorten:
            return None
        for n in range(len(label) - 1, self.min_chars - 1, -1):
            cut = label[:n].rstrip() + ELLIPSIS
            if self._width(renderer, cut, prop) <= room:
                return cut
        return None

    def draw(self, renderer) -> None:
        self.drawn = []
        if not self.get_visible() or not self.spans:
            return
        ax = self.axes
        box = ax.bbox
        margin = MARGIN_PT * renderer.points_to_pixels(1.0)
        to_px = ax.transData.transform
        last_right = -float("inf")
        for span in self.spans:
            (x0, y), (x1, _) = to_px([(span.start, span.y), (span.end, span.y)])
            left, right = max(x0, box.x0), min(x1, box.x1)
            prop = FontProperties(size=self.fontsize, style=span.style)
            room = right - left - 2 * margin
            if room <= 0:
                continue
            text = self._fit(renderer, span.label, room, prop)
            if text is None:
                continue
            width = self._width(renderer, text, prop)
            centre = 0.5 * (left + right)
            if centre - width / 2 < last_right + margin:
                continue                    # it would touch the label before it
            artist = Text(centre, y, text, ha="center", va="center", fontproperties=prop,
                          color=span.color, transform=IdentityTransform(), figure=self.figure)
            artist.draw(renderer)
            extent = artist.get_window_extent(renderer)
            self.drawn.append((text, extent, (left, right)))
            last_right = extent.x1
        self.stale = False


class StackedLabels(Artist):
    """Labels of spans that must all be read (the lip-error panel's worst segments): each centred
    over its span (kept inside the axes) at the top, and one that would touch a label already
    drawn goes a row lower, as many rows as it takes: never one over another (they printed over
    each other: "sp 9.4", "L", "AE", "9.9"). A label has a white backing, so that a lower row is
    read over the curves. ``drawn`` as :class:`FittedLabels`' (text, extent, span in px)."""

    def __init__(self, ax, spans: Sequence[Span], fontsize: float = 7.0):
        super().__init__()
        self.axes = ax
        self.spans = sorted(spans, key=lambda s: s.start)
        self.fontsize = fontsize
        self.drawn: list[tuple[str, Bbox, tuple[float, float]]] = []
        self.set_zorder(4)

    def draw(self, renderer) -> None:
        self.drawn = []
        if not self.get_visible() or not self.spans:
            return
        box = self.axes.bbox
        margin = MARGIN_PT * renderer.points_to_pixels(1.0)
        placed: list[Bbox] = []
        for span in self.spans:
            (x0, _), (x1, _) = self.axes.transData.transform([(span.start, 0), (span.end, 0)])
            prop = FontProperties(size=self.fontsize, style=span.style)
            w, h, _d = renderer.get_text_width_height_descent(span.label, prop, ismath=False)
            centre = min(max(0.5 * (x0 + x1), box.x0 + w / 2 + margin), box.x1 - w / 2 - margin)
            top = box.y1 - margin
            while top - h > box.y0 and any(
                    b.x0 - margin < centre + w / 2 and centre - w / 2 < b.x1 + margin
                    and b.y0 - margin < top and top - h < b.y1 + margin for b in placed):
                top -= h + 2 * margin                     # a row lower
            artist = Text(centre, top, span.label, ha="center", va="top", fontproperties=prop,
                          color=span.color, transform=IdentityTransform(), figure=self.figure,
                          bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 0.5})
            artist.draw(renderer)
            extent = Bbox.from_extents(centre - w / 2, top - h, centre + w / 2, top)
            placed.append(extent)
            self.drawn.append((span.label, extent, (x0, x1)))
        self.stale = False


__all__ = ["FittedLabels", "Span", "StackedLabels"]
