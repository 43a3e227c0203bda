"""What a person does on the label editor's rows, for the GUI tests: a click on a phone or a word
at a time, a boundary dragged, keys pressed, a label typed (real Qt mouse and key events on the
window's widgets)."""

from __future__ import annotations

from PyQt6.QtCore import QPoint, Qt
from PyQt6.QtTest import QTest
from PyQt6.QtWidgets import QApplication

from facetraj_engine.labels.editing import PHONES


def active(win, wait_ms: int = 10_000) -> None:
    """The window active (its keys go to it), as a person's window is when she types."""
    from PyQt6.QtCore import QDeadlineTimer

    if win.isActiveWindow():
        return
    win.raise_()
    win.activateWindow()
    deadline = QDeadlineTimer(wait_ms)
    while not win.isActiveWindow() and not deadline.hasExpired():
        QApplication.processEvents()
    assert win.isActiveWindow(), "the window could not be made active"


def tier_panel(win):
    return win.extension("labels").panel


def tier_point(win, tier: str, t: float) -> QPoint:
    """Where time ``t`` of ``tier``'s row is on the panels' canvas (widget pixels)."""
    win.timeline.ensure_drawn()
    panel = tier_panel(win)
    row = panel.row_of(tier)
    assert row is not None, f"no {tier} row"
    ax = panel.ax
    x, y = ax.transData.transform((t, row + 0.5))
    ratio = win.timeline.canvas.device_pixel_ratio
    return QPoint(int(round(x / ratio)), int(round(win.timeline.canvas.height() - y / ratio)))


def click(win, t: float, tier: str = PHONES) -> None:
    """A click on ``tier``'s row at ``t`` s: the segment there selected, the cursor moved."""
    canvas = win.timeline.canvas
    QTest.mouseClick(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                     tier_point(win, tier, t))
    QApplication.processEvents()


def drag(win, t_from: float, t_to: float, tier: str = PHONES) -> None:
    """Press on the boundary at ``t_from`` of ``tier``'s row, move to ``t_to``, let go."""
    canvas = win.timeline.canvas
    a, b = tier_point(win, tier, t_from), tier_point(win, tier, t_to)
    QTest.mousePress(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, a)
    steps = 4
    for k in range(1, steps + 1):
        QTest.mouseMove(canvas, QPoint(a.x() + (b.x() - a.x()) * k // steps, a.y()))
        QApplication.processEvents()
    QTest.mouseRelease(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, b)
    QApplication.processEvents()


def key(win, sequence: str) -> None:
    """A key (``"F2"``, ``"S"``, ``"Delete"``, ``"Ctrl+Z"``) pressed where the focus is (the
    panels after a click on them)."""
    from PyQt6.QtGui import QKeySequence

    active(win)
    combo = QKeySequence(sequence)[0]
    target = QApplication.focusWidget() or win
    QTest.keyClick(target, combo.key(), combo.keyboardModifiers())
    QApplication.processEvents()


def rename(win, label: str) -> None:
    """F2, the label typed into the rename field, Enter."""
    key(win, "F2")
    field = win.extension("labels").bar.field
    assert field.hasFocus()
    QTest.keyClicks(field, label)
    popup = field.completer().popup()
    QTest.keyClick(popup if popup.isVisible() else field, Qt.Key.Key_Return)
    QApplication.processEvents()
    if field.hasFocus() and popup.isHidden():   # the popup took the first Enter
        QTest.keyClick(field, Qt.Key.Key_Return)
        QApplication.processEvents()
