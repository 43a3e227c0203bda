"""The time-aligned panels under the 3-D view: one matplotlib figure, one shared time axis.

A panel is any object with ``title: str``, ``height: float`` (relative) and
``draw(ax, view) -> None``. The timeline lays the panels out, redraws them when the view changes,
and draws the moving cursor by blitting (a full redraw happens only on layout, zoom or pan): the
cursor of every panel is one line artist in pixels, restored and drawn over a strip in one pass.

Full draws run in the background (``app/figure_canvas.py``); while one runs the figure is not
changed (a relayout waits for it), and panels added by a view are built one per pass of the event
loop (``relayout(soon=True)``), so that opening a view never freezes the window.

Mouse: click to seek, drag to select a loop range, wheel to zoom the time axis around the pointer,
right or middle drag to pan, double-click to show the whole utterance. A panel may take a press
of the left button itself (``mouse_press(event)`` returning an object with ``move(event)`` and
``release(event)``: the phone tier's boundary drags, ``app/tier_edit.py``).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Protocol

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.transforms import Bbox, IdentityTransform
from PyQt6 import sip
from PyQt6.QtCore import Qt, QTimer, pyqtSignal
from PyQt6.QtWidgets import QLabel, QSizePolicy, QVBoxLayout, QWidget

from facetraj_engine.analysis.apertures import SILENT_LABELS

from .figure_canvas import BackgroundCanvas, SteppedBuild
from .panel_layout import GAP_PX, fit_heights, legend_entries, legend_html, panel_min_px, panel_priority
from .state import UtteranceView
from .style import (
    CURSOR_COLOR,
    LABEL_MARGIN_PX,
    LOOP_COLOR,
    ORIGINAL_COLOR,
    SPEECH_DOT_COLOR,
    SPLINE_COLOR,
    TRIANGULAR_COLOR,
    closed_line,
    fit_ylabel,
    refit_ylabels,
    text_width_px,
)
from .tier_labels import FittedLabels, Span

#: the lines the legend row may grow by when more panels are shown (their curves' entries)
LEGEND_SWING_LINES = 2

log = logging.getLogger(__name__)

#: the loop range's spans are told from the panels' own artists by this id
LOOP_GID = "loop range"
#: the timeline's bottom margin: the time tick labels and "time (s)"
BOTTOM_MARGIN_PX = 40.0
#: the timeline's top margin (px)
TOP_MARGIN_PX = 4.0
#: the widest row name of the phone tier (its glyphs' outline, px at 100 dpi) written at full
#: size (7 pt) in the left margin (100 px, less the tick pad and what the outline leaves out);
#: a wider one ("phones (recognized)": 98 px) smaller
ROW_NAME_PX = 82.0


class _Canvas(BackgroundCanvas):
    """A canvas whose full draws run off the GUI thread (``app/figure_canvas.py``: a resize, a
    zoom or new panels do not freeze the window) and whose ``blit`` schedules the repaint instead
    of forcing it: the window then puts the cursor, the 3-D frame and the widgets on screen in one
    flush per frame (each flush composes the whole window through OpenGL once a GL widget is in
    it)."""

    def blit(self, bbox=None) -> None:
        if bbox is None:
            bbox = self.figure.bbox
        left, bottom, w, h = (int(pt / self.device_pixel_ratio) for pt in bbox.bounds)
        self.update(left, self.rect().height() - (bottom + h), w + 1, h + 1)


class Panel(Protocol):
    """A time-aligned panel. Optional attributes: ``min_px`` (the least height it is readable at,
    default 48) and ``priority`` (panels of low priority are left out first when the timeline is
    short: ``app/panel_layout.py``), and ``mouse_press(event)``: a left-button press in the
    panel, which the panel takes by returning an object with ``move(event)`` and
    ``release(event)`` (else ``None``: the timeline seeks or selects a loop range). Curves named
    with a matplotlib ``label`` appear in the timeline's legend row, never in a legend over the
    panel."""

    title: str
    height: float

    def draw(self, ax, view: UtteranceView) -> None: ...


# ---------------------------------------------------------------------- built-in panels
class WaveformPanel:
    """The speech signal (min/max envelope per pixel column)."""

    audio_only = True           # the same for every result of a recording
    title = "waveform"
    height = 0.8
    min_px = 24.0
    priority = 20               # left out before every other panel but the spectrogram

    def draw(self, ax, view: UtteranceView) -> None:
        x = view.utterance.audio
        rate = view.utterance.sample_rate
        bins = min(len(x), 6000)
        step = max(1, len(x) // bins)
        n = (len(x) // step) * step
        blocks = x[:n].reshape(-1, step)
        t = (np.arange(blocks.shape[0]) + 0.5) * step / rate
        ax.fill_between(t, blocks.min(axis=1), blocks.max(axis=1), color="#333333", lw=0.4,
                        step="mid")
        peak = float(np.abs(x).max()) or 1.0
        ax.set_ylim(-1.05 * peak, 1.05 * peak)
        ax.set_yticks([])
        ax.set_ylabel("speech", fontsize=8)


def spectrogram(x: np.ndarray, rate: float, nperseg: int, hop: int,
                nfft: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frequencies, segment-centre times and power spectral density ``(freqs, segments)`` of
    ``x``: periodic Hamming window, each segment's mean removed, one-sided density scaling.

    The same values as ``scipy.signal.spectrogram(x, rate, window="hamming", nperseg=nperseg,
    noverlap=nperseg - hop, nfft=nfft, mode="psd")`` (tested), without importing scipy.signal,
    which takes 1-2 s and would delay the window's first frame.
    """
    x = np.asarray(x, dtype=np.float64)
    n_seg = (len(x) - nperseg) // hop + 1
    win = np.hamming(nperseg + 1)[:-1]
    seg = np.lib.stride_tricks.sliding_window_view(x, nperseg)[::hop][:n_seg]
    seg = (seg - seg.mean(axis=1, keepdims=True)) * win
    psd = np.abs(np.fft.rfft(seg, nfft, axis=1)) ** 2 / (rate * np.sum(win ** 2))
    psd[:, 1:-1 if nfft % 2 == 0 else None] *= 2.0
    freqs = np.fft.rfftfreq(nfft, 1.0 / rate)
    times = (nperseg / 2 + hop * np.arange(n_seg)) / rate
    return freqs, times, psd.T


class SpectrogramPanel:
    """A wide-band spectrogram (grey scale, 0 to 8 kHz)."""

    audio_only = True
    title = "spectrogram"
    height = 1.3
    min_px = 40.0
    priority = 10               # the first left out on a short timeline
    max_freq = 8000.0

    def draw(self, ax, view: UtteranceView) -> None:
        x = view.utterance.audio
        rate = view.utterance.sample_rate
        nper = max(16, int(0.006 * rate))
        hop = max(1, int(0.002 * rate))
        f, t, s = spectrogram(x, rate, nper, hop, max(256, 2 ** int(np.ceil(np.log2(nper)))))
        keep = f <= self.max_freq
        db = 10 * np.log10(s[keep] + 1e-14)
        top = float(db.max())
        ax.imshow(db, origin="lower", aspect="auto", cmap="gray_r", vmin=top - 65, vmax=top,
                  extent=(float(t[0]), float(t[-1]), 0.0, float(f[keep][-1]) / 1000.0),
                  interpolation="bilinear", rasterized=True)
        ax.set_ylabel("kHz", fontsize=8)


def tier_rows(view: UtteranceView, pins: Sequence = ()) -> list[tuple[str, list, str]]:
    """The rows of the phone tier, bottom up: (name, segments, kind "phones" | "words", colour):
    the phones, a pinned result's phones where its labels differ (``pins``: objects with ``name``,
    ``view`` and ``color``), then the words."""
    utt = view.utterance
    rows = [(f"phones ({view.label_origin.short()})" if utt.phones else "phones", list(utt.phones),
             "phones", "black")]
    for pin in pins:
        phones = list(pin.view.utterance.phones)
        if phones and phones != list(utt.phones):
            rows.append((f"{pin.name}: {pin.view.label_origin.short()}", phones, "phones", pin.color))
    if utt.words:
        rows.append(("words", list(utt.words), "words", "black"))
    return rows


class PhoneTierPanel:
    """Word and phone labels with their boundaries (and the phones of a pinned result whose
    labels differ: ``context.pins``), each row named beside it; a label is drawn only where it
    fits (:class:`facetraj_app.tier_labels.FittedLabels`: phones left out, words shortened)."""

    title = "phones"
    height = 0.8
    min_px = 30.0
    priority = 90

    def __init__(self, context):
        self.context = context
        self.labels: list[FittedLabels] = []     # the rows' label artists of the last draw

    def draw(self, ax, view: UtteranceView) -> None:
        rows = tier_rows(view, self.context.pins.shown(view))
        ax.set_ylim(0, len(rows))
        # each row named beside it, the phones with where they came from (a y label "words
        # phones (aligned)" shrank to a few pixels); the title and status line say it in full
        ax.set_yticks([k + 0.5 for k in range(len(rows))], [r[0] for r in rows])
        for tick, row in zip(ax.get_yticklabels(), rows, strict=True):
            # a long name ("phones (recognized)") smaller, so that it stays in the left margin
            width = text_width_px(row[0], 7.0)
            tick.set(color=row[3], fontsize=max(5.0, min(7.0, 7.0 * ROW_NAME_PX / width)))
        ax.tick_params(axis="y", length=0)
        if not view.utterance.phones:
            ax.text(0.5, 0.5 / len(rows), "no phone labels: acoustic-only synthesis",
                    transform=ax.transAxes, ha="center", va="center", fontsize=8, color="#777777")
        # the boundaries: one line collection per row, x in data, y in axes coordinates
        across = ax.get_xaxis_transform()
        self.labels = []
        for k, (_name, segments, kind, color) in enumerate(rows):
            lo, hi = k / len(rows), (k + 1) / len(rows)
            if kind == "phones":
                for seg in segments:
                    if seg.label in SILENT_LABELS:
                        ax.axvspan(seg.start, seg.end, lo, hi, color="#eeeeee", lw=0)
            if segments:
                ax.vlines(sorted({t for s in segments for t in (s.start, s.end)}), lo, hi,
                          transform=across, color="#888888", lw=0.6)
            if k:
                ax.axhline(k, color="#bbbbbb", lw=0.5)
            spans = [Span(s.start, s.end, s.label, k + 0.5,
                          "#999999" if s.label in SILENT_LABELS else color,
                          "italic" if kind == "words" else "normal") for s in segments]
            fitted = FittedLabels(ax, spans, fontsize=8, shorten=kind == "words")
            ax.add_artist(fitted)
            self.labels.append(fitted)


class LipPanel:
    """Upper- or lower-lip centre y: original (dashed), spline (dark) and triangular (light)
    synthesis, and the speech/silence dots on a line through the middle (paper Figure 4); a
    dashed line marks where the talker's lip is when the lips are closed. ``context`` gives the
    ``model``, its ``closed_lips`` and the ``pins`` (results kept to compare: their curves in
    their colours) — the main window, or a plain object for exports."""

    height = 1.2
    min_px = 72.0
    priority = 100

    def __init__(self, context, which: str):
        self.context = context
        self.which = which
        self.title = f"{which} lip y"

    def marker(self) -> int:
        model = self.context.model
        return model.upper_lip if self.which == "upper" else model.lower_lip

    def draw(self, ax, view: UtteranceView) -> None:
        k = self.marker()
        t = view.times
        tri = view.triangular[:, k, 1]
        spl = view.spline[:, k, 1]
        ax.plot(t, tri, color=TRIANGULAR_COLOR, lw=1.6, label="synthesized, triangular")
        ax.plot(t, spl, color=SPLINE_COLOR, lw=1.3, label="synthesized, spline")
        ys = [tri, spl]
        if view.original is not None:
            orig = view.original[:, k, 1]
            ax.plot(t, orig, color=ORIGINAL_COLOR, lw=1.5, ls=(0, (2, 1.5)), label="original")
            ys.append(orig)
        for pin, text in self.context.pins.named(view):
            y = pin.view.shown[:, k, 1]
            ax.plot(pin.view.times[:len(y)], y, color=pin.color, lw=1.4, ls=(0, (6, 2)), label=text)
            ys.append(y)
        closed = self.context.closed_lips
        closed_y = float(closed.markers[k, 1]) if closed is not None else None
        extra = [np.array([closed_y])] if closed_y is not None else []
        allv = np.concatenate([y[np.isfinite(y)] for y in ys] + extra)
        lo, hi = float(allv.min()), float(allv.max())
        pad = 0.12 * max(hi - lo, 0.5)
        ax.set_ylim(lo - pad, hi + pad)          # no room kept for a legend: it is above the panels
        mid = (lo + hi) / 2
        sp = view.speech
        ax.plot(t[sp], np.full(int(sp.sum()), mid), ls="none", marker=".", ms=2.2,
                color=SPEECH_DOT_COLOR, label="speech frames")
        if closed_y is not None:     # the talker's lip at closure (the middles of /p b m/)
            closed_line(ax, closed_y)
        fit_ylabel(ax, f"{self.which} lip\ny (mm)")


def place_grid(fig: Figure, grid, heights: list[float]) -> None:
    """The panels' ``grid`` in pixels: the margins (the y labels and tick labels; the time
    axis) and the gaps fixed whatever the size, each panel its height of ``heights``."""
    width, height = max(fig.get_figwidth() * fig.dpi, 1.0), max(fig.get_figheight() * fig.dpi, 1.0)
    mean = max(sum(heights) / max(len(heights), 1), 1.0)
    grid.set_height_ratios(heights)
    grid.update(left=min(0.3, LABEL_MARGIN_PX / width), right=1 - min(0.05, 8 / width),
                top=1 - min(0.05, TOP_MARGIN_PX / height),
                bottom=min(0.3, BOTTOM_MARGIN_PX / height), hspace=GAP_PX / mean)


def redraw_in_place(panels: Sequence[Panel], axes: Sequence, view: UtteranceView) -> None:
    """Each panel drawn again in its axes for another result of the same recording (a label
    edit, other settings): the artists it drew removed (the loop range's kept), the axes kept
    (made anew they cost 40 ms each), the panels of the audio alone (``audio_only``) as they
    are."""
    for i, (panel, ax) in enumerate(zip(panels, axes, strict=True)):
        if getattr(panel, "audio_only", False):
            continue
        for artist in [*ax.lines, *ax.collections, *ax.patches, *ax.texts, *ax.images, *ax.artists]:
            if artist.get_gid() != LOOP_GID:
                artist.remove()
        draw_panel(panel, ax, view, last=i == len(axes) - 1)


def redraw_soon(timeline: Timeline, view: UtteranceView) -> None:
    """:func:`redraw_in_place` of ``timeline``'s panels for ``view`` (now, or right after the
    background draw running), then a full draw in the background."""
    shown, axes = list(timeline.shown), list(timeline.axes)

    def redo() -> None:      # not over a layout being built since (its axes taken off the figure)
        if timeline.view is view and axes == timeline.axes and \
                all(ax.figure is timeline.figure for ax in axes):
            redraw_in_place(shown, axes, view)
            timeline.redraw()

    timeline.canvas.when_idle(redo)


def draw_panel(panel: Panel, ax, view: UtteranceView, last: bool) -> None:
    """Draw ``panel`` in ``ax`` as the timeline does (the window's and exported figures): its
    content, its y label fitted, small ticks, the time labels under the last panel only."""
    ax.tick_params(labelsize=7, length=2)   # first: a panel may size its own tick labels
    try:
        panel.draw(ax, view)
    except Exception:  # a broken panel must not take the window down
        try:
            title = str(getattr(panel, "title", "panel"))
        except Exception:           # a title read from a view's widgets, gone with the view
            title = type(panel).__name__
        log.exception("panel %r failed to draw", title)
        ax.text(0.5, 0.5, f"{title}: drawing failed", transform=ax.transAxes, ha="center",
                va="center", color="red")
    refit_ylabels([ax])                     # every panel's label placed the same way
    if last:
        ax.set_xlabel("time (s)", fontsize=8)
    else:
        ax.tick_params(labelbottom=False)
    ax.grid(axis="x", color="#dddddd", lw=0.5)


# ---------------------------------------------------------------------- the timeline
class Timeline(QWidget):
    """The stack of time-aligned panels with a blitted cursor."""

    seekRequested = pyqtSignal(float)
    loopSelected = pyqtSignal(float, float)
    loopCleared = pyqtSignal()
    laidOut = pyqtSignal()          # a relayout's panels are built (``hidden``: those left out)

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.figure = Figure(figsize=(10, 5), dpi=100)
        self.figure.set_facecolor("white")
        self.canvas = _Canvas(self.figure)
        self.canvas.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        # the legend of every panel's curves, in a row of its own above them (it wraps): never
        # drawn over the data
        self.legend_bar = QLabel()
        self.legend_bar.setWordWrap(True)
        self.legend_bar.setTextFormat(Qt.TextFormat.RichText)
        self.legend_bar.setStyleSheet("font-size: 11px; padding: 0px 6px;")
        self.legend_bar.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Minimum)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        lay.addWidget(self.legend_bar)
        lay.addWidget(self.canvas)
        self.panels: list[Panel] = []
        self.axes: list = []
        self.shown: list[Panel] = []            # the panels with an axes, in self.axes's order
        self.hidden: list[Panel] = []           # left out for lack of room (panel_layout)
        self.legend: list = []                  # the legend row's entries (panel_layout.LegendEntry)
        self.view: UtteranceView | None = None
        self.cursor_time = 0.0
        self.loop: tuple[float, float] | None = None
        self._range: tuple[float, float] | None = None    # the time range shown (s)
        self._cursor: Line2D | None = None     # the cursors of all panels (display pixels)
        self._cursor_rows: list[tuple[float, float]] = []   # each axes' bottom and top (pixels)
        self._cursor_columns: tuple[float, float] = (0.0, 0.0)  # the axes' left and right
        self._spans: list = []
        self._bg = None                         # the figure without the cursor; None: redraw due
        self._cursor_x: float | None = None
        self._bg_bounds: tuple[float, ...] = ()
        self._press: tuple[float, float, int] | None = None   # (xdata, xpixel, button)
        self._grab = None                       # a panel's own drag (``mouse_press``)
        self._drag_span: tuple[float, float] | None = None
        self.builds = SteppedBuild(self.canvas)  # the relayout built over several passes
        self.layouts = 0                        # relayouts finished (tests)
        self._grid = None                       # the panels' grid (its margins follow resizes)
        self.canvas.drawn.connect(self._on_draw)
        self.canvas.mpl_connect("resize_event", self._on_resize)
        self.canvas.mpl_connect("button_press_event", self._on_press)
        self.canvas.mpl_connect("motion_notify_event", self._on_motion)
        self.canvas.mpl_connect("button_release_event", self._on_release)
        self.canvas.mpl_connect("scroll_event", self._on_scroll)

    # ------------------------------------------------------------------ panels
    def add_panel(self, panel: Panel, soon: bool = False) -> None:
        self.panels.append(panel)
        self.relayout(self.xlim() if self.axes else None, soon=soon)

    def remove_panel(self, panel: Panel, soon: bool = False) -> None:
        if panel in self.panels:
            self.panels.remove(panel)
            self.relayout(self.xlim() if self.axes else None, soon=soon)

    def set_view(self, view: UtteranceView | None, keep_zoom: bool = False) -> None:
        """Show ``view``; another result of the recording shown (``keep_zoom``) is drawn in the
        panels' axes as they are (:func:`redraw_in_place`), else the panels are laid out anew."""
        old, self.view = self.view, view
        if keep_zoom and not self.builds.running and self.axes and view is not None and \
                old is not None and old.utterance.audio is view.utterance.audio:
            redraw_soon(self, view)
            return
        self.relayout(self._range if keep_zoom else None)

    def axes_of(self, panel: Panel):
        """The matplotlib axes a panel was drawn in (None before the first layout, or while it is
        left out for lack of room)."""
        try:
            return self.axes[self.shown.index(panel)]
        except (ValueError, IndexError):
            return None

    def _heights(self, panels: list[Panel], slack: float = 0.0) -> list[float | None]:
        """Each panel's height in pixels at the figure's present size less ``slack`` (None:
        left out)."""
        fig = self.figure
        room = fig.get_figheight() * fig.dpi - BOTTOM_MARGIN_PX - TOP_MARGIN_PX - slack
        return fit_heights([p.height for p in panels], [panel_min_px(p) for p in panels],
                           [panel_priority(p) for p in panels], room)

    def _fitting(self, slack: float = 0.0) -> list[Panel]:
        """The panels that fit the present size less ``slack``."""
        return [p for p, h in zip(self.panels, self._heights(self.panels, slack), strict=True)
                if h is not None]

    @property
    def building(self) -> bool:
        """Whether a relayout is being built (``relayout(soon=True)``) or drawn."""
        return self.builds.running or self.canvas.busy

    def relayout(self, xlim: tuple[float, float] | None = None, soon: bool = False) -> None:
        """Rebuild the figure (one axes per panel, shared time axis) and draw it in the
        background. Now (the axes are there on return), or with ``soon`` one panel per pass of
        the event loop, after a draw that is running (a view adding panels)."""
        if self.builds.executing:   # asked for by what a build does (its legend resizing the
            # panels): after it, never inside it (a second build removed the first one's axes)
            QTimer.singleShot(0, lambda: self.relayout(self.xlim() if self.axes else xlim, soon=True))
            return
        self.builds.start(self._build_steps(xlim), soon)

    def _build_steps(self, xlim: tuple[float, float] | None):
        """The relayout, a step per panel (a generator); no draw starts until it ends."""
        self.canvas.hold()
        try:
            fig = self.figure
            while fig.axes:                     # one at a time (fig.clear() clears each axes
                fig.axes[0].remove()            # first: 70 ms for eight panels)
                yield
            fig.clear()
            self.axes, self.shown, self.hidden, self._spans, self._cursor = [], [], [], [], None
            self._bg = None
            panels = list(self.panels)
            if not panels or self.view is None:
                return
            # the range to show, kept apart from the axes' limits: while the axes are built
            # they autoscale with margins (-0.17 to 3.57 s for 0 to 3.40), and a relayout asked
            # for then read those
            self._range = tuple(map(float, xlim or (0.0, self.view.duration)))
            yield
            heights = self._heights(panels)
            self.shown = [p for p, h in zip(panels, heights, strict=True) if h is not None]
            self.hidden = [p for p, h in zip(panels, heights, strict=True) if h is None]
            grid = fig.add_gridspec(len(self.shown), 1, height_ratios=[h for h in heights if h is not None])
            self._grid = grid
            place_grid(self.figure, self._grid, [h for h in heights if h is not None])
            first = None
            for i, panel in enumerate(self.shown):
                ax = fig.add_subplot(grid[i, 0], sharex=first)
                first = first or ax
                draw_panel(panel, ax, self.view, last=i == len(self.shown) - 1)
                self.axes.append(ax)
                yield
            self._show_legend()
            # animated: left out of full draws, drawn over the saved background (_on_draw, set_cursor)
            self._cursor = Line2D([], [], color=CURSOR_COLOR, lw=1.2, animated=True,
                                  transform=IdentityTransform())
            fig.add_artist(self._cursor)
            self._draw_loop_spans()
            first.set_xlim(*self._range)
            self.layouts += 1
        finally:
            self.canvas.release()

    def _show_legend(self) -> None:
        """The legend row: every named curve of the panels, and the panels left out for lack of
        room (nothing once the window is gone: a relayout's last step may come after it)."""
        if sip.isdeleted(self) or sip.isdeleted(self.legend_bar):
            return
        self.legend = legend_entries(self.axes)
        note = f"no room for: {', '.join(p.title for p in self.hidden)}" if self.hidden else ""
        self.legend_bar.setText(legend_html(self.legend, note))
        self.legend_bar.setVisible(bool(self.legend or note))
        self.laidOut.emit()

    def needed_height(self) -> float:
        """The height (px) the timeline needs to show every panel at its least readable height,
        with its margins and legend row."""
        panels = self.panels
        return (sum(panel_min_px(p) for p in panels) + GAP_PX * max(len(panels) - 1, 0)
                + BOTTOM_MARGIN_PX + TOP_MARGIN_PX
                + (self.legend_bar.sizeHint().height() if self.legend_bar.isVisible() else 0))

    def _fit_to_size(self) -> None:
        """After a resize: the panels' heights and margins in pixels and every y label fitted
        again (they were fractions of the size the figure was built at: a narrower timeline cut
        "upper lip" off its label); a relayout when the panels left out change."""
        if self._grid is None or not self.axes:
            return
        shown, fitting = set(self.shown), set(self._fitting())
        # more panels fit: shown only when they fit with the legend row a few lines taller (it
        # grows with their curves and shrinks with the note of those left out, and the panels'
        # height with it: at 800 x 600 the layout flipped between 3 and 4 panels without end)
        if fitting > shown:
            line = self.legend_bar.fontMetrics().lineSpacing()
            fitting = set(self._fitting(slack=LEGEND_SWING_LINES * line)) | shown
        if fitting != shown:
            self.relayout(self.xlim(), soon=True)
            return
        place_grid(self.figure, self._grid, self._heights(self.shown))
        for ax in self.axes:            # (GridSpec.update moves only pyplot's figures' axes)
            ax.set_position(ax.get_subplotspec().get_position(self.figure))
        refit_ylabels(self.axes)

    def _draw_loop_spans(self) -> None:
        for s in self._spans:
            s.remove()
        self._spans = []
        span = self._drag_span or self.loop
        if span is None:
            return
        for ax in self.axes:
            self._spans.append(ax.axvspan(span[0], span[1], color=LOOP_COLOR, alpha=0.18, lw=0,
                                          gid=LOOP_GID))

    # ------------------------------------------------------------------ cursor (blitting)
    @property
    def cursor_ready(self) -> bool:
        """Whether the cursor moves by blitting now (the background of the last full draw is
        current); if not, the next move asks for a full draw."""
        return self._bg is not None

    def ensure_drawn(self) -> None:
        """Bring the canvas up to date for a picture of it (a screenshot): a relayout being built
        is finished and a full draw made only when the last one is stale (never drawn, resized,
        zoomed, loop range changed; a background draw running is waited for). Otherwise the
        canvas already holds that draw with the cursor blitted at ``cursor_time``, pixel for
        pixel what a new full draw gives (``test_a_moved_cursor_leaves_no_trace``)."""
        self.builds.finish()
        self.canvas.wait()
        if not self.cursor_ready or tuple(self.figure.bbox.bounds) != self._bg_bounds:
            self.canvas.finish()
        if not self.cursor_ready:
            self.canvas.draw()

    def _request_draw(self) -> None:
        """A full draw at the next idle moment (layout, zoom, loop range): the saved background
        is stale until then, so the cursor waits for it."""
        self._bg = None
        self.canvas.draw_idle()

    def _on_draw(self) -> None:
        if self.builds.running:
            return                      # a relayout is on its way: its draw follows
        self._bg = self.canvas.copy_from_bbox(self.figure.bbox)
        self._bg_bounds = tuple(self.figure.bbox.bounds)
        self._cursor_rows = [(ax.bbox.y0, ax.bbox.y1) for ax in self.axes]
        self._cursor_columns = (self.axes[0].bbox.x0, self.axes[0].bbox.x1) if self.axes else (0, 0)
        self._cursor_x = None
        if self._cursor is not None:
            self._cursor_x = self._cursor_px(self.cursor_time)
            self._draw_cursor(self._cursor_x)

    def _draw_cursor(self, x: float) -> None:
        """The cursor at pixel ``x``: one vertical segment per panel, drawn as one path (none
        when ``x`` is outside the panels, as a clipped line would be)."""
        lo, hi = self._cursor_columns
        rows = self._cursor_rows if lo <= x <= hi else []
        xs = np.tile([x, x, np.nan], len(rows))
        # 1 px inside the frame at both ends, where the per-axes lines were clipped
        ys = np.array([[y0 + 1.0, y1 - 1.0, np.nan] for y0, y1 in rows]).ravel()
        self._cursor.set_data(xs, ys)
        self.figure.draw_artist(self._cursor)

    def _on_resize(self, event) -> None:
        self._bg = None
        if self.builds.executing:       # a build resized the panels (its legend): after it
            QTimer.singleShot(0, lambda: self._on_resize(event))
        elif not self.builds.running:
            self.canvas.when_idle(self._fit_to_size)

    def set_cursor(self, t: float, follow: bool = False) -> None:
        """Move the cursor to ``t`` seconds by blitting; with ``follow`` the visible range pages
        along when the cursor leaves it (a zoomed view during playback)."""
        self.cursor_time = float(t)
        if not self.axes:
            return
        if follow:
            lo, hi = self.xlim()
            if not lo <= t <= hi and self.view is not None:
                width = hi - lo
                lo = min(max(0.0, t - 0.1 * width), max(0.0, self.view.duration - width))
                self._range = (lo, lo + width)
                self.axes[0].set_xlim(*self._range)
                self._request_draw()
                return
        if self._bg is None or tuple(self.figure.bbox.bounds) != self._bg_bounds:
            self._request_draw()     # a full draw is due anyway (layout, resize, zoom)
            return
        x_new = self._cursor_px(t)
        # restore and repaint only the strip between the old and the new cursor position
        fig_box = self.figure.bbox
        x_old = self._cursor_x if self._cursor_x is not None else x_new
        lo = max(fig_box.x0, min(x_old, x_new) - 3)
        hi = min(fig_box.x1, max(x_old, x_new) + 3)
        self._cursor_x = x_new
        strip = Bbox([[np.floor(lo), fig_box.y0], [np.ceil(hi), fig_box.y1]])
        # xy is where the saved region's lower-left corner goes (the figure's), not the strip's
        self.canvas.restore_region(self._bg, bbox=strip, xy=(fig_box.x0, fig_box.y0))
        self._draw_cursor(x_new)
        self.canvas.blit(strip)

    def _cursor_px(self, t: float) -> float:
        return float(self.axes[0].transData.transform((t, 0))[0])

    def redraw(self) -> None:
        """A full draw soon, the panels kept (a panel's artist changed: the tier's selection)."""
        if self.axes:
            self._request_draw()

    def set_loop(self, loop: tuple[float, float] | None) -> None:
        self.loop = loop
        self._draw_loop_spans()
        self._request_draw()

    def xlim(self) -> tuple[float, float]:
        """The time range shown (s): the one asked for, also while the axes are being built."""
        return self._range if self._range is not None else (0.0, 0.0)

    def set_xlim(self, lo: float, hi: float) -> None:
        if self.axes and self.view is not None:
            dur = self.view.duration
            width = min(max(hi - lo, 0.02), dur)
            lo = min(max(0.0, lo), dur - width)
            self._range = (float(lo), float(lo + width))
            self.axes[0].set_xlim(*self._range)
            self._request_draw()

    def reset_zoom(self) -> None:
        if self.view is not None:
            self.set_xlim(0.0, self.view.duration)

    # ------------------------------------------------------------------ mouse
    def _on_press(self, event) -> None:
        if event.inaxes is None or event.xdata is None:
            return
        if event.dblclick:
            self.reset_zoom()
            return
        panel = self.shown[self.axes.index(event.inaxes)] if event.inaxes in self.axes else None
        if int(event.button) == 1 and hasattr(panel, "mouse_press"):
            self._grab = panel.mouse_press(event)
            if self._grab is not None:
                return
        self._press = (float(event.xdata), float(event.x), int(event.button))

    def _on_motion(self, event) -> None:
        if self._grab is not None:
            self._grab.move(event)
            return
        if self._press is None or event.x is None:
            return
        x0, px0, button = self._press
        if button == 1 and event.xdata is not None and event.inaxes is not None:
            if abs(event.x - px0) >= 4:
                self._drag_span = (min(x0, event.xdata), max(x0, event.xdata))
                self._draw_loop_spans()
                self._request_draw()
        elif button in (2, 3) and self.axes:
            ax = self.axes[0]
            inv = ax.transData.inverted()
            dx = inv.transform((event.x, 0))[0] - inv.transform((px0, 0))[0]
            lo, hi = self.xlim()
            self.set_xlim(lo - dx, hi - dx)
            self._press = (x0, float(event.x), button)

    def _on_release(self, event) -> None:
        if self._grab is not None:
            grab, self._grab = self._grab, None
            grab.release(event)
            return
        if self._press is None:
            return
        x0, _px0, button = self._press
        self._press = None
        if button != 1:
            return
        span, self._drag_span = self._drag_span, None
        if span is not None and span[1] - span[0] > 1e-3:
            self.loop = span
            self._draw_loop_spans()
            self._request_draw()
            self.loopSelected.emit(span[0], span[1])
        else:
            self.seekRequested.emit(x0)

    def _on_scroll(self, event) -> None:
        if event.xdata is None or not self.axes:
            return
        factor = 0.8 if event.button == "up" else 1.25
        lo, hi = self.xlim()
        x = float(event.xdata)
        self.set_xlim(x - (x - lo) * factor, x + (hi - x) * factor)
