"""How the time-aligned panels share the timeline's height, and their legend, without Qt.

Every panel has a relative ``height``, a ``min_px`` under which it is not readable (a lip panel
needs room for three tick labels and its curves) and a ``priority``. :func:`fit_heights` gives
each panel its share of the height, none less than its minimum: when the timeline is too short
for all of them (a laptop screen with analysis docks open) the panels of lowest priority (the
spectrogram, then the waveform) are left out, never the lip panels squeezed to a sliver.

:func:`legend_entries` reads what the panels' curves are called (their matplotlib ``label``s)
into :class:`LegendEntry` objects, one per name; the window draws them in a row above the
panels (``app/timeline.py``) and exported figures in a band above theirs
(``app/screen_export.py``): a legend is never drawn over the data.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass

#: the defaults of a panel that does not say (``min_px``, ``priority``)
DEFAULT_MIN_PX = 48.0
DEFAULT_PRIORITY = 50
#: the gap between two panels (px)
GAP_PX = 6.0


def panel_min_px(panel) -> float:
    return float(getattr(panel, "min_px", DEFAULT_MIN_PX))


def panel_priority(panel) -> int:
    return int(getattr(panel, "priority", DEFAULT_PRIORITY))


def min_scale_to_fit(min_px: Sequence[float], available_px: float, floor: float,
                     gap_px: float = GAP_PX) -> float:
    """The scale (at most 1, at least ``floor``) of the panels' least heights ``min_px`` at
    which all of them fit ``available_px`` with their gaps: a video keeps every panel the window
    shows, each a little lower, before :func:`fit_heights` leaves one out.

    >>> min_scale_to_fit([100, 100], 300, 0.45), min_scale_to_fit([100, 100], 106, 0.45)
    (1.0, 0.5)
    >>> min_scale_to_fit([100, 100], 50, 0.45)
    0.45
    """
    need = float(sum(min_px))
    room = available_px - gap_px * max(len(min_px) - 1, 0)
    return float(min(1.0, max(floor, room / need))) if need > 0 else 1.0


def fit_heights(heights: Sequence[float], min_px: Sequence[float], priority: Sequence[int],
                available_px: float, gap_px: float = GAP_PX) -> list[float | None]:
    """The height in pixels of each panel (``None``: left out for lack of room).

    Panels are left out, lowest ``priority`` first (the later one of equal priority first),
    until the rest fit at their minimum heights with ``gap_px`` between them; the panel of
    highest priority is always kept. The height left over is shared in proportion to
    ``heights``, each panel getting at least its minimum.

    >>> fit_heights([1, 1, 2], [40, 40, 60], [10, 20, 100], 400)
    [97.0, 97.0, 194.0]
    >>> fit_heights([1, 1, 2], [40, 40, 60], [10, 20, 100], 150)
    [None, 48.0, 96.0]
    >>> fit_heights([1, 4], [40, 60], [10, 100], 120)
    [40.0, 74.0]
    """
    n = len(heights)
    keep = [True] * n
    order = sorted(range(n), key=lambda i: (priority[i], -i))

    def needed() -> float:
        shown = [i for i in range(n) if keep[i]]
        return sum(min_px[i] for i in shown) + gap_px * max(len(shown) - 1, 0)

    for i in order[:-1]:
        if needed() <= available_px:
            break
        keep[i] = False
    shown = [i for i in range(n) if keep[i]]
    room = max(available_px - gap_px * max(len(shown) - 1, 0), 0.0)
    out: list[float | None] = [None] * n
    # proportional shares; a panel below its minimum gets the minimum and leaves the share
    fixed: dict[int, float] = {}
    while True:
        free = [i for i in shown if i not in fixed]
        left = room - sum(fixed.values())
        total = sum(heights[i] for i in free) or 1.0
        short = [i for i in free if left * heights[i] / total < min_px[i]]
        if not short:
            break
        for i in short:
            fixed[i] = float(min_px[i])
    for i in shown:
        out[i] = fixed.get(i, left * heights[i] / total)
    return [None if h is None else round(h, 3) for h in out]


@dataclass(frozen=True)
class LegendEntry:
    """One named curve of the panels: its name, colour and how it is drawn (``solid``,
    ``dashed``, ``dotted``, ``dots`` for markers without a line, ``band`` for a filled area)."""

    label: str
    color: str
    style: str
    width: float = 1.5


def _style(handle) -> str:
    """How a matplotlib legend handle is drawn (see :class:`LegendEntry`)."""
    if not hasattr(handle, "get_xdata"):
        return "band"                               # a patch or a filled collection
    ls = handle.get_linestyle()
    if ls in ("--", "-."):
        return "dashed"                             # (a dash pattern reads back as "--")
    if ls == ":":
        return "dotted"
    if ls in ("None", "none", "", " "):
        return "dots" if handle.get_marker() not in (None, "None", "none", "") else "band"
    return "solid"


def _colour(handle) -> str:
    from matplotlib.colors import to_hex

    for getter in ("get_color", "get_facecolor", "get_edgecolor"):
        fn = getattr(handle, getter, None)
        if fn is None:
            continue
        value = fn()
        if hasattr(value, "ndim") and getattr(value, "ndim", 0) == 2:
            value = value[0] if len(value) else "#000000"
        try:
            return to_hex(value)
        except (ValueError, TypeError):
            continue
    return "#000000"


def legend_entries(axes) -> list[LegendEntry]:
    """The named curves of ``axes`` (every artist with a label not starting with "_"), one entry
    per name in the order first met."""
    seen: dict[str, LegendEntry] = {}
    for ax in axes:
        handles, labels = ax.get_legend_handles_labels()
        for handle, label in zip(handles, labels, strict=True):
            if label and not label.startswith("_") and label not in seen:
                seen[label] = LegendEntry(label, _colour(handle), _style(handle),
                                          float(getattr(handle, "get_linewidth", lambda: 1.5)() or 1.5))
    return list(seen.values())


#: the sample drawn before each name in the window's legend row (text: it wraps with the row)
SAMPLES = {"solid": "━━", "dashed": "╺\u00a0╸", "dotted": "┈┈", "dots": "•", "band": "▬"}


def _unbroken(text: str) -> str:
    """``text`` as rich text that is never broken across lines (non-breaking spaces, a word
    joiner after each slash: "/p b m/")."""
    return html.escape(text).replace(" ", "&nbsp;").replace("/", "/&#8288;")


def legend_html(entries: Sequence[LegendEntry], note: str = "") -> str:
    """The legend row as rich text: each entry a coloured sample and its name, kept together
    (non-breaking spaces: the row wraps between entries, not inside one); ``note`` after them
    in grey.

    >>> legend_html([LegendEntry("speech frames", "#222222", "dots")])
    '<span style="color:#222222"><b>•</b></span>&nbsp;speech&nbsp;frames'
    """
    parts = [f'<span style="color:{e.color}"><b>{SAMPLES[e.style]}</b></span>&nbsp;'
             f'{_unbroken(e.label)}' for e in entries]
    if note:
        parts.append(f'<span style="color:#777777">{html.escape(note)}</span>')
    return " &nbsp;&nbsp; ".join(parts)


def legend_handles(entries: Sequence[LegendEntry]) -> list:
    """Matplotlib handles drawing the entries as the panels draw them (exported figures)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    out = []
    for e in entries:
        if e.style == "band":
            out.append(Patch(color=e.color, label=e.label))
        elif e.style == "dots":
            out.append(Line2D([], [], ls="none", marker=".", ms=6, color=e.color, label=e.label))
        else:
            ls = {"solid": "-", "dashed": (0, (5, 2.5)), "dotted": (0, (2, 1.5))}[e.style]
            out.append(Line2D([], [], ls=ls, lw=e.width, color=e.color, label=e.label))
    return out


__all__ = ["GAP_PX", "LegendEntry", "fit_heights", "legend_entries", "legend_handles", "legend_html",
           "panel_min_px", "panel_priority"]
