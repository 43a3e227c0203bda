"""The main window's menus and docks: menus by name (new ones before Help), menu entries whose
engine errors are reported rather than raised, and docks tabbed together by area, each view in a
scroll area so that no dock can push the window wider than the screen."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PyQt6.QtCore import Qt
from PyQt6.QtGui import QAction
from PyQt6.QtWidgets import QDockWidget, QFrame, QMainWindow, QMenu, QScrollArea, QWidget

from facetraj_engine.errors import FacetrajError


class WindowMenus:
    """The menus of ``window`` by name; an entry's engine error goes to ``on_error``."""

    def __init__(self, window: QMainWindow, on_error: Callable[[BaseException], None]):
        self.window = window
        self.on_error = on_error
        self.menus: dict[str, QMenu] = {}

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


class WindowDocks:
    """The docks of ``window``: movable, floatable, closable; extra docks in one area tabbed."""

    def __init__(self, window: QMainWindow):
        self.window = window
        self.last: dict[Qt.DockWidgetArea, QDockWidget] = {}

    def dock(self, widget: QWidget, title: str, area: Qt.DockWidgetArea) -> QDockWidget:
        dock = QDockWidget(title, self.window)
        dock.setObjectName(title)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                         | QDockWidget.DockWidgetFeature.DockWidgetClosable)
        self.window.addDockWidget(area, dock)
        return dock

    def add(self, widget: QWidget, title: str, area: Qt.DockWidgetArea) -> QDockWidget:
        """A dock tabbed with the one added to the same area before it; ``widget`` sits in a
        scroll area (``dock.widget().widget()``): a view wider than its dock scrolls instead of
        widening the window (a main window grows to fit the minimum widths of its docks: four
        analysis views took it from 1600 to 1864 px and it stayed so after they closed). The
        first dock of an area gets :func:`dock_width` of the window."""
        scroll = QScrollArea()
        scroll.setWidget(widget)
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QFrame.Shape.NoFrame)
        # across only: the views fill the dock's height (their tables, plots and splitters
        # stretch or shrink), so no dock can make the window taller either
        scroll.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        dock = self.dock(scroll, title, area)
        previous = self.last.get(area)
        if previous is not None:
            self.window.tabifyDockWidget(previous, dock)
        else:
            orientation = (Qt.Orientation.Horizontal
                           if area in (Qt.DockWidgetArea.LeftDockWidgetArea,
                                       Qt.DockWidgetArea.RightDockWidgetArea)
                           else Qt.Orientation.Vertical)
            self.window.resizeDocks([dock], [dock_width(self.window.width())], orientation)
        self.last[area] = dock
        return dock


def dock_width(window_width: int) -> int:
    """The width an analysis dock opens with: a third of the window, 420-620 px.

    >>> dock_width(1600), dock_width(1280), dock_width(2400)
    (560, 448, 620)
    """
    return int(min(620, max(420, 0.35 * window_width)))
