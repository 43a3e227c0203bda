"""Analysis views (similarity matrix, metrics, PC modes, codebook inspector, errors, kinematics).

``install(window)`` adds them to the main window (see the window contract in
``app/main_window.py``): one "Analysis" menu entry per view, each opening a dock on first use, and
checkable entries for the time-aligned panels (lip aperture, width, protrusion, tangential
velocity with landmarks, lip error). Views are rebuilt when a new model is loaded. Every number
shown comes from the engine (``facetraj_engine.analysis``, ``facetraj_engine.evaluation.kinematics`` and the
modules they use).

Each view is also a standalone widget taking ``(model[, corpus], window=None)``.
"""

from __future__ import annotations

import importlib
import logging
import sys
from collections.abc import Callable

from PyQt6.QtCore import QEvent, QObject, Qt, pyqtSignal
from PyQt6.QtGui import QAction
from PyQt6.QtWidgets import QDockWidget, QWidget

from ..workers import keep_long_lived

log = logging.getLogger(__name__)

__all__ = ["AnalysisViews", "install"]


class AnalysisViews(QObject):
    """The analysis menu, docks and timeline panels of one main window. ``viewOpened(key)``
    after a view is shown."""

    viewOpened = pyqtSignal(str)

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self._importing: dict[str, list[Callable[[], None]]] = {}
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
    def _after_import(self, module: str, fn: Callable[[], None], label: str) -> bool:
        """Run ``fn`` now when the view module ``module`` is imported, else import it in the
        background first (a view's module brings scipy's clustering or ``ndimage``: 0.1-1.7 s
        that must not freeze the window) and run ``fn`` then. Whether ``fn`` ran now."""
        name = f"{__name__}.{module}"
        if name in sys.modules:
            fn()
            return True
        waiting = self._importing.setdefault(name, [])
        waiting.append(fn)
        if len(waiting) == 1:
            def done(_module) -> None:
                for then in self._importing.pop(name, []):
                    then()

            def failed(exc: BaseException) -> None:
                self._importing.pop(name, None)
                self.window.report_error(exc)

            self.window.run_task(lambda _p: importlib.import_module(name), done, label,
                                 on_error=failed)
        return False

    def _create(self, key: str) -> QWidget:
        """View ``key``'s widget (its module imported). Each view does its slow work in the
        background (``app/analysis/common.py: task_runner``) or in steps (``one_per_pass``)."""
        w = self.window
        if key == "kinematics":
            return self._kinematics_controls()
        module = sys.modules[f"{__name__}.{VIEW_MODULES[key]}"]
        cls = getattr(module, VIEW_CLASSES[key])
        if key in ("metrics", "errors"):
            return cls(w.model, w.corpus, w)
        return cls(w.model, w)

    def open_view(self, key: str) -> QWidget | None:
        """Show view ``key`` (created on first use) and return it; None while no model is loaded
        or while its module is imported in the background (``viewOpened`` follows)."""
        w = self.window
        if w.model is None:
            w.show_status("the model is not ready yet", 4000)
            return None
        if self._after_import(VIEW_MODULES[key], lambda: self._open(key), f"opening {TITLES[key]}"):
            return self.widgets[key]
        return None

    def _open(self, key: str) -> None:
        w = self.window
        if w.model is None:
            return
        if key not in self.docks:
            widget = self._create(key)
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
        keep_long_lived()       # full garbage passes over every view's objects froze the window
        self.viewOpened.emit(key)

    def _kinematics_controls(self):
        from .kinematics_panels import KinematicsControls

        if self.controls is None:
            self.controls = KinematicsControls(self.window.model, self.window)
        return self.controls

    # ------------------------------------------------------------------ panels
    def _make_panel(self, key: str):
        model = self.window.model
        if key in ("aperture", "width", "protrusion"):
            from .kinematics_panels import LipMeasurePanel
            return LipMeasurePanel(model, key, getattr(self.window, "closed_lips", None))
        if key == "velocity":
            return self._kinematics_controls().panel
        if key == "lip_error":
            from .errors_view import LipErrorPanel
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
            tl.relayout(tl.xlim() if tl.axes else None, soon=True)

    def set_panel(self, key: str, on: bool) -> None:
        """Add or remove timeline panel ``key`` (kept checked and added once a model exists)."""
        tl = self.window.timeline
        if not on:
            panel = self.panels.pop(key, None)
            if panel is not None:
                tl.remove_panel(panel, soon=True)
            return
        if key in self.panels or self.window.model is None:
            return
        self._after_import(PANEL_MODULES[key], lambda: self._add_panel(key),
                           f"adding the {PANELS[key]} panel")

    def _add_panel(self, key: str) -> None:
        """Add panel ``key`` (its module imported) if it is still wanted."""
        if (key in self.panels or self.window.model is None
                or not self.panel_actions[key].isChecked()):
            return
        tl = self.window.timeline
        panel = self._make_panel(key)
        self.panels[key] = panel
        if self._batch:
            tl.panels.append(panel)
        else:
            tl.add_panel(panel, soon=True)

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
        for panel in self.panels.values():      # a build under way drawing them replaced (the
            tl.remove_panel(panel, soon=True)   # velocity panel's controls are deleted below)
        self.panels.clear()
        if self.controls is not None:       # made for the velocity panel alone, without a dock
            self.controls.close_view()
            self.controls.deleteLater()
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
#: the module (in this package) and class of each view
VIEW_MODULES = {"similarity": "similarity_view", "metrics": "metrics_view", "pc_modes": "pc_modes",
                "inspector": "inspector", "errors": "errors_view", "kinematics": "kinematics_panels"}
VIEW_CLASSES = {"similarity": "SimilarityView", "metrics": "MetricsView",
                "pc_modes": "PCModeExplorer", "inspector": "CodebookInspector",
                "errors": "ErrorView", "kinematics": "KinematicsControls"}
PANELS = {
    "aperture": "lip aperture",
    "width": "lip width",
    "protrusion": "lip protrusion",
    "velocity": "tangential velocity and landmarks",
    "lip_error": "lip error |original - synthesized|",
}


PANEL_MODULES = {"aperture": "kinematics_panels", "width": "kinematics_panels",
                 "protrusion": "kinematics_panels", "velocity": "kinematics_panels",
                 "lip_error": "errors_view"}


def install(window) -> AnalysisViews:
    """Add the analysis views to ``window``; also ``window.extension("analysis")``."""
    views = AnalysisViews(window)
    window.add_extension("analysis", views)
    return views
