"""Analysis views (similarity matrix, metrics, PC modes, codebook inspector, errors, kinematics).

``install(window)`` adds them to the main window (see the window contract in
``app/main_window.py``): one "Analysis" menu entry per view, each opening a dock on first use, and
checkable entries for the time-aligned panels (lip aperture, width, protrusion, tangential
velocity with landmarks, lip error). Views are rebuilt when a new model is loaded. Every number
shown comes from the engine (``engine.analysis``, ``engine.evaluation.kinematics`` and the modules they use).

Each view is also a standalone widget taking ``(model[, corpus], window=None)``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from PyQt6.QtCore import QEvent, QObject, Qt
from PyQt6.QtGui import QAction
from PyQt6.QtWidgets import QDockWidget, QWidget

log = logging.getLogger(__name__)

__all__ = ["AnalysisViews", "install"]


class AnalysisViews:
    """The analysis menu, docks and timeline panels of one main window."""

    def __init__(self, window):
        self.window = window
        self.docks: dict[str, QDockWidget] = {}
        self.widgets: dict[str, QWidget] = {}
        self.panels: dict[str, object] = {}
        self.controls = None        # KinematicsControls (owns the velocity panel)
        self._batch = False
        menu = window.menu("Analysis")
        self.view_actions: dict[str, QAction] = {}
        for key, text in VIEWS.items():
            act = QAction(text, window)
            act.triggered.connect(lambda _c=False, k=key: self.open_view(k))
            menu.addAction(act)
            self.view_actions[key] = act
        menu.addSeparator()
        self.panel_actions: dict[str, QAction] = {}
        for key, text in PANELS.items():
            act = QAction(f"Panel: {text}", window)
            act.setCheckable(True)
            act.toggled.connect(lambda on, k=key: self.set_panel(k, on))
            menu.addAction(act)
            self.panel_actions[key] = act
        window.modelReady.connect(self._model_changed)
        window.installEventFilter(_CloseWatcher(self, window))

    # ------------------------------------------------------------------ views
    def _factories(self) -> dict[str, Callable[[], QWidget]]:
        from .errors_view import ErrorView
        from .inspector import CodebookInspector
        from .metrics_view import MetricsView
        from .pc_modes import PCModeExplorer
        from .similarity_view import SimilarityView

        w = self.window
        return {
            "similarity": lambda: SimilarityView(w.model, w),
            "metrics": lambda: MetricsView(w.model, w.corpus, w),
            "pc_modes": lambda: PCModeExplorer(w.model, w),
            "inspector": lambda: CodebookInspector(w.model, w),
            "errors": lambda: ErrorView(w.model, w.corpus, w),
            "kinematics": lambda: self._kinematics_controls(),
        }

    def open_view(self, key: str) -> QWidget | None:
        """Show view ``key`` (created on first use); None while no model is loaded."""
        w = self.window
        if w.model is None:
            w.show_status("the model is not ready yet", 4000)
            return None
        if key not in self.docks:
            widget = self._factories()[key]()
            dock = w.add_dock(widget, TITLES[key], Qt.DockWidgetArea.RightDockWidgetArea)
            self.docks[key] = dock
            self.widgets[key] = widget
        dock = self.docks[key]
        dock.show()
        dock.raise_()
        if key == "kinematics":
            self.show_panels(["aperture", "velocity"])
        if key == "errors":
            self.show_panels(["lip_error"])
        return self.widgets[key]

    def _kinematics_controls(self):
        from .kinematics_panels import KinematicsControls

        if self.controls is None:
            self.controls = KinematicsControls(self.window.model, self.window)
        return self.controls

    # ------------------------------------------------------------------ panels
    def _make_panel(self, key: str):
        from .errors_view import LipErrorPanel
        from .kinematics_panels import LipMeasurePanel

        model = self.window.model
        if key in ("aperture", "width", "protrusion"):
            return LipMeasurePanel(model, key)
        if key == "velocity":
            return self._kinematics_controls().panel
        if key == "lip_error":
            return LipErrorPanel(model)
        raise KeyError(key)

    def show_panels(self, keys: list[str]) -> None:
        """Check several panels at once with a single timeline redraw."""
        tl = self.window.timeline
        self._batch = True
        try:
            for k in keys:
                self.panel_actions[k].setChecked(True)
        finally:
            self._batch = False
        if self.window.model is not None:
            tl.relayout(tl.xlim() if tl.axes else None)

    def set_panel(self, key: str, on: bool) -> None:
        """Add or remove timeline panel ``key`` (kept checked and added once a model exists)."""
        tl = self.window.timeline
        if not on:
            panel = self.panels.pop(key, None)
            if panel is not None:
                tl.remove_panel(panel)
            return
        if key in self.panels or self.window.model is None:
            return
        panel = self._make_panel(key)
        self.panels[key] = panel
        if self._batch:
            tl.panels.append(panel)
        else:
            tl.add_panel(panel)

    # ------------------------------------------------------------------ model changes
    def _model_changed(self) -> None:
        for key, dock in list(self.docks.items()):
            widget = self.widgets.get(key)
            close = getattr(widget, "close_view", None)
            if close is not None:
                close()
            self.window.removeDockWidget(dock)
            dock.deleteLater()
        self.docks.clear()
        self.widgets.clear()
        tl = self.window.timeline
        for panel in self.panels.values():
            if panel in tl.panels:
                tl.panels.remove(panel)
        self.panels.clear()
        self.controls = None
        for key, act in self.panel_actions.items():
            if act.isChecked():
                self.set_panel(key, True)

    def close(self) -> None:
        """Stop timers and close the 3-D views of the open analysis views."""
        for widget in self.widgets.values():
            close = getattr(widget, "close_view", None)
            if close is not None:
                close()


class _CloseWatcher(QObject):
    """Stops the analysis views (animation timers, 3-D views) when the window closes."""

    def __init__(self, views: AnalysisViews, parent: QObject):
        super().__init__(parent)
        self.views = views

    def eventFilter(self, obj, event) -> bool:
        if event.type() == QEvent.Type.Close:
            self.views.close()
        return False


VIEWS = {
    "similarity": "Similarity matrix (Table 1)…",
    "metrics": "Metrics: Table 2 and N sweep (Figure 5)…",
    "pc_modes": "PC mode explorer (Figure 2)…",
    "inspector": "Codebook inspector at the cursor…",
    "errors": "Error analysis…",
    "kinematics": "Kinematics and gesture landmarks…",
}
TITLES = {
    "similarity": "Similarity matrix",
    "metrics": "Metrics",
    "pc_modes": "PC modes",
    "inspector": "Codebook inspector",
    "errors": "Errors",
    "kinematics": "Kinematics",
}
PANELS = {
    "aperture": "lip aperture",
    "width": "lip width",
    "protrusion": "lip protrusion",
    "velocity": "tangential velocity and landmarks",
    "lip_error": "lip error |original - synthesized|",
}


def install(window) -> AnalysisViews:
    """Add the analysis views to ``window``; also ``window.extension("analysis")``."""
    views = AnalysisViews(window)
    window.add_extension("analysis", views)
    return views
