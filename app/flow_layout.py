"""A row of widgets that wraps onto further rows when its width runs out (:class:`FlowLayout`):
a bar of controls as wide as its widest widget, not as all of them, so that it never sets the
least width of a dock or of the window (the 3-D view's bars kept the window 568 px wider than its
left docks; the Metrics options made the dock scroll sideways on a laptop, its plots and buttons
cut). Its height follows its width (``heightForWidth``), which the box layouts around it use."""

from __future__ import annotations

from PyQt6.QtCore import QPoint, QRect, QSize, Qt
from PyQt6.QtWidgets import QHBoxLayout, QLayout, QLayoutItem, QSizePolicy, QWidget


class FlowLayout(QLayout):
    """Items left to right at their preferred widths, a new row when the next does not fit;
    an item added with ``stretch`` (a slider, a text box) is as narrow as ``stretch`` px when
    rows are made and takes the rest of its row. Items in a row are centred vertically."""

    def __init__(self, parent: QWidget | None = None, spacing: int = 4,
                 margins: tuple[int, int, int, int] = (0, 0, 0, 0), row_spacing: int = 2):
        super().__init__(parent)
        self._items: list[QLayoutItem] = []
        self._stretch: dict[int, int] = {}       # id(item) -> least width while rows are made
        self.row_spacing = row_spacing
        self.setSpacing(spacing)
        self.setContentsMargins(*margins)

    # ------------------------------------------------------------------ items
    def add(self, widget: QWidget, stretch: int = 0) -> QWidget:
        """Add ``widget``; with ``stretch`` > 0, at least that wide and the rest of its row."""
        self.addWidget(widget)
        if stretch:
            self._stretch[id(self._items[-1])] = stretch
        return widget

    def addItem(self, item: QLayoutItem) -> None:
        self._items.append(item)

    def count(self) -> int:
        return len(self._items)

    def itemAt(self, index: int) -> QLayoutItem | None:
        return self._items[index] if 0 <= index < len(self._items) else None

    def takeAt(self, index: int) -> QLayoutItem | None:
        if 0 <= index < len(self._items):
            item = self._items.pop(index)
            self._stretch.pop(id(item), None)
            return item
        return None

    def expandingDirections(self) -> Qt.Orientation:
        return Qt.Orientation.Horizontal

    # ------------------------------------------------------------------ sizes
    def hasHeightForWidth(self) -> bool:
        return True

    def heightForWidth(self, width: int) -> int:
        return self._place(QRect(0, 0, width, 0), apply=False)

    def minimumHeightForWidth(self, width: int) -> int:
        return self.heightForWidth(width)

    def sizeHint(self) -> QSize:
        """Every item in one row."""
        shown = self._shown()
        m = self.contentsMargins()
        width = sum(i.sizeHint().width() for i in shown) + self.spacing() * max(len(shown) - 1, 0)
        height = max((i.sizeHint().height() for i in shown), default=0)
        return QSize(width + m.left() + m.right(), height + m.top() + m.bottom())

    def minimumSize(self) -> QSize:
        """The widest item (every item on a row of its own) by the tallest."""
        shown = self._shown()
        m = self.contentsMargins()
        width = max((self._least(i) for i in shown), default=0)
        height = max((i.minimumSize().height() for i in shown), default=0)
        return QSize(width + m.left() + m.right(), height + m.top() + m.bottom())

    def setGeometry(self, rect: QRect) -> None:
        super().setGeometry(rect)
        self._place(rect, apply=True)

    # ------------------------------------------------------------------ placing
    def _shown(self) -> list[QLayoutItem]:
        return [i for i in self._items if not i.isEmpty()]

    def _least(self, item: QLayoutItem) -> int:
        """The width an item takes while rows are made: a stretching item its given least
        width, another its preferred width (never under its minimum)."""
        least = self._stretch.get(id(item))
        if least is not None:
            return max(least, item.minimumSize().width())
        return max(item.sizeHint().width(), item.minimumSize().width())

    def rows(self, width: int) -> list[list[QLayoutItem]]:
        """The items of each row at ``width`` px (margins included)."""
        m = self.contentsMargins()
        room = width - m.left() - m.right()
        rows: list[list[QLayoutItem]] = []
        used = 0
        for item in self._shown():
            w = self._least(item)
            if rows and rows[-1] and used + self.spacing() + w <= room:
                rows[-1].append(item)
                used += self.spacing() + w
            else:
                rows.append([item])
                used = w
        return rows

    def _place(self, rect: QRect, apply: bool) -> int:
        """Lay the items out in ``rect`` (when ``apply``); the height they take."""
        m = self.contentsMargins()
        inner = rect.adjusted(m.left(), m.top(), -m.right(), -m.bottom())
        y = inner.y()
        rows = self.rows(rect.width())
        for k, row in enumerate(rows):
            widths = [self._least(i) for i in row]
            height = max(i.sizeHint().height() for i in row)
            spare = inner.width() - sum(widths) - self.spacing() * (len(row) - 1)
            stretching = [j for j, i in enumerate(row) if id(i) in self._stretch]
            if stretching and spare > 0:
                for n, j in enumerate(stretching):
                    widths[j] += spare // len(stretching) + (1 if n < spare % len(stretching) else 0)
            if apply:
                x = inner.x()
                for item, w in zip(row, widths, strict=True):
                    h = min(height, item.maximumSize().height())
                    widget = item.widget()
                    if widget is None or not (widget.sizePolicy().verticalPolicy().value
                                              & QSizePolicy.PolicyFlag.GrowFlag.value):
                        h = min(h, item.sizeHint().height())
                    item.setGeometry(QRect(QPoint(x, y + (height - h) // 2), QSize(w, h)))
                    x += w + self.spacing()
            y += height + (self.row_spacing if k < len(rows) - 1 else 0)
        return y - inner.y() + m.top() + m.bottom()


def flow_row(widgets: list[QWidget], spacing: int = 3) -> QWidget:
    """``widgets`` side by side in one box that wraps as a whole (the four camera buttons, the
    playback buttons): a group is never split over two rows."""
    box = QWidget()
    lay = QHBoxLayout(box)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.setSpacing(spacing)
    for w in widgets:
        lay.addWidget(w)
    return box


__all__ = ["FlowLayout", "flow_row"]
