"""The main window's menus and docks: menus by name (new ones before Help), menu entries whose
engine errors are reported rather than raised, and docks tabbed together by area."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PyQt6.QtCore import Qt
from PyQt6.QtGui import QAction
from PyQt6.QtWidgets import QDockWidget, QMainWindow, QMenu, QWidget

from engine.errors import FacetrajError


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
        """A dock tabbed with the one added to the same area before it."""
        dock = self.dock(widget, title, area)
        previous = self.last.get(area)
        if previous is not None:
            self.window.tabifyDockWidget(previous, dock)
        self.last[area] = dock
        return dock
