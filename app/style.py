"""Colours shared by the 3-D view and the panels, so a colour means the same thing everywhere, and
the placing of the panels' y labels."""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING
from weakref import WeakKeyDictionary

if TYPE_CHECKING:
    from matplotlib.lines import Line2D

ORIGINAL_COLOR = "#1f5fbf"      # original markers: blue
SYNTH_COLOR = "#e8590c"         # synthesized markers (the chosen smoothing): orange
SPLINE_COLOR = "#b33c00"        # synthesized, spline smoothing: dark orange
TRIANGULAR_COLOR = "#f7b27a"    # synthesized, triangular smoothing: light orange
SPEECH_DOT_COLOR = "#222222"    # speech/silence dots
CURSOR_COLOR = "#d6336c"        # the play cursor
LOOP_COLOR = "#fab005"          # the loop range (yellow: no pin's or curve's colour)
SURFACE_COLOR = "#ecc9ae"       # the face surface
CAVITY_COLOR = "#3b1f1a"        # the mouth opening (dark: the oral cavity behind the lips)
CLOSED_COLOR = "#5f6b3a"        # the lips at closure (the lip panels' reference line)
BACKGROUND = "#ffffff"
#: the legend's name of the line of the lips at closure
CLOSED_LABEL = "closed (the talker's /p b m/)"


#: the width of the timeline's left margin (figure edge to axes): tick labels and the y labels
LABEL_MARGIN_PX = 100.0
#: room kept for tick labels such as "-22.5" beside the axes
TICK_LABELS_PX = 34.0


def fit_ylabel(ax, label: str, max_size: float = 8.0, min_size: float = 6.0) -> None:
    """Set ``ax``'s y label so that it is readable and stays in the ``LABEL_MARGIN_PX`` margin at
    the axes' present size: running up the axes in the largest font (up to ``max_size`` points)
    whose longest line fits the axes' height; on a panel too short for that at ``min_size``,
    written across, left-aligned in the margin (its first line only if the lines do not fit the
    height either). Placed in pixels, so that every panel's label starts at the same x (call it
    again after a resize: :func:`refit_ylabels`)."""
    fig = ax.figure
    _LABELS[ax] = label
    bbox = ax.get_position()
    height_px = bbox.height * fig.get_figheight() * fig.dpi
    width_px = max(bbox.width * fig.get_figwidth() * fig.dpi, 1.0)
    px_per_pt = fig.dpi / 72.0
    lines = label.splitlines() or [""]
    longest = max(len(line) for line in lines)
    size = height_px / (0.62 * max(longest, 1) * px_per_pt)
    room = LABEL_MARGIN_PX - TICK_LABELS_PX
    if size >= min_size:
        size = min(max_size, size)
        x_px = 4.0 + 0.6 * len(lines) * size * px_per_pt      # the lines' centre, from the edge
        ax.set_ylabel(label, fontsize=size, rotation=90, ha="center", va="center")
    else:
        size = min_size + 1.0
        while len(lines) > 1 and 1.2 * len(lines) * size * px_per_pt > height_px:
            lines = lines[:1]
        widest = max(len(line) for line in lines) * 0.6 * size * px_per_pt
        if widest > room - 4:
            size = max(4.5, size * (room - 4) / widest)
        x_px = 4.0
        ax.set_ylabel("\n".join(lines), fontsize=size, rotation=0, ha="left", va="center")
    ax.yaxis.set_label_coords(-(LABEL_MARGIN_PX - x_px) / width_px, 0.5)


def closed_line(ax, y: float) -> Line2D:
    """The line of the talker's lips at closure (the middles of /p b m/) across ``ax`` at ``y``:
    dashed, under the curves, named in the legend."""
    return ax.axhline(y, color=CLOSED_COLOR, lw=0.9, ls=(0, (6, 3)), zorder=0.5, label=CLOSED_LABEL)


def refit_ylabels(axes) -> None:
    """Fit the y labels to the axes' present size again (the full text :func:`fit_ylabel` was
    given, else the label as set)."""
    for ax in axes:
        label = _LABELS.get(ax) or ax.get_ylabel()
        if label:
            fit_ylabel(ax, label)


_LABELS: WeakKeyDictionary = WeakKeyDictionary()     # axes -> its full y label


@functools.lru_cache(maxsize=512)
def text_width_px(text: str, size_pt: float, dpi: float = 100.0) -> float:
    """How wide ``text`` is at ``size_pt`` in matplotlib's default font, in pixels at ``dpi``
    (from the glyphs' outlines: no renderer needed).

    >>> round(text_width_px("phones (label file)", 7.0)), round(text_width_px("phones (recognized)", 7.0))
    (86, 98)
    """
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    return float(TextPath((0, 0), text, prop=FontProperties(size=size_pt)).get_extents().width
                 * dpi / 72.0)
