"""The main window's menus and docks: menus by name (new ones before Help), menu entries whose
engine errors are reported rather than raised, docks tabbed together by area, each view in a
scroll area so that no dock can push the window wider than the screen, and windows sized and
placed to fit the screen they open on (:func:`fit_to_screen`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PyQt6 import sip
from PyQt6.QtCore import QEvent, QObject, QSize, Qt, QTimer
from PyQt6.QtGui import QAction, QGuiApplication
from PyQt6.QtWidgets import QDockWidget, QFrame, QMainWindow, QMenu, QScrollArea, QVBoxLayout, QWidget

from facetraj_engine.errors import FacetrajError


class WindowMenus:
    """The menus of ``window`` by name; an entry's engine error goes to ``on_error``."""

    def __init__(self, window: QMainWindow, on_error: Callable[[BaseException], None]):
        self.window = window
        self.on_error = on_error
        self.menus: dict[str, QMenu] = {}
        self._watchers: list[Callable[[QMenu], None]] = []

    def watch(self, fn: Callable[[QMenu], None]) -> None:
        """Call ``fn(menu)`` for each menu, those made later included (e.g. to note which entry
        the user chose last: ``app/exception_hook.py``)."""
        self._watchers.append(fn)
        for menu in self.menus.values():
            fn(menu)

    def menu(self, name: str) -> QMenu:
        """The menu ``name`` ("File", "View", "Analysis", "Help"; another name: a new menu,
        placed before Help)."""
        if name not in self.menus:
            help_menu = self.menus.get("Help")
            if help_menu is None:
                self.menus[name] = self.window.menuBar().addMenu(f"&{name}")
            else:
                self.menus[name] = QMenu(f"&{name}", self.window)
                self.window.menuBar().insertMenu(help_menu.menuAction(), self.menus[name])
            for fn in self._watchers:
                fn(self.menus[name])
        return self.menus[name]

    def action(self, menu: str, text: str, slot: Callable[[], Any]) -> QAction:
        """A menu entry; an engine error its slot raises is reported, never raised."""
        def run(_checked: bool = False) -> None:
            try:
                slot()
            except FacetrajError as exc:
                self.on_error(exc)

        action = QAction(text, self.window)
        action.triggered.connect(run)
        self.menu(menu).addAction(action)
        return action


def rows_height(layout, width: int) -> int:
    """The least height of ``layout`` at ``width`` px where its rows wrap (a
    :class:`~facetraj_app.flow_layout.FlowLayout`, word-wrapped text: its
    ``minimumHeightForWidth``); 0 when its height does not depend on its width."""
    if layout is None or not layout.hasHeightForWidth():
        return 0
    return getattr(layout, "minimumHeightForWidth", layout.heightForWidth)(width)


def least_size(widget: QWidget, width: int, least: QSize | None = None) -> QSize:
    """The least size of ``widget`` at ``width`` px: ``least`` (its ``minimumSizeHint``), taller
    where its rows wrap at that width (:func:`rows_height`)."""
    if least is None:
        least = widget.minimumSizeHint().expandedTo(widget.minimumSize())
    least.setHeight(max(least.height(), rows_height(widget.layout(), max(width, least.width()))))
    return least


class Column(QWidget):
    """Widgets stacked vertically without margins, the spare height to ``stretch``; its least
    height is what its rows need at its width (:func:`rows_height`), so that a splitter never
    squeezes a bar that wrapped onto more rows (the transport bar's last row was cut off)."""

    def __init__(self, widgets: list[QWidget], spacing: int, stretch: QWidget):
        super().__init__()
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(spacing)
        for w in widgets:
            lay.addWidget(w, 1 if w is stretch else 0)
        self._width = -1

    def minimumSizeHint(self) -> QSize:
        return least_size(self, self.width(), self.layout().totalMinimumSize())

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        if self.width() != self._width:         # its rows may wrap otherwise: a new least height
            self._width = self.width()
            self.updateGeometry()


class FillScrollArea(QScrollArea):
    """The scroll area of a dock: its view fills the viewport (its tables, plots and splitters
    stretch or shrink to the dock) and is never made smaller than its least size
    (``minimumSizeHint``), scrolling then. Unlike ``setWidgetResizable``, the view's height never
    follows its preferred height for its width: a view with word-wrapped text was made as tall
    as all its plots' preferred sizes (905 px in a 637 px dock) and its bottom cut off (Figure
    5's x label was). No dock can make the window taller or wider."""

    def setWidget(self, widget: QWidget) -> None:
        super().setWidget(widget)
        widget.installEventFilter(self)
        self._fit()

    def viewportEvent(self, event) -> bool:
        if event.type() == QEvent.Type.Resize:
            self._fit()
        return super().viewportEvent(event)

    def eventFilter(self, obj, event) -> bool:
        if obj is self.widget() and event.type() == QEvent.Type.LayoutRequest:
            QTimer.singleShot(0, self._fit)         # after the layout has its new least size
        return False

    def _fit(self) -> None:
        widget = self.widget()
        if widget is None:
            return
        room = self.viewport().size()
        least = least_size(widget, room.width())       # rows that wrap at the viewport's width
        size = QSize(max(room.width(), least.width()), max(room.height(), least.height()))
        if widget.size() != size:
            widget.resize(size)


def text_scroll(widget: QWidget) -> QScrollArea:
    """``widget`` (a panel of controls and wrapped text, e.g. the synthesis settings) in a
    scroll area that gives it the height its text needs at the dock's width, scrolling when the
    dock is shorter (a laptop screen): its lines never run into each other."""
    scroll = QScrollArea()
    scroll.setWidget(widget)
    scroll.setWidgetResizable(True)
    scroll.setFrameShape(QFrame.Shape.NoFrame)
    scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
    # never narrower than the panel's controls (a squeezed dock cut "model's" to "r" and hid
    # the spin boxes' arrows)
    scroll.setMinimumWidth(widget.minimumSizeHint().width()
                           + scroll.verticalScrollBar().sizeHint().width())
    return scroll


#: the most of the window's width the docks of a side take when the window is resized
DOCK_SHARES = {Qt.DockWidgetArea.LeftDockWidgetArea: 0.25, Qt.DockWidgetArea.RightDockWidgetArea: 0.4}


class WindowDocks:
    """The docks of ``window``: movable, floatable, closable; extra docks in one area tabbed; the
    width of the left and of the right docks kept through resizes (:class:`DockWidth`)."""

    def __init__(self, window: QMainWindow):
        self.window = window
        self.last: dict[Qt.DockWidgetArea, QDockWidget] = {}
        self.widths: dict[Qt.DockWidgetArea, DockWidth] = {}

    def width_of(self, area: Qt.DockWidgetArea) -> DockWidth:
        """The kept width of the docks of ``area`` (the left or the right side)."""
        if area not in self.widths:
            self.widths[area] = DockWidth(self.window, area, 0, DOCK_SHARES.get(area, 0.4))
        return self.widths[area]

    def dock(self, widget: QWidget, title: str, area: Qt.DockWidgetArea) -> QDockWidget:
        dock = QDockWidget(title, self.window)
        dock.setObjectName(title)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                         | QDockWidget.DockWidgetFeature.DockWidgetClosable)
        self.window.addDockWidget(area, dock)
        if area in DOCK_SHARES:
            self.width_of(area).watch(dock)
        return dock

    def add(self, widget: QWidget, title: str, area: Qt.DockWidgetArea) -> QDockWidget:
        """A dock tabbed with the one added to the same area before it; ``widget`` sits in a
        scroll area (``dock.widget().widget()``): a view wider than its dock scrolls instead of
        widening the window (a main window grows to fit the minimum widths of its docks: four
        analysis views took it from 1600 to 1864 px and it stayed so after they closed). The
        first dock of an area gets :func:`dock_width` of the window, kept through resizes."""
        scroll = FillScrollArea()
        scroll.setWidget(widget)
        scroll.setFrameShape(QFrame.Shape.NoFrame)
        dock = self.dock(scroll, title, area)
        previous = self.last.get(area)
        if previous is not None and self._docked(previous, area):
            self.window.tabifyDockWidget(previous, dock)
        elif area in DOCK_SHARES:
            self.width_of(area).place(dock_width(self.window.width()))
        else:
            self.window.resizeDocks([dock], [dock_width(self.window.width())], Qt.Orientation.Vertical)
        self.last[area] = dock
        return dock


    def _docked(self, dock: QDockWidget, area: Qt.DockWidgetArea) -> bool:
        """Whether ``dock`` is still one of the window's, in ``area`` (a view's dock is removed
        and deleted when another model is loaded: a new dock cannot be tabbed with it)."""
        return not sip.isdeleted(dock) and self.window.dockWidgetArea(dock) == area


def dock_width(window_width: int) -> int:
    """The width an analysis dock opens with: a third of the window, 420-620 px.

    >>> dock_width(1600), dock_width(1280), dock_width(2400)
    (560, 448, 620)
    """
    return int(min(620, max(420, 0.35 * window_width)))


def fitted_geometry(wanted: tuple[int, int], available: tuple[int, int, int, int],
                    frame: tuple[int, int] = (0, 0),
                    minimum: tuple[int, int] = (0, 0)) -> tuple[int, int, int, int]:
    """Where a window of ``wanted`` size goes on a screen whose free area is ``available``
    ``(x, y, width, height)``: as large as wanted but no larger than the free area (less the
    window frame's ``frame`` width and height), at least ``minimum``, centred. Returns the
    window's ``(x, y, width, height)`` without its frame.

    >>> fitted_geometry((1600, 1000), (0, 0, 1920, 1200))
    (160, 100, 1600, 1000)
    >>> fitted_geometry((1600, 1000), (0, 0, 1366, 768))      # a laptop: the whole screen
    (0, 0, 1366, 768)
    >>> fitted_geometry((1600, 1000), (0, 28, 1366, 740), frame=(2, 30))
    (0, 28, 1364, 710)
    """
    ax, ay, aw, ah = available
    w = max(minimum[0], min(wanted[0], aw - frame[0]))
    h = max(minimum[1], min(wanted[1], ah - frame[1]))
    x = ax + max(0, (aw - frame[0] - w) // 2)
    y = ay + max(0, (ah - frame[1] - h) // 2)
    return x, y, w, h


def fit_to_screen(window: QWidget, wanted: tuple[int, int]) -> tuple[int, int, int, int]:
    """Size and place ``window`` by :func:`fitted_geometry` on its screen (the one it is on, else
    the primary one): on a 1366 x 768 laptop a window that wants 1600 x 1000 fills the screen
    instead of reaching past it. Call it again once the window is shown: its frame (title bar,
    borders) is known then."""
    screen = window.screen() or QGuiApplication.primaryScreen()
    free = screen.availableGeometry()
    if window.isVisible():
        outer, inner = window.frameGeometry(), window.geometry()
        frame = (outer.width() - inner.width(), outer.height() - inner.height())
    else:
        frame = (0, 0)
    minimum = window.minimumSizeHint()
    x, y, w, h = fitted_geometry(wanted, (free.x(), free.y(), free.width(), free.height()), frame,
                                 (min(minimum.width(), free.width()), min(minimum.height(), free.height())))
    window.resize(w, h)
    window.move(x, y)
    return x, y, w, h


def split_sizes(total: int, share: float, need: int, most: float) -> tuple[int, int]:
    """The heights of the 3-D view (top) and the panels (bottom) in ``total`` px: the panels'
    ``share`` of it, more if they ``need`` more to show every panel, but at most ``most`` of it.

    >>> split_sizes(1000, 0.5, 300, 0.72), split_sizes(650, 0.5, 430, 0.72), split_sizes(650, 0.5, 600, 0.72)
    ((500, 500), (220, 430), (182, 468))
    """
    bottom = min(max(int(round(share * total)), need), int(most * total))
    return total - bottom, bottom


class PanelSplit(QObject):
    """The split of ``splitter`` between the 3-D view (top) and the panels (bottom, holding
    ``timeline``), kept through resizes and relayouts (:func:`split_sizes`): the panels' share
    the user left (``share``; dragging the handle sets it), grown to show every panel at its
    least readable height, up to ``most`` of the height (a laptop screen with analysis docks:
    the 3-D view gives up height). Made afresh from the size each time, so that a window made
    smaller and larger again is laid out as before (it kept the squeezed split: a 3-D view 217
    px tall instead of 375)."""

    def __init__(self, splitter, timeline, share: float = 0.52, most: float = 0.72):
        super().__init__(splitter)
        self.splitter, self.timeline = splitter, timeline
        self.share, self.most = share, most
        self._applying = False
        splitter.splitterMoved.connect(self._moved)
        splitter.installEventFilter(self)
        timeline.laidOut.connect(self.apply)

    def need(self) -> int:
        """The panels' side's height that shows every panel (the title and notes over the
        timeline included)."""
        column = self.splitter.widget(1)
        return int(column.height() - self.timeline.height() + self.timeline.needed_height())

    def enlarge(self, on: bool) -> None:
        """The 3-D view over the whole height (the panels hidden), or the split as before."""
        self.splitter.widget(1).setVisible(not on)
        if not on:
            QTimer.singleShot(0, self.apply)

    def apply(self) -> None:
        sizes = self.splitter.sizes()
        total = sum(sizes)
        if total <= 0 or self._applying or not self.splitter.widget(1).isVisible():
            return
        wanted = list(split_sizes(total, self.share, self.need(), self.most))
        if abs(wanted[1] - sizes[1]) > 1:
            self._applying = True
            try:
                self.splitter.setSizes(wanted)
            finally:
                self._applying = False

    def _moved(self, _pos: int, _index: int) -> None:
        top, bottom = self.splitter.sizes()
        if top + bottom > 0 and bottom > 0:
            self.share = bottom / (top + bottom)

    def eventFilter(self, obj, event) -> bool:
        if event.type() == QEvent.Type.Resize:
            QTimer.singleShot(0, self.apply)        # once the splitter has its new size
        return False


class DockWidth(QObject):
    """The width of the docks on one side of ``window`` (``area``: the left docks' column, the
    analysis docks on the right) kept through resizes of the window: the width placed (or the
    user's, dragging the docks' edge), but at most ``share`` of the window. A window made smaller
    squeezes the docks; made larger again, they get their width back (the left column stayed
    squeezed, the settings clipped; a right dock stayed 68 px wide instead of 560). A dock shown
    again (reopened, another tab) gets it too."""

    def __init__(self, window: QMainWindow, area: Qt.DockWidgetArea, width: int, share: float = 0.25):
        super().__init__(window)
        self.window, self.area, self.share = window, area, share
        self.width = width
        self.docks: list[QDockWidget] = []
        self._window_width = window.width()
        self._applying = False
        window.installEventFilter(self)

    def watch(self, dock: QDockWidget) -> None:
        """Keep the width of ``dock`` (one of the side's) while it lives (an analysis view's
        dock is deleted when another model is loaded)."""
        self.docks.append(dock)
        dock.installEventFilter(self)
        dock.destroyed.connect(self._forget)

    def _forget(self) -> None:
        self.docks = [d for d in self.docks if not sip.isdeleted(d)]

    def dock(self) -> QDockWidget | None:
        """The side's dock to resize: the one shown (a tab group's current one), else the last
        one added that is docked there."""
        docked = [d for d in self.docks if not sip.isdeleted(d) and not d.isFloating()
                  and self.window.dockWidgetArea(d) == self.area]
        shown = [d for d in docked if d.isVisible()]
        on_top = [d for d in shown if not d.visibleRegion().isEmpty()]    # a tab behind is "visible"
        return (on_top or shown or docked[-1:] or [None])[0]

    def place(self, width: int) -> None:
        """The docks ``width`` px wide (what the window asks for when it is placed)."""
        self.width = width
        self.apply()

    def wanted(self) -> int:
        """The width the docks get at the window's present width."""
        return min(self.width, int(self.share * self.window.width()))

    def apply(self) -> None:
        self._window_width = self.window.width()
        dock = self.dock()
        if dock is None or self.width <= 0:
            return
        want = self.wanted()
        if abs(dock.width() - want) > 1:
            self._applying = True
            try:
                self.window.resizeDocks([dock], [want], Qt.Orientation.Horizontal)
            finally:
                self._applying = False

    def eventFilter(self, obj, event) -> bool:
        kind = event.type()
        if obj is self.window:
            if kind == QEvent.Type.Resize:
                QTimer.singleShot(0, self.apply)        # once the docks have their new size
        elif kind == QEvent.Type.Show:
            QTimer.singleShot(0, self.apply)
        elif kind == QEvent.Type.Resize and not self._applying and obj.isVisible() \
                and self.window.width() == self._window_width \
                and QGuiApplication.mouseButtons() != Qt.MouseButton.NoButton:
            self.width = obj.width()                    # the user's drag of the docks' edge
        return False


class LeftDocks(QObject):
    """Two docks one above the other: ``bottom`` (holding ``panel``, controls and wrapped text)
    the height its text needs at its width, ``top`` (a list, which scrolls) the rest but at
    least ``least_top`` px; again whenever the window is resized or the panel's text changes
    (a note added after a synthesis: on a laptop the settings' last line was cut off, to be
    scrolled to)."""

    def __init__(self, window: QMainWindow, top: QDockWidget, bottom: QDockWidget, panel: QWidget,
                 least_top: int = 150):
        super().__init__(window)
        self.window, self.top, self.bottom, self.panel = window, top, bottom, panel
        self.least_top = least_top
        self._due = False
        window.installEventFilter(self)
        panel.installEventFilter(self)

    def needed(self) -> int:
        """The bottom dock's height that shows all of the panel (its title bar included)."""
        scroll = self.bottom.widget()
        width = max(scroll.width() - 2 * scroll.frameWidth(), 200)   # no scroll bar then
        text = self.panel.heightForWidth(width)
        text = text if text > 0 else self.panel.sizeHint().height()
        chrome = self.bottom.height() - scroll.viewport().height() if scroll.viewport().height() > 0 else 0
        return text + max(chrome, 0)

    def apply(self) -> None:
        self._due = False
        top, bottom = self.top, self.bottom
        total = top.height() + bottom.height()
        area = self.window.dockWidgetArea
        if (total <= 0 or not top.isVisible() or not bottom.isVisible() or top.isFloating()
                or bottom.isFloating() or area(top) != area(bottom)):
            return
        low = max(total // 2, min(self.needed(), total - self.least_top))
        if abs(bottom.height() - low) > 1:
            self.window.resizeDocks([top, bottom], [total - low, low], Qt.Orientation.Vertical)

    def eventFilter(self, obj, event) -> bool:
        kind = event.type()
        if (obj is self.window and kind == QEvent.Type.Resize) or \
                (obj is self.panel and kind == QEvent.Type.LayoutRequest):
            if not self._due:
                self._due = True
                QTimer.singleShot(0, self.apply)        # once the docks have their new size
        return False
