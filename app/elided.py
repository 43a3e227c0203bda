"""Texts shortened to the room they get, with an ellipsis and the whole text in the tooltip, so
that a long text never widens the window nor is cut off without a sign: :class:`ElidedLabel`
(the status bar's message and note) and :func:`distinct_names` (names that start alike, shown by
the part that tells them apart: the browser's opened recordings)."""

from __future__ import annotations

import re

from PyQt6.QtCore import QEvent, QSize, Qt
from PyQt6.QtGui import QPainter
from PyQt6.QtWidgets import QLabel, QToolTip, QWidget

#: the least width an elided label asks for (a few characters and the ellipsis)
LEAST_PX = 60


class ElidedLabel(QLabel):
    """A one-line label that asks for its text's width but takes any room down to
    :data:`LEAST_PX`, drawing its text elided (``…``) where it does not fit. ``text()`` is the
    whole text; its tooltip shows the whole text (then the tooltip set, if any) while elided."""

    def __init__(self, text: str = "", parent: QWidget | None = None,
                 mode: Qt.TextElideMode = Qt.TextElideMode.ElideRight):
        super().__init__(text, parent)
        self.mode = mode

    def minimumSizeHint(self) -> QSize:
        return QSize(min(LEAST_PX, super().minimumSizeHint().width()), super().minimumSizeHint().height())

    def shown_text(self) -> str:
        """The text as drawn: elided to the label's width."""
        return self.fontMetrics().elidedText(self.text(), self.mode, max(self.contentsRect().width(), 0))

    def elided(self) -> bool:
        return self.shown_text() != self.text()

    def paintEvent(self, _event) -> None:
        painter = QPainter(self)
        self.style().drawItemText(painter, self.contentsRect(), int(self.alignment()), self.palette(),
                                  self.isEnabled(), self.shown_text(), self.foregroundRole())

    def event(self, event) -> bool:
        if event.type() == QEvent.Type.ToolTip and self.elided():
            tip = "\n\n".join(t for t in (self.text(), self.toolTip()) if t)
            QToolTip.showText(event.globalPos(), tip, self)
            return True
        return super().event(event)


def distinct_names(names: list[str], separators: str = "_-. ") -> dict[str, str]:
    """Each of ``names`` as shown in a narrow list: without the beginning all of them share (cut
    back to a separator, marked by "…"), so that names that start alike show the part that tells
    them apart; a single name, or names sharing no word, as they are.

    >>> distinct_names(["cmu_arctic_us_aew_a0001", "cmu_arctic_us_aew_a0002"])
    {'cmu_arctic_us_aew_a0001': '…a0001', 'cmu_arctic_us_aew_a0002': '…a0002'}
    >>> distinct_names(["cmu_arctic_us_aew_a0001", "cmu_arctic_us_axb_a0004"])["cmu_arctic_us_axb_a0004"]
    '…axb_a0004'
    >>> distinct_names(["fsew0_001", "cmu_arctic_us_aew_a0001"])["fsew0_001"], distinct_names(["s002"])
    ('fsew0_001', {'s002': 's002'})
    """
    if len(names) < 2:
        return {n: n for n in names}
    first, last = min(names), max(names)      # the shared beginning of all: of these two
    k = 0
    while k < min(len(first), len(last)) and first[k] == last[k]:
        k += 1
    common = first[:k]
    cut = max((m.end() for m in re.finditer(f"[{re.escape(separators)}]", common)), default=0)
    if cut == 0 or any(len(n) <= cut for n in names):
        return {n: n for n in names}
    return {n: "…" + n[cut:] for n in names}
