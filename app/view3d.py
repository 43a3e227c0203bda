"""The 3-D view: original and synthesized face markers, lip contours and an optional face surface.

The two marker sets share one scene, overlaid or side by side. Each set is one ``vtkPoints``
shared by its markers and its lip contour lines (the synthesized set's face surface follows a few
mm beneath), so a frame update is a few small array copies and one render. Hovering a marker shows its name.
"""

from __future__ import annotations

import logging

import numpy as np
import pyvista as pv
from PyQt6.QtCore import QPoint
from PyQt6.QtGui import QCursor
from PyQt6.QtWidgets import QToolTip, QVBoxLayout, QWidget

from facetraj_engine.analysis.lips import ClosedLips, closed_lips
from facetraj_engine.method.model import Model

from .articulators import ArticulatorSet, fit_parallel, gap_axis, is_articulograph
from .plotter_widget import is_native, make_plotter
from .state import UtteranceView
from .style import BACKGROUND, CAVITY_COLOR, ORIGINAL_COLOR, SURFACE_COLOR, SYNTH_COLOR
from .surface import Mouth, lip_contours, stored_face_triangles

log = logging.getLogger(__name__)

SURFACE_INSET_MM = 4.0
#: how far behind the lips the dark backing of the mouth opening lies
CAVITY_DEPTH_MM = 4.0

CAMERA_PRESETS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    # direction from the face to the camera (x to the talker's left, y up, z forward), view up
    "front": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "profile": ((-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    "three-quarter": ((-0.6, 0.12, 1.0), (0.0, 1.0, 0.0)),
}


def _fill_nan(markers: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """For display: a marker not seen keeps its last seen position (else the fallback)."""
    out = np.array(markers, dtype=np.float64)
    bad = ~np.isfinite(out).all(axis=2)
    if not bad.any():
        return out
    for m in np.flatnonzero(bad.any(axis=0)):
        ok = ~bad[:, m]
        if not ok.any():
            out[:, m] = fallback[m]
            continue
        idx = np.where(ok, np.arange(len(ok)), 0)
        np.maximum.accumulate(idx, out=idx)
        first = int(np.argmax(ok))
        idx[:first] = first
        out[:, m] = out[idx, m]
    return out


class MarkerSet:
    """One marker set in the scene: points, lip lines, optionally a surface, all sharing points.
    The surface has the lips' inner edges too (``mouth``, :class:`facetraj_app.surface.Mouth`): the mouth
    closes where the lips meet. Adding them renders nothing (the owner renders the finished scene
    once)."""

    def __init__(self, plotter: pv.BasePlotter, name: str, color: str, neutral: np.ndarray,
                 contours: list[list[int]], triangles: np.ndarray | None, mouth: Mouth | None = None):
        self.name = name
        self.mouth = mouth if triangles is not None and len(triangles) else None
        self.points = pv.PolyData(neutral.copy())
        self.points.verts = np.column_stack([np.ones(len(neutral), int), np.arange(len(neutral))]).ravel()
        self.actor = plotter.add_mesh(self.points, color=color, render_points_as_spheres=True,
                                      point_size=11, style="points", name=f"{name}-points",
                                      reset_camera=False, lighting=True, pickable=False,
                                      ambient=0.3, diffuse=0.8, render=False)
        self.lines = pv.PolyData()
        self.lines.SetPoints(self.points.GetPoints())
        self.lines.lines = np.concatenate([[len(c), *c] for c in contours])
        self.line_actor = plotter.add_mesh(self.lines, color=color, line_width=3, name=f"{name}-lips",
                                           reset_camera=False, pickable=False, render=False)
        self.surface_actor = None
        self._inset: np.ndarray | None = None
        self.n_markers = len(neutral)
        if triangles is not None and len(triangles):
            self._add_surface(plotter, name, neutral, triangles)
        self.current = neutral.copy()
        # numpy views of the VTK point arrays: a frame update writes into them in place
        self.xyz = self.points.points
        self.surface_xyz = self.surface.points if self._inset is not None else None

    def _add_surface(self, plotter: pv.BasePlotter, name: str, neutral: np.ndarray,
                     triangles: np.ndarray) -> None:
        vertices, tri = neutral, triangles
        if self.mouth is not None:
            vertices = np.vstack([neutral, self.mouth.points(neutral)])
            tri = np.vstack([triangles, self.mouth.triangles(len(neutral))])
        faces = np.column_stack([np.full(len(tri), 3), tri]).ravel()
        # normals of the neutral face, kept (the face moves little): smooth, cheap shading
        shape = pv.PolyData(vertices, faces=faces).compute_normals(
            cell_normals=False, auto_orient_normals=True, consistent_normals=True)
        normals = np.asarray(shape.point_data["Normals"])
        faces = shape.faces                # wound consistently (the lips' strips too): no face
        #                                    of the surface is lit as a back face
        if normals[:, 2].mean() < 0:       # z is forward: normals face the viewer
            normals = -normals
        if self.mouth is not None:         # an inner edge point lies as deep as its marker
            normals[self.n_markers:] = normals[self.mouth.owners()]
        # the surface lies SURFACE_INSET_MM under the markers, so that it hides neither its
        # own markers nor original markers a little behind them; opaque, because a
        # translucent surface costs an order-independent transparency pass (several times
        # the whole frame on a software renderer)
        self._inset = SURFACE_INSET_MM * normals
        self.surface = pv.PolyData(vertices - self._inset, faces=faces)
        self.surface.point_data.active_normals = normals
        self.surface_actor = plotter.add_mesh(self.surface, color=SURFACE_COLOR, opacity=1.0,
                                              smooth_shading=False, name=f"{name}-surface",
                                              reset_camera=False, pickable=False,
                                              specular=0.1, ambient=0.3, diffuse=0.75, render=False)
        self.surface_actor.GetProperty().SetInterpolationToGouraud()
        if self.mouth is not None:
            self._add_cavity(plotter, name, vertices)

    def _add_cavity(self, plotter: pv.BasePlotter, name: str, vertices: np.ndarray) -> None:
        """A dark pouch behind the mouth opening: walls from the opening's outline back to a
        wider outline CAVITY_DEPTH_MM behind it, closed at the back. Whatever the angle, a line
        of sight through an open mouth ends on it (dark), never on the background (a backing
        behind the opening alone left a see-through sliver at the far corner in the ¾ view);
        a closed mouth shows skin."""
        self._cavity_loop = self.mouth.opening_loop(self.n_markers)
        n = len(self._cavity_loop)
        i, j = np.arange(n), (np.arange(n) + 1) % n
        walls = np.concatenate([np.column_stack([i, j, n + j]), np.column_stack([i, n + j, n + i])])
        back = np.column_stack([np.full(n, 2 * n), n + i, n + j])
        tri = np.concatenate([walls, back])
        faces = np.column_stack([np.full(len(tri), 3), tri]).ravel()
        self.cavity = pv.PolyData(self._cavity_points(vertices - self._inset), faces=faces)
        self.cavity_actor = plotter.add_mesh(self.cavity, color=CAVITY_COLOR, name=f"{name}-mouth",
                                             reset_camera=False, pickable=False, lighting=False,
                                             render=False)

    def _cavity_points(self, surface: np.ndarray) -> np.ndarray:
        """The pouch's points for the surface's vertices ``surface``: the opening's outline as
        it is, the same moved back (z is forward), a tenth wider and twice as tall about its
        centre, and the centre of the back."""
        loop = surface[self._cavity_loop]
        centre = loop.mean(axis=0)
        back = centre + (loop - centre) * [1.1, 2.0, 1.0]
        back[:, 2] = loop[:, 2] - CAVITY_DEPTH_MM
        return np.vstack([loop, back, centre - [0.0, 0.0, CAVITY_DEPTH_MM]])

    def set_points(self, pts: np.ndarray) -> None:
        """Move the markers (and their lip lines and surface) to ``pts``, in place: the same
        actors and point arrays, no new VTK objects."""
        self.current = pts
        np.copyto(self.xyz, pts)
        self.points.GetPoints().Modified()
        if self.surface_xyz is not None:
            m = self.n_markers
            np.subtract(pts, self._inset[:m], out=self.surface_xyz[:m])
            if self.mouth is not None:
                np.subtract(self.mouth.points(pts), self._inset[m:], out=self.surface_xyz[m:])
                self.cavity.points[:] = self._cavity_points(self.surface_xyz)
                self.cavity.GetPoints().Modified()
            self.surface.GetPoints().Modified()

    def set_visible(self, visible: bool, surface: bool) -> None:
        self.actor.SetVisibility(visible)
        self.line_actor.SetVisibility(visible)
        if self.surface_actor is not None:
            self.surface_actor.SetVisibility(visible and surface)
        if self.mouth is not None:
            self.cavity_actor.SetVisibility(visible and surface)


class FaceView(QWidget):
    """The 3-D marker view (a PyVista plotter widget, ``app/plotter_widget.py``).
    ``show_frame(k)`` displays frame ``k`` of the view."""

    def __init__(self, parent: QWidget | None = None, multi_samples: int = 0,
                 native: bool | None = None, closed_mouth: bool = True):
        super().__init__(parent)
        self.closed_mouth = closed_mouth       # False: the lips' strips left out (the old surface)
        self.plotter = make_plotter(self, multi_samples, native)
        self.plotter.set_background(BACKGROUND)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.plotter.interactor)
        self.model: Model | None = None
        self.view: UtteranceView | None = None
        self.original: MarkerSet | None = None
        self.synth: MarkerSet | None = None
        self.side_by_side = False
        self.articulators = False               # the model's markers are articulograph sensors
        self.show_surface = True
        self.show_original = True
        self.show_synth = True
        self.frame = -1
        self.ahead = -1              # the frame rendered ahead, not on screen yet (prepare_frame)
        self.preset = "three-quarter"
        self._orig = self._syn = None
        self._offset = np.zeros(3)
        self._fit: tuple[np.ndarray, float] | None = None   # what the camera was fitted to
        self.pins: list = []                    # the pinned results shown (app/pins.py: Pin)
        self._pin_sets: dict[str, MarkerSet] = {}   # by colour: made once, reused
        self._pin_frames: list[np.ndarray] = []
        self._hover_name = ""
        self.plotter.iren.add_observer("MouseMoveEvent", self._on_mouse_move)

    # ------------------------------------------------------------------ scene
    def set_model(self, model: Model, closed: ClosedLips | None = None) -> None:
        """Build the scene for ``model``'s marker set; ``closed``: the talker's lips at closure
        (``facetraj_engine.analysis.lips.closed_lips``, made here if not given), where the mouth shuts."""
        self.model = model
        self.articulators = is_articulograph(model)     # sensors drawn as articulators, no face
        self.ahead = -1
        self.plotter.clear()
        # one light that follows the camera plus a key light from above: shading that shows
        # the face's shape at little cost (each light is per-fragment work on a software renderer)
        self.plotter.remove_all_lights()
        self.plotter.add_light(pv.Light(light_type="headlight", intensity=0.75))
        self.plotter.add_light(pv.Light(position=(0.4, 1.0, 0.6), light_type="camera light",
                                        intensity=0.35))
        neutral = model.neutral_face()
        self.neutral = neutral
        self.contours = lip_contours(neutral, model.upper_lip, model.lower_lip, list(model.lip_corners))
        self._tri = self._mouth = None          # the faces' surface and lips (the pins' too)
        if not self.articulators:
            self._tri = stored_face_triangles(neutral, self.contours)
            closed = closed if closed is not None else closed_lips(model)
            if self.closed_mouth:
                self._mouth = Mouth.between(neutral, self.contours, closed.markers)
        self._pin_sets = {}
        self.synth = self._new_set("synthesized", SYNTH_COLOR)
        # the original markers have a surface too: shown when the synthesized ones are hidden
        self.original = self._new_set("original", ORIGINAL_COLOR)
        axis = gap_axis(model)
        self._half_gap = np.zeros(3)
        self._half_gap[axis] = 0.55 * float(np.ptp(neutral[:, axis])) + 10.0
        # no VTK text (legend, caption): re-rasterizing text costs more than the whole scene on a
        # software renderer; the window shows the legend and the time in Qt widgets instead
        self._update_visibility()
        self.set_camera(self.preset, render=False)
        self.request_render()       # once: the meshes were added without a render each

    def _new_set(self, name: str, color: str) -> MarkerSet | ArticulatorSet:
        """A marker set of the model in the scene: a face (points, lip lines, surface) or, for
        articulograph sensors, the articulators (``app/articulators.py``)."""
        if self.articulators:
            return ArticulatorSet(self.plotter, name, color, self.neutral, self.model.roles)
        return MarkerSet(self.plotter, name, color, self.neutral, self.contours, self._tri,
                         self._mouth)

    def set_view(self, view: UtteranceView) -> None:
        self.view = view
        self._syn = _fill_nan(view.shown, self.neutral)
        self._orig = None if view.original is None else _fill_nan(view.original, self.neutral)
        if self.articulators:                    # the recording's palate trace, if it has one
            self.original.set_palate(view.original)
        self._update_visibility()
        self.frame = -1

    def set_pins(self, pins: list) -> None:
        """Show ``pins`` (results kept to compare, ``app/pins.py``: each with its ``view`` and
        ``color``) beside the current face, each with its surface and lips, in its colour."""
        if self.synth is None:
            return
        refit = len(pins) != len(self.pins)         # the faces' row changed: the camera fits it
        self.pins = list(pins)
        for pin in self.pins:
            if pin.color not in self._pin_sets:
                self._pin_sets[pin.color] = self._new_set(f"pin-{pin.color}", pin.color)
        for pin in self.pins:
            self._pin_sets[pin.color].name = pin.name     # the hover's "UL_C (pin 1)"
        self._pin_frames = [_fill_nan(p.view.shown, self.neutral) for p in self.pins]
        self._update_visibility()
        if self.frame >= 0:
            self._move_points(self.frame)
        if refit:
            self.set_camera(self.preset)
        else:
            self.request_render()

    def _pin_offset(self, i: int) -> np.ndarray:
        """Where pin ``i``'s face goes: beside the synthesized face, to the talker's left."""
        return self._offset + (i + 1) * 2 * self._half_gap

    def _update_visibility(self) -> None:
        self.ahead = -1
        if self.synth is None:
            return
        shown = {p.color for p in self.pins}
        for color, mset in self._pin_sets.items():
            mset.set_visible(color in shown, self.show_surface)
        has_orig = self._orig is not None or self.view is None
        # overlaid, one surface: the synthesized face's, or the original's when only it is
        # shown; side by side, each face its own (closure compared face to face)
        self.original.set_visible(self.show_original and has_orig,
                                  self.show_surface and (not self.show_synth or self.side_by_side))
        self.synth.set_visible(self.show_synth, self.show_surface)
        self._offset = self._half_gap if (self.side_by_side and has_orig) else np.zeros(3)

    def show_frame(self, k: int, render: bool = True) -> None:
        """Put frame ``k`` of the current view in the scene (the points move in place) and put
        it on screen (:meth:`request_render`); a frame rendered ahead (:meth:`prepare_frame`) is
        only put on screen."""
        if self._syn is None:
            return
        k = int(np.clip(k, 0, len(self._syn) - 1))
        ahead, self.ahead = self.ahead, -1
        if render and k == ahead:
            self.frame = k
            self.plotter.present()
            return
        self._move_points(k)
        self.frame = k
        if render:
            self.request_render()

    def prepare_frame(self, k: int) -> None:
        """Render frame ``k`` ahead, off screen, so that ``show_frame(k)`` only has to put it on
        screen (playback: the render's time does not delay the frame's arrival). Native view
        only (:func:`facetraj_app.plotter_widget.is_native`), when shown; the frame on screen stays."""
        if self._syn is None or not is_native(self.plotter) or not self.plotter.isVisible():
            return
        k = int(np.clip(k, 0, len(self._syn) - 1))
        self._move_points(k)
        self.plotter.render_ahead()
        self.ahead = k

    def _move_points(self, k: int) -> None:
        self.synth.set_points(self._syn[k] + self._offset)
        if self._orig is not None:
            self.original.set_points(self._orig[min(k, len(self._orig) - 1)] - self._offset)
        for i, (pin, frames) in enumerate(zip(self.pins, self._pin_frames, strict=True)):
            self._pin_sets[pin.color].set_points(frames[min(k, len(frames) - 1)] + self._pin_offset(i))

    def request_render(self) -> None:
        """One render of the changed scene: at once in a native window (it swaps only its own
        pixels), else at the widget's next paint, which Qt composes with the rest of the window's
        (a ``render()`` there would render twice). A hidden view renders when it is shown."""
        if not is_native(self.plotter):
            self.plotter.update()
        elif self.plotter.isVisible():
            self.plotter.render()

    def rerender(self) -> None:
        """Render now (synchronously), e.g. before a screenshot."""
        if self.frame >= 0:
            self.show_frame(self.frame, render=False)
        self.plotter.render()

    # ------------------------------------------------------------------ options
    def set_side_by_side(self, on: bool) -> None:
        self.side_by_side = bool(on)
        self._update_visibility()
        self.rerender()
        self.set_camera(self.preset)

    def set_surface(self, on: bool) -> None:
        self.show_surface = bool(on)
        self._update_visibility()
        self.plotter.render()

    def set_sets_visible(self, original: bool, synth: bool) -> None:
        self.show_original, self.show_synth = bool(original), bool(synth)
        self._update_visibility()
        self.plotter.render()

    def set_camera(self, preset: str, render: bool = True) -> None:
        """Front, profile or three-quarter view of the face, fitted to the markers."""
        if self.model is None:
            return
        self.preset = preset
        # articulators in a parallel projection: the midsagittal profile true to scale
        self.plotter.renderer.GetActiveCamera().SetParallelProjection(self.articulators)
        direction, up = CAMERA_PRESETS[preset]
        d = np.asarray(direction, float)
        d /= np.linalg.norm(d)
        # the articulators fitted with room for their motion, the reference sensors left out
        # (faint, far off: the nose bridge); a face fitted close
        fit = self.neutral[list(self.model.roles.moving)] if self.articulators else self.neutral
        margin = 10.0 if self.articulators else 5.0
        pts = [fit + self._offset, fit - self._offset]
        pts += [fit + self._pin_offset(i) for i in range(len(self.pins))]
        allp = np.concatenate(pts)
        centre = (allp.min(axis=0) + allp.max(axis=0)) / 2
        self.plotter.camera_position = [tuple(centre + 400 * d), tuple(centre), up]
        lo, hi = allp.min(axis=0) - margin, allp.max(axis=0) + margin
        self.plotter.renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
        self._fit = (allp, margin)
        if self.articulators:           # the view filled: the extent across and up the screen
            fit_parallel(self.plotter, allp, margin, (self.width(), self.height()))
        else:
            self.plotter.camera.zoom(1.45)
        if render:
            self.plotter.render()
        else:
            self.ahead = -1                     # a frame rendered ahead has the old camera

    def resizeEvent(self, event) -> None:
        """Articulators fill the resized view (their parallel projection fitted again)."""
        super().resizeEvent(event)
        if self.articulators and self._fit is not None:
            fit_parallel(self.plotter, *self._fit, (self.width(), self.height()))
            self.ahead = -1
            self.request_render()

    # ------------------------------------------------------------------ hover
    def _project(self, pts: np.ndarray) -> np.ndarray:
        """Display coordinates (pixels, origin bottom left) of world points."""
        ren = self.plotter.renderer
        cam = ren.GetActiveCamera()
        m = cam.GetCompositeProjectionTransformMatrix(ren.GetTiledAspectRatio(), -1, 1)
        mat = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
        h = np.c_[pts, np.ones(len(pts))] @ mat.T
        ndc = h[:, :2] / h[:, 3:4]
        w, hgt = ren.GetSize()
        ox, oy = ren.GetOrigin()
        return np.c_[ox + (ndc[:, 0] + 1) * w / 2, oy + (ndc[:, 1] + 1) * hgt / 2]

    def marker_at(self, x: float, y: float, radius: float = 9.0) -> str | None:
        """The marker under display position ``(x, y)`` (VTK pixels), as "NAME (set)"."""
        if self.model is None:
            return None
        best, label = radius, None
        pinned = [(self._pin_sets[p.color], True) for p in self.pins]
        for mset, visible in ((self.synth, self.show_synth), (self.original, self.show_original),
                              *pinned):
            if mset is None or not visible or not mset.actor.GetVisibility():
                continue
            d = np.linalg.norm(self._project(mset.current) - np.array([x, y]), axis=1)
            i = int(np.nanargmin(d))
            if d[i] < best:
                best, label = float(d[i]), f"{self.model.marker_names[i]} ({mset.name})"
        return label

    def _on_mouse_move(self, obj, event) -> None:
        try:
            x, y = self.plotter.iren.interactor.GetEventPosition()
            label = self.marker_at(x, y)
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
