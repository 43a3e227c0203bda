"""Compare: keep the result on screen as a pin and see the next one beside it (an extension of
the main window, using its public contract and its ``pins``, ``app/pins.py``).

*Pin this result* keeps the synthesis shown; change the search, the labels (an opened
recording's label source), N, the smoothing or the model, and the lip panels draw the pinned
curves in the pin's colour (the legend row names how each was made), the phone tier adds the
pin's phones where its labels differ, the 3-D view shows the pinned face beside the current one,
and a panel draws the difference of the lip aperture, this result minus each pin's.
"""

from __future__ import annotations

from html import escape

import numpy as np
from PyQt6.QtCore import QObject, QSize, Qt, QTimer, pyqtSignal
from PyQt6.QtGui import QKeySequence
from PyQt6.QtWidgets import QLabel

from .pins import aperture_difference

#: the widest the pins' list asks to be in the toolbar (it dropped into the toolbar's overflow
#: menu on a laptop screen when it asked for its whole text); narrower, it is elided, and the
#: legend row and the tooltip name each pin in full
PIN_LIST_PX = 900
#: between two pins in the list
PIN_GAP = "  "


class PinDifferencePanel:
    """Timeline panel: the lip aperture of the result on screen minus each pinned one's (mm),
    in the pins' colours, with a line at 0."""

    title = "aperture minus pin"
    height = 0.8
    min_px = 48.0
    priority = 60

    def __init__(self, window):
        self.window = window

    def draw(self, ax, view) -> None:
        model = self.window.model
        ax.axhline(0.0, color="#888888", lw=0.7)
        low = high = 0.0
        for pin in self.window.pins.shown(view):
            diff = aperture_difference(view, pin, model.upper_lip, model.lower_lip)
            ax.plot(view.times[:len(diff)], diff, color=pin.color, lw=1.3,
                    label=f"aperture: this − {pin.name}")
            if np.isfinite(diff).any():
                low, high = min(low, float(np.nanmin(diff))), max(high, float(np.nanmax(diff)))
        pad = 0.12 * max(high - low, 1.0)
        ax.set_ylim(low - pad, high + pad)
        ax.set_ylabel("aperture\n− pin (mm)", fontsize=8)


class PinList(QLabel):
    """The pins shown, in the toolbar: each one's colour, name and how it differs from the
    others (``distinct_settings``), never asking for more than :data:`PIN_LIST_PX`; what does not
    fit the width it gets is elided ("…", the whole list in the tooltip: on a laptop its end was
    cut off without a sign)."""

    def __init__(self):
        super().__init__("")
        self.setTextFormat(Qt.TextFormat.RichText)
        self.setStyleSheet("padding-left: 6px; color: #444444;")
        self.parts: list[tuple[str, str]] = []      # (colour, "pin k: how it differs") or ("", note)

    def sizeHint(self) -> QSize:
        hint = super().sizeHint()
        full = self.fontMetrics().horizontalAdvance(self.plain_text()) + self._padding()
        return QSize(min(full, PIN_LIST_PX), hint.height())

    def minimumSizeHint(self) -> QSize:
        return QSize(120, super().minimumSizeHint().height())

    def show_pins(self, named: list, note: str) -> None:
        """``named``: the pins drawn with the result on screen, each with its text
        (``PinBoard.named``); else ``note`` says why none is."""
        if not named:
            self.parts = [("", note)] if note else []
            self.setToolTip(note)
        else:
            self.parts = [(p.color, text) for p, text in named]
            self.setToolTip("\n".join(f"{p.name}: {p.settings}" for p, _text in named))
        self.setText(self._html(self.parts))        # whole, until the toolbar has laid it out
        self.updateGeometry()
        QTimer.singleShot(0, self._fit)

    def plain_text(self) -> str:
        """The whole list as words (each pin's colour a square)."""
        return PIN_GAP.join(("■ " if colour else "") + text for colour, text in self.parts)

    def shown_text(self) -> str:
        """The list as drawn now, elided to the width (each pin's colour a square)."""
        return PIN_GAP.join(("■ " if colour else "") + text for colour, text in self._elided())

    def _padding(self) -> int:
        return 6 + 2 * self.margin() + 2

    def _elided(self) -> list[tuple[str, str]]:
        """The parts that fit the label's width: whole as long as they fit, then the next one cut
        with an ellipsis ("…" alone when not even its square fits)."""
        fm = self.fontMetrics()
        room = self.width() - self._padding()
        out: list[tuple[str, str]] = []
        for k, (colour, text) in enumerate(self.parts):
            gap = fm.horizontalAdvance(PIN_GAP) if out else 0
            square = fm.horizontalAdvance("■ ") if colour else 0
            need = gap + square + fm.horizontalAdvance(text)
            last = k == len(self.parts) - 1
            if need <= room and (last or need + fm.horizontalAdvance(PIN_GAP + "…") <= room):
                out.append((colour, text))
                room -= need
                continue
            left = room - gap - square
            if fm.horizontalAdvance(text) <= left:      # it fits, what follows does not: say so
                left = fm.horizontalAdvance(text) - 1
            cut = fm.elidedText(text, Qt.TextElideMode.ElideRight, max(left, 0))
            if left < fm.horizontalAdvance("…") or not cut or cut == "…":
                out.append(("", "…"))
            else:
                out.append((colour, cut))
            break
        return out

    @staticmethod
    def _html(parts: list[tuple[str, str]]) -> str:
        return ("&nbsp;" * len(PIN_GAP)).join(
            (f'<span style="color:{colour}">■</span> ' if colour else "") + escape(text)
            for colour, text in parts)

    def _fit(self) -> None:
        text = self._html(self._elided())
        if text != self.text():
            self.setText(text)

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self._fit()


class Compare(QObject):
    """The pins' toolbar (*Pin this result*, *Clear pins*, what is pinned), the difference panel
    and the pinned faces in 3-D, following the window's result. ``changed`` after the pins shown
    change (a pin kept or cleared, a new result)."""

    changed = pyqtSignal()

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.panel = PinDifferencePanel(window)
        bar = window.addToolBar("Compare")
        bar.setObjectName("compare-toolbar")
        self.pin_action = bar.addAction("Pin this result", self.pin)
        self.pin_action.setShortcut(QKeySequence("Ctrl+P"))
        self.pin_action.setToolTip("keep the result on screen to compare the next one with it "
                                   "(another search, labels, N, smoothing or model) (Ctrl+P)")
        self.clear_action = bar.addAction("Clear pins", self.clear)
        self.label = PinList()
        bar.addWidget(self.label)
        menu = window.menu("View")
        menu.addSeparator()
        menu.addAction(self.pin_action)
        menu.addAction(self.clear_action)
        self._shown: list = []          # the pins shown at the last refresh (app/pins.py: Pin)
        window.synthesisChanged.connect(lambda: self.refresh(new_result=True))
        self.refresh()

    def pin(self) -> None:
        """Keep the result on screen as a pin."""
        view = self.window.view
        if view is None:
            self.window.show_status("nothing to pin yet", 4000)
            return
        kept = self.window.pins.pinned(view)
        if kept is not None:
            self.window.show_status(f"this result is pinned already ({kept.name})", 6000)
            return
        pin = self.window.pins.pin(view)
        self.window.show_status(f"{pin.name} kept: {pin.settings}; change a setting (labels, "
                                "search, N, smoothing) to compare", 8000)
        self.refresh()

    def clear(self) -> None:
        self.window.pins.clear()
        self.refresh()

    def refresh(self, new_result: bool = False) -> None:
        """Show the pins of the utterance on screen: the difference panel there while one is
        shown, the pinned faces in 3-D, and the panels redrawn with their curves when the pins
        shown changed without a new result (``new_result``: a new result redraws them anyway)."""
        w = self.window
        shown = w.pins.shown(w.view)
        changed, self._shown = shown != self._shown, shown
        self.clear_action.setEnabled(len(w.pins) > 0)
        self.label.show_pins(w.pins.named(w.view), self._note())
        w.face.set_pins(shown)
        tl = w.timeline
        if shown and self.panel not in tl.panels:
            tl.add_panel(self.panel, soon=True)
        elif not shown and self.panel in tl.panels:
            tl.remove_panel(self.panel, soon=True)
        elif changed and not new_result and tl.view is not None:
            tl.relayout(tl.xlim() if tl.axes else None, soon=True)
        self.changed.emit()


    def _note(self) -> str:
        """What the pins' list says when no pin is drawn with the result on screen."""
        w = self.window
        pins = w.pins
        own = pins.pinned(w.view) if w.view is not None else None
        if own is not None:
            return (f"{own.name}: the result on screen; change a setting (labels, search, N, "
                    "smoothing) to compare")
        if len(pins):
            return f"{len(pins)} pinned of another utterance or marker set"
        return ""


def install(window) -> Compare:
    """Add the pins to ``window``; also ``window.extension("compare")``."""
    compare = Compare(window)
    window.add_extension("compare", compare)
    return compare
