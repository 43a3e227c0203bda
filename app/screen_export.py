"""Exporting what is on screen: the time-aligned panels drawn again, by the same panel objects as
the window's (the same curves, "closed" line, speech dots, phones and pinned results), into a
figure of their own with a caption naming the utterance, where its labels came from and how it
was synthesized, and a legend in a band above the panels (never over them).

:func:`panels_figure` makes that figure (matplotlib only: exports and the video's frames,
``app/video.py``); :func:`caption_text` words the caption; :class:`PanelContext` is what the
panels read from the window (the model, the talker's closed lips, the pins) for a figure made
without one.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from dataclasses import dataclass, field

from matplotlib.figure import Figure
from matplotlib.transforms import Bbox

from .panel_layout import (
    GAP_PX,
    LegendEntry,
    fit_heights,
    legend_entries,
    legend_handles,
    panel_min_px,
    panel_priority,
)
from .pins import PinBoard
from .provenance import settings_text
from .state import UtteranceView
from .style import CURSOR_COLOR, LABEL_MARGIN_PX
from .timeline import BOTTOM_MARGIN_PX, TOP_MARGIN_PX, LipPanel, PhoneTierPanel, draw_panel
from .viewer_model import view_heading

CAPTION_PT = 9.0
CAPTION_SEPARATOR = "  ·  "
LEGEND_PT = 8.0


@dataclass
class PanelContext:
    """What the panels read from the window, for a figure made without one: the ``model``, the
    talker's ``closed_lips`` and the ``pins``."""

    model: object
    closed_lips: object = None
    pins: PinBoard = field(default_factory=PinBoard)


def caption_text(view: UtteranceView, pins: Sequence[str] = (), heading: str | None = None) -> str:
    """The utterance, its sentence (not for recognized labels), how it was synthesized and where
    the labels came from, and each pinned result shown with it (``pins``: their texts,
    ``PinBoard.named``, what tells each apart, as the toolbar says); ``heading``: written in
    place of the utterance and its sentence ("": nothing)."""
    head = view_heading(view, " ") if heading is None else heading
    parts = ([head] if head else []) + [f"synthesized: {settings_text(view)}"]
    return CAPTION_SEPARATOR.join(parts + list(pins))


def main_panels(context) -> list:
    """The panels a figure of the lips shows: the phones, the upper and the lower lip."""
    return [PhoneTierPanel(context), LipPanel(context, "upper"), LipPanel(context, "lower")]


LEGEND_STYLE = dict(fontsize=LEGEND_PT, frameon=False, borderaxespad=0.0, handlelength=2.2,
                    columnspacing=1.2, borderpad=0.2)


def fitting_columns(fig: Figure, entries: Sequence[LegendEntry], width_px: float,
                    style: dict | None = None) -> int:
    """The most columns a legend of ``entries`` (drawn with ``style``) can have on ``fig`` and be
    no wider than ``width_px``, measured."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    for ncol in range(len(entries), 1, -1):
        legend = fig.legend(handles=legend_handles(entries), ncol=ncol, **(style or LEGEND_STYLE))
        wide = legend.get_window_extent(renderer).width
        legend.remove()
        if wide <= width_px:
            return ncol
    return 1


@dataclass
class FigureLayout:
    """Where a :func:`panels_figure`'s parts are (display pixels, y up; after a draw)."""

    caption: object = None
    legend: object = None
    axes: list = field(default_factory=list)
    shown: list = field(default_factory=list)

    def boxes(self, renderer) -> dict[str, Bbox]:
        out = {}
        if self.caption is not None:
            out["caption"] = self.caption.get_window_extent(renderer)
        if self.legend is not None:
            out["legend"] = self.legend.get_window_extent(renderer)
        return out


def panels_figure(panels: Sequence, view: UtteranceView, size_px: tuple[int, int], dpi: float = 100.0,
                  xlim: tuple[float, float] | None = None, cursor: float | None = None,
                  caption: str = "", legend: bool = True,
                  extra_entries: Sequence[LegendEntry] = (),
                  min_scale: float = 1.0) -> tuple[Figure, FigureLayout]:
    """The ``panels`` of ``view`` on a new figure of ``size_px`` (at ``dpi``), drawn as the
    timeline draws them, over the time range ``xlim`` (the whole utterance by default), with the
    cursor at ``cursor`` seconds, ``caption`` on top and the panels' legend (and
    ``extra_entries``) under it. Panels that have no room at that size are left out as the
    window leaves them out (``panel_layout.fit_heights``; ``min_scale``: their least heights
    scaled, for a small video frame)."""
    fig = Figure(figsize=(size_px[0] / dpi, size_px[1] / dpi), dpi=dpi, facecolor="white")
    scale = dpi / 100.0                     # the window's pixel margins at this resolution
    width, height = size_px
    layout = FigureLayout()
    top = TOP_MARGIN_PX * scale
    if caption:
        chars = max(20, int(width / (0.55 * CAPTION_PT * dpi / 72.0)))
        lines = textwrap.wrap(caption, chars)
        layout.caption = fig.text(6 * scale / width, 1 - top / height, "\n".join(lines),
                                  ha="left", va="top", fontsize=CAPTION_PT, color="#222222")
        top += len(lines) * 1.3 * CAPTION_PT * dpi / 72.0 + 4 * scale
    # the panels first (their curves name the legend's entries), then the legend over them
    bottom = BOTTOM_MARGIN_PX * scale
    room = height - top - bottom - (2 * 1.45 * LEGEND_PT * dpi / 72.0 if legend else 0)  # 2 rows
    heights = fit_heights([p.height for p in panels], [panel_min_px(p) * scale * min_scale for p in panels],
                          [panel_priority(p) for p in panels], room)
    layout.shown = [p for p, h in zip(panels, heights, strict=True) if h is not None]
    return _draw(fig, layout, view, [h for h in heights if h is not None], top, bottom, xlim, cursor,
                 legend, extra_entries, scale)


def _draw(fig: Figure, layout: FigureLayout, view: UtteranceView, heights: list[float], top: float,
          bottom: float, xlim, cursor, legend: bool, extra: Sequence[LegendEntry],
          scale: float) -> tuple[Figure, FigureLayout]:
    width, height = fig.get_figwidth() * fig.dpi, fig.get_figheight() * fig.dpi
    entries: list[LegendEntry] = []
    counted: list[LegendEntry] = []         # the entries ``ncol`` was measured for
    ncol = 1
    legend_px = 0.0
    for _ in range(2):                      # the legend's height known once its entries are
        grid = fig.add_gridspec(len(heights), 1, height_ratios=heights,
                                left=LABEL_MARGIN_PX * scale / width, right=1 - 8 * scale / width,
                                top=1 - (top + legend_px) / height, bottom=bottom / height,
                                hspace=GAP_PX * scale / max(sum(heights) / len(heights), 1.0))
        for ax in list(fig.axes):
            ax.remove()
        first = None
        layout.axes = []
        for i, panel in enumerate(layout.shown):
            ax = fig.add_subplot(grid[i, 0], sharex=first)
            first = first or ax
            draw_panel(panel, ax, view, last=i == len(layout.shown) - 1)
            layout.axes.append(ax)
        entries = (legend_entries(layout.axes) + list(extra)) if legend else []
        if not entries:
            break
        if entries != counted:
            counted, ncol = entries, fitting_columns(fig, entries, width - 12 * scale)
        rows = -(-len(entries) // ncol)
        needed = rows * 1.45 * LEGEND_PT * fig.dpi / 72.0 + 6 * scale
        if abs(needed - legend_px) < 1:
            break
        legend_px = needed
    if first is not None:
        first.set_xlim(*(xlim or (0.0, view.duration)))
        if cursor is not None:
            for ax in layout.axes:
                ax.axvline(cursor, color=CURSOR_COLOR, lw=1.2)
    if entries:
        layout.legend = fig.legend(handles=legend_handles(entries), loc="upper left",
                                   bbox_to_anchor=(6 * scale / width, 1 - top / height),
                                   ncol=ncol, **LEGEND_STYLE)
    return fig, layout


def point_entries(original: bool) -> list[LegendEntry]:
    """The 3-D view's point colours as legend entries (a video's face beside the panels)."""
    from .style import ORIGINAL_COLOR, SYNTH_COLOR

    out = [LegendEntry("original points", ORIGINAL_COLOR, "dots")] if original else []
    out.append(LegendEntry("synthesized points", SYNTH_COLOR, "dots"))
    return out


__all__ = ["FigureLayout", "PanelContext", "caption_text", "fitting_columns", "main_panels",
           "panels_figure", "point_entries"]
