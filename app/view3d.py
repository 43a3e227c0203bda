"""The 3-D view: the window's widget of the faces (``app/face_scene.py``: original and synthesized
face points, lip contours, face surfaces, the pinned faces, camera presets and the close-up of
the lips; articulograph sensors drawn as articulators, ``app/articulators.py``). Hovering a
marker shows its name; in a native window a frame can be rendered ahead of its time (playback).
"""

from __future__ import annotations

import logging

import numpy as np
from PyQt6.QtCore import QPoint, QTimer
from PyQt6.QtGui import QCursor
from PyQt6.QtWidgets import QToolTip, QVBoxLayout, QWidget

from .face_scene import CAMERA_PRESETS, CLOSE_UP, FaceScene, MarkerSet
from .plotter_widget import is_native, make_plotter
from .style import BACKGROUND

log = logging.getLogger(__name__)

__all__ = ["CAMERA_PRESETS", "CLOSE_UP", "FaceView", "MarkerSet"]


class FaceView(QWidget):
    """The 3-D marker view (a PyVista plotter widget, ``app/plotter_widget.py``) showing a
    :class:`~facetraj_app.face_scene.FaceScene` (``scene``; its state and methods are the view's:
    ``set_model``, ``set_view``, ``set_pins``, ``set_camera``, ``synth``, ``preset``, ...).
    ``show_frame(k)`` displays frame ``k`` of the view."""

    def __init__(self, parent: QWidget | None = None, multi_samples: int = 0,
                 native: bool | None = None, closed_mouth: bool = True):
        super().__init__(parent)
        self.plotter = make_plotter(self, multi_samples, native)
        self.plotter.set_background(BACKGROUND)
        self.scene = _WidgetScene(self.plotter, closed_mouth)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.plotter.interactor)
        self._hover_name = ""
        self.plotter.iren.add_observer("MouseMoveEvent", self._on_mouse_move)

    def __getattr__(self, name: str):
        """The scene's state and methods (``synth``, ``pins``, ``set_camera``, ...)."""
        if name in ("scene", "plotter") or name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.scene, name)

    def resizeEvent(self, event) -> None:
        """A preset's camera (not one the user moved since) fitted to the new size (the
        articulators' parallel projection too: they fill the view whatever its shape); the
        close-up of the lips laid out again (its grid of faces follows the view's shape)."""
        super().resizeEvent(event)
        QTimer.singleShot(0, self._refit)

    def _refit(self) -> None:
        if self.scene.model is not None and not self.scene.camera_moved:
            self.scene.set_camera(self.scene.preset)

    def show_frame(self, k: int, render: bool = True) -> None:
        """Put frame ``k`` of the current view in the scene (the points move in place) and put
        it on screen (:meth:`request_render`); a frame rendered ahead (:meth:`prepare_frame`) is
        only put on screen."""
        if not self.scene.n_frames:
            return
        k = int(np.clip(k, 0, self.scene.n_frames - 1))
        ahead, self.scene.ahead = self.scene.ahead, -1
        if render and k == ahead:
            self.scene.frame = k
            self.plotter.present()
            return
        self.scene.show_frame(k, render)

    def prepare_frame(self, k: int) -> None:
        """Render frame ``k`` ahead, off screen, so that ``show_frame(k)`` only has to put it on
        screen (playback: the render's time does not delay the frame's arrival). Native view
        only (:func:`facetraj_app.plotter_widget.is_native`), when shown; the frame on screen stays."""
        if not self.scene.n_frames or not is_native(self.plotter) or not self.plotter.isVisible():
            return
        k = int(np.clip(k, 0, self.scene.n_frames - 1))
        self.scene.move_points(k)
        self.plotter.render_ahead()
        self.scene.ahead = k

    def _on_mouse_move(self, obj, event) -> None:
        try:
            x, y = self.plotter.iren.interactor.GetEventPosition()
            label = self.scene.marker_at(x, y)
        except Exception:  # never let a hover raise inside VTK's callback
            log.debug("hover failed", exc_info=True)
            return
        if label != self._hover_name:
            self._hover_name = label or ""
            if label:
                QToolTip.showText(QCursor.pos() + QPoint(12, 8), label, self)
            else:
                QToolTip.hideText()

    def close_view(self) -> None:
        try:
            self.plotter.close()
        except Exception:
            log.debug("plotter close failed", exc_info=True)


class _WidgetScene(FaceScene):
    """A scene in a widget: one render of the changed scene at once in a native window (it swaps
    only its own pixels), else at the widget's next paint, which Qt composes with the rest of the
    window's (a ``render()`` there would render twice); a hidden view renders when shown. A
    change of the scene drops the frame rendered ahead (its owner's ``ahead``)."""

    def request_render(self) -> None:
        if not is_native(self.plotter):
            self.plotter.update()
        elif self.plotter.isVisible():
            self.plotter.render()
