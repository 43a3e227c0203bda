"""The widget the 3-D views render in: a PyVista plotter that is a Qt widget.

On X11 (Qt's ``xcb`` platform, Xvfb included) the plotter renders into a native child window
(:class:`NativePlotter`: VTK's own ``QVTKRenderWindowInteractor`` with PyVista's plotter API).
pyvistaqt's ``QtInteractor`` is a ``QOpenGLWidget`` instead, and once a ``QOpenGLWidget`` is in a
window, Qt composes the *whole* window through OpenGL at every flush: with a software renderer
(Mesa llvmpipe under Xvfb) that costs more than the 3-D render itself (docs/benchmarks.md,
"Playback"). In a native child window VTK swaps
only its own pixels, and the rest of the window stays a raster backing store whose flushes copy
only what changed (a moving cursor, a label). Other platforms (Wayland) keep ``QtInteractor``;
``FACETRAJ_3D_WIDGET=opengl`` chooses it on X11 too.
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Iterator

import numpy as np
import pyvista
from PyQt6.QtCore import QPoint, QRect
from PyQt6.QtGui import QGuiApplication, QImage, QPainter, QPixmap
from PyQt6.QtWidgets import QWidget
from pyvista.plotting.plotter import BasePlotter
from pyvista.plotting.render_window_interactor import RenderWindowInteractor
from vtkmodules.qt.QVTKRenderWindowInteractor import QVTKRenderWindowInteractor

log = logging.getLogger(__name__)

ENV_WIDGET = "FACETRAJ_3D_WIDGET"


def native_window_available() -> bool:
    """Whether 3-D views render into a native child window here (X11, unless
    ``FACETRAJ_3D_WIDGET=opengl``)."""
    if os.environ.get(ENV_WIDGET, "").lower() == "opengl":
        return False
    return QGuiApplication.platformName() == "xcb"


def make_plotter(parent: QWidget | None = None, multi_samples: int = 0, native: bool | None = None):
    """A PyVista plotter widget: :class:`NativePlotter` when ``native`` (default: where
    :func:`native_window_available`), else pyvistaqt's ``QtInteractor``. Neither renders on a
    timer: call ``render()`` after changing the scene."""
    if native is None:
        native = native_window_available()
    if native:
        return NativePlotter(parent, multi_samples=multi_samples)
    from pyvistaqt import QtInteractor

    return QtInteractor(parent, auto_update=False, multi_samples=multi_samples)


def is_native(plotter) -> bool:
    """Whether ``plotter`` renders into its own native window (:class:`NativePlotter`)."""
    return isinstance(plotter, NativePlotter)


def grab_with_3d(top: QWidget) -> QPixmap:
    """``top.grab()`` with every visible 3-D view inside it drawn in, as on the screen.

    A widget grab holds noise or black where a view renders through OpenGL (a native window or
    a ``QOpenGLWidget``): each such view shown (not in a hidden tab or dock) is rendered and its
    own picture painted over its place, clipped to the part of it on screen (a dock's scroll
    area may hide some). The main window's 3-D view, the PC-modes view and the Live window's face
    are all saved this way.
    """
    pix = top.grab()
    dpr = pix.devicePixelRatio()
    painter = QPainter(pix)
    try:
        for view in top.findChildren(QWidget):
            if not isinstance(view, BasePlotter) or not view.isVisible():
                continue
            visible = view.visibleRegion().boundingRect()
            if visible.isEmpty():
                continue
            BasePlotter.render(view)
            img = view.screenshot(return_img=True)
            if img is None or not img.size:
                continue
            rgb = np.ascontiguousarray(img[:, :, :3])
            h, w = rgb.shape[:2]
            qimg = QImage(rgb.data, w, h, 3 * w, QImage.Format.Format_RGB888)
            qimg = qimg.scaled(int(view.width() * dpr), int(view.height() * dpr))
            qimg.setDevicePixelRatio(dpr)
            origin = view.mapTo(top, QPoint(0, 0))
            painter.save()
            painter.setClipRect(QRect(origin + visible.topLeft(), visible.size()))
            painter.drawImage(origin, qimg)
            painter.restore()
    finally:
        painter.end()
    return pix


@contextlib.contextmanager
def _base_plotter_init_skipped() -> Iterator[None]:
    """PyQt's cooperative ``__init__`` calls the next base class's ``__init__`` (PyVista's
    ``BasePlotter``) with no arguments from inside ``QWidget.__init__``: skip that call, the real
    one follows (as pyvistaqt's ``QtInteractor`` does)."""
    init = BasePlotter.__init__
    BasePlotter.__init__ = lambda *_a, **_k: None
    try:
        yield
    finally:
        BasePlotter.__init__ = init


class NativePlotter(QVTKRenderWindowInteractor, BasePlotter):
    """A PyVista plotter in VTK's native-window Qt widget (a ``QWidget`` with its own X window
    and OpenGL context). ``render()`` draws and swaps at once; a paint event (expose, resize)
    renders too. As with pyvistaqt's ``QtInteractor``, ``interactor`` is the widget itself."""

    def __init__(self, parent: QWidget | None = None, multi_samples: int = 0):
        with _base_plotter_init_skipped():
            QVTKRenderWindowInteractor.__init__(self, parent)
        BasePlotter.__init__(self)
        self.interactor = self
        self.ren_win = self.GetRenderWindow()
        self.ren_win.SetMultiSamples(int(multi_samples))
        # VTK renders into its own framebuffer and by default copies both its colour and its depth
        # into the window's buffers at every frame ("BlitToHardware"); the depth copy is a
        # full-window shader pass (a third of a render on llvmpipe, measured) that nothing here
        # uses: nothing else draws into this window. Colour only, into the window's back buffer.
        self.ren_win.SetFrameBlitModeToBlitToCurrent()
        for renderer in self.renderers:
            renderer.view_isometric()
            self.ren_win.AddRenderer(renderer)
        self.background_color = pyvista.global_theme.background
        self.iren = RenderWindowInteractor(self, interactor=self.ren_win.GetInteractor())
        self.iren.interactor.RemoveObservers("MouseMoveEvent")
        self.iren.initialize()
        self.enable_trackball_style()
        self._first_time = False        # BasePlotter renders only after show(); Qt shows this one

    def render(self) -> None:
        """Render and swap now (``QWidget.render`` would shadow PyVista's)."""
        BasePlotter.render(self)

    def render_ahead(self) -> None:
        """Render the scene into VTK's own framebuffer and wait until it is drawn, without putting
        it on screen: :meth:`present` does, in a fraction of the time."""
        rw = self.ren_win
        rw.SwapBuffersOff()
        try:
            BasePlotter.render(self)
        finally:
            rw.SwapBuffersOn()
        rw.WaitForCompletion()

    def present(self) -> None:
        """Put the last render on screen: copy it to the window and swap."""
        self.ren_win.Frame()

    def _check_has_ren_win(self) -> None:
        """Screenshots read this window's pixels: make its context current first (another
        view's render may have made its own current)."""
        if self.render_window is not None:
            self.render_window.MakeCurrent()
        BasePlotter._check_has_ren_win(self)

    def paintEvent(self, ev) -> None:
        if not getattr(self, "_closed", True):         # never render a closed plotter
            super().paintEvent(ev)

    def close(self) -> None:
        """Release the plotter and its render window (returns None, as ``QtInteractor``)."""
        if getattr(self, "_closed", True):
            return
        BasePlotter.close(self)
        QVTKRenderWindowInteractor.close(self)
