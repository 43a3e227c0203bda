"""The phone tier as a label editor: the words and phones rows of the labels on screen take the
mouse (a click selects a segment and moves the cursor there; a press on a boundary drags it,
snapped to frames when it is let go), and the segment selected is drawn as a blue box over its
row. The edits themselves are the label editor's (``app/label_editing.py``); this panel draws
them and turns the mouse into them."""

from __future__ import annotations

from typing import Protocol

from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle

from facetraj_engine.labels.editing import PHONES, WORDS

from .state import UtteranceView
from .timeline import PhoneTierPanel, tier_rows

#: the segment selected, and a boundary being dragged
SELECT_COLOR = "#74c0fc"
DRAG_COLOR = "#1864ab"
#: a press this close to a boundary (px) grabs it
GRAB_PX = 5.0


class TierEditor(Protocol):
    """What the panel needs of the label editor (``app/label_editing.py: LabelEditing``)."""

    def tier_view(self, view: UtteranceView) -> UtteranceView: ...
    def editable(self, view: UtteranceView) -> bool: ...
    def boundaries(self, tier: str) -> list[tuple[float, int, str]]: ...
    def selected_span(self) -> tuple[str, float, float] | None: ...
    def select_at(self, tier: str, t: float) -> None: ...
    def drag_boundary(self, tier: str, index: int, side: str, t: float) -> None: ...
    def seek(self, t: float) -> None: ...
    def redraw(self) -> None: ...


class EditableTierPanel(PhoneTierPanel):
    """:class:`~facetraj_app.timeline.PhoneTierPanel` whose own labels take the mouse; its rows
    show the labels being edited (the editor's, one step ahead of the synthesis)."""

    def __init__(self, context, editor: TierEditor):
        super().__init__(context)
        self.editor = editor
        self.ax = None
        self.rows: list = []
        self.view: UtteranceView | None = None
        self.highlight: Rectangle | None = None
        self.drag_line: Line2D | None = None

    def draw(self, ax, view: UtteranceView) -> None:
        shown = self.editor.tier_view(view)
        super().draw(ax, shown)
        self.ax, self.view = ax, view
        self.rows = tier_rows(shown, self.context.pins.shown(shown))
        self.highlight = Rectangle((0.0, 0.0), 0.0, 1.0, color=SELECT_COLOR, alpha=0.45, lw=0,
                                   zorder=0.5, visible=False)
        ax.add_patch(self.highlight)
        self.drag_line = Line2D([], [], color=DRAG_COLOR, lw=2.0, zorder=4, visible=False)
        ax.add_line(self.drag_line)
        self.show_selection()

    def row_of(self, tier: str) -> int | None:
        """The row (from the bottom) of the labels' ``tier``: the phones first, the words last."""
        if tier == PHONES:
            return 0 if self.rows else None
        last = len(self.rows) - 1
        return last if last > 0 and self.rows[last][2] == "words" else None

    def show_selection(self) -> None:
        """The selected segment's box where it is (hidden without one); the panels drawn again."""
        if self.highlight is None:
            return
        span = self.editor.selected_span()
        row = self.row_of(span[0]) if span is not None else None
        if row is None:
            self.highlight.set_visible(False)
        else:
            self.highlight.set_bounds(span[1], row, span[2] - span[1], 1.0)
            self.highlight.set_visible(True)

    # ------------------------------------------------------------------ the mouse
    def mouse_press(self, event):
        """A press on the labels' rows: on a boundary, a drag; inside a segment, it is selected
        (and the timeline moves the cursor there as for any click)."""
        if self.ax is None or event.ydata is None or self.view is None or \
                not self.editor.editable(self.view):
            return None
        k = int(event.ydata)
        tier = PHONES if k == self.row_of(PHONES) else WORDS if k == self.row_of(WORDS) else None
        if tier is None:
            return None
        to_px = self.ax.transData.transform
        near = [(abs(to_px((t, 0))[0] - event.x), t, i, side)
                for t, i, side in self.editor.boundaries(tier)]
        best = min(near, default=None)
        if best is not None and best[0] <= GRAB_PX:
            return BoundaryDrag(self, tier, best[2], best[3], best[1], k, float(event.x))
        self.editor.select_at(tier, float(event.xdata))
        return None


class BoundaryDrag:
    """A boundary held by the mouse: a line follows the pointer over its row; let go, the
    editor moves the boundary there (snapped). Let go where it was taken, it is a click (the
    segment after the boundary is selected and the cursor goes there)."""

    def __init__(self, panel: EditableTierPanel, tier: str, index: int, side: str, t: float,
                 row: int, x: float):
        self.panel, self.tier, self.index, self.side = panel, tier, index, side
        self.t, self.row, self.x, self.moved = t, row, x, False

    def move(self, event) -> None:
        if event.x is None or abs(event.x - self.x) < 2:
            return
        ax = self.panel.ax
        self.moved = True
        self.t = float(ax.transData.inverted().transform((event.x, 0))[0])
        line = self.panel.drag_line
        line.set_data([self.t, self.t], [self.row, self.row + 1])
        line.set_visible(True)
        self.panel.editor.redraw()

    def release(self, event) -> None:
        self.panel.drag_line.set_visible(False)
        editor = self.panel.editor
        if self.moved:
            editor.drag_boundary(self.tier, self.index, self.side, self.t)
        else:
            editor.select_at(self.tier, self.t + 1e-6 if self.side == "start" else self.t - 1e-6)
            editor.seek(self.t)
        editor.redraw()
