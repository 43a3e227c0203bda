"""The 3-D scene of faces, without Qt: the original and the synthesized face points, their lip
contours and face surfaces (the lips to where they meet, ``app/surface.py``), the pinned
results' faces, side by side or overlaid, the camera presets and the close-up of the lips
(``lips``: the patch of each face around the mouth, front on, the faces in a grid that fills the
view). :class:`FaceScene` draws into any PyVista plotter: the window's 3-D view
(``app/view3d.py: FaceView``, a widget) and the video's off-screen one (``app/video.py``), so that
a video shows what the window shows (:meth:`FaceScene.options`, :meth:`FaceScene.camera_state`).
Each set is one ``vtkPoints`` shared by its markers, its lip contour lines and its surface, so a
frame update is a few small array copies and one render.

Articulograph sensors (``Model.roles.articulograph``) are drawn as articulators, not as a face
(``app/articulators.py: ArticulatorSet``: no surface): in a parallel projection fitted to the
moving sensors (the reference sensors left out) with room for their motion, the sets side by side
along the profile's front-back axis (:func:`~facetraj_app.articulators.gap_axis`), the palate
trace on the original set, and the close-up of the lips showing the lip sensors alone, in profile.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyvista as pv

from facetraj_engine.analysis.lips import ClosedLips, closed_lips
from facetraj_engine.method.model import Model

from .articulators import ArticulatorSet, fit_parallel, gap_axis, is_articulograph, lip_sensors
from .state import UtteranceView
from .style import CAVITY_COLOR, ORIGINAL_COLOR, SURFACE_COLOR, SYNTH_COLOR
from .surface import Mouth, lip_contours, mouth_region, stored_face_triangles

SURFACE_INSET_MM = 4.0
#: how far behind the lips the dark backing of the mouth opening lies
CAVITY_DEPTH_MM = 4.0

CAMERA_PRESETS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    # direction from the face to the camera (x to the talker's left, y up, z forward), view up
    "front": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "profile": ((-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    "three-quarter": ((-0.6, 0.12, 1.0), (0.0, 1.0, 0.0)),
    "lips": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),    # the close-up: the lips' patch, front on
}
#: the preset that shows each face's lips alone, large (its faces in a grid)
CLOSE_UP = "lips"
#: room (mm) around the articulators the camera is fitted to, for their motion; around their
#: lips in the close-up
ARTICULATOR_MARGIN_MM, LIPS_MARGIN_MM = 10.0, 8.0


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
    closes where the lips meet. ``keep``: the markers drawn (the close-up of the lips: their
    patch of the face; default all), the surface's triangles among them. Adding them renders
    nothing (the owner renders the finished scene once)."""

    def __init__(self, plotter: pv.BasePlotter, name: str, color: str, neutral: np.ndarray,
                 contours: list[list[int]], triangles: np.ndarray | None, mouth: Mouth | None = None,
                 keep: np.ndarray | None = None):
        self.name = name
        self.mouth = mouth if triangles is not None and len(triangles) else None
        keep = np.arange(len(neutral)) if keep is None else np.asarray(keep, int)
        if triangles is not None and len(keep) < len(neutral):
            triangles = triangles[np.isin(triangles, keep).all(axis=1)]
        self.points = pv.PolyData(neutral.copy())
        self.points.verts = np.column_stack([np.ones(len(keep), int), keep]).ravel()
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
        self._open = True

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
                self._show_opening(not self.mouth.shut(pts))
            self.surface.GetPoints().Modified()

    def _show_opening(self, is_open: bool) -> None:
        """The pouch dark behind an open mouth; skin-coloured when the lips meet all along, so
        that the sub-pixel seam between the two lips' edges shows no dark speck (a shut mouth
        read as a crack in the close-up)."""
        if is_open != self._open:
            self._open = is_open
            self.cavity_actor.GetProperty().SetColor(pv.Color(CAVITY_COLOR if is_open
                                                              else SURFACE_COLOR).float_rgb)

    def set_visible(self, visible: bool, surface: bool) -> None:
        self.actor.SetVisibility(visible)
        self.line_actor.SetVisibility(visible)
        if self.surface_actor is not None:
            self.surface_actor.SetVisibility(visible and surface)
        if self.mouth is not None:
            self.cavity_actor.SetVisibility(visible and surface)


def grid_columns(n: int, cell: tuple[float, float], aspect: float) -> int:
    """How many columns ``n`` cells of ``cell`` (width, height) are laid out in so that they are
    largest in a view of ``aspect`` (width / height).

    >>> grid_columns(1, (70, 50), 3.0), grid_columns(5, (70, 50), 7.0), grid_columns(5, (70, 50), 3.0)
    (1, 5, 3)
    """
    def scale(c: int) -> float:
        rows = -(-n // c)
        return min(aspect / (c * cell[0]), 1.0 / (rows * cell[1]))

    return max(range(1, max(n, 1) + 1), key=lambda c: (scale(c), -c))


def fit_camera(plotter, points: np.ndarray, direction, up, margin: float = 0.06) -> None:
    """Look at ``points`` from ``direction`` (from them to the camera) with ``up`` up, as close
    as shows them all in the view with ``margin`` around, whatever its aspect (a camera fitted
    to their bounding sphere left a row of faces a third of a short, wide view's height)."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    right = np.cross(np.asarray(up, float), d)
    right /= np.linalg.norm(right)
    upward = np.cross(d, right)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2
    rel = points - centre
    half_w, half_h = np.abs(rel @ right).max(), np.abs(rel @ upward).max()
    w, h = plotter.renderer.GetSize()
    aspect = w / max(h, 1) if w > 0 and h > 0 else 1.0
    cam = plotter.camera
    tan_half = np.tan(np.radians(cam.view_angle) / 2)
    distance = (1 + margin) * max(half_h, half_w / aspect) / tan_half + float((rel @ d).max())
    cam.focal_point = tuple(centre)
    cam.position = tuple(centre + distance * d)
    cam.up = tuple(upward)
    plotter.renderer.ResetCameraClippingRange()


@dataclass(frozen=True)
class SceneOptions:
    """What a scene shows beyond its data: faces side by side, the surface, which point sets,
    the camera preset (:data:`CAMERA_PRESETS`)."""

    side_by_side: bool = False
    show_surface: bool = True
    show_original: bool = True
    show_synth: bool = True
    preset: str = "three-quarter"


class FaceScene:
    """The faces of the utterance shown in a PyVista ``plotter``: the original and synthesized
    points (overlaid, or side by side), each pinned result's face beside them, every face with
    its surface and lips; ``show_frame(k)`` puts frame ``k`` on screen. The camera presets fit
    the faces; the close-up (``lips``) shows each face's lips alone, front on, in a grid."""

    def __init__(self, plotter: pv.BasePlotter | None = None, closed_mouth: bool = True):
        self.plotter = plotter
        self.closed_mouth = closed_mouth       # False: the lips' strips left out (the old surface)
        self.model: Model | None = None
        self.articulators = False               # the model's markers are articulograph sensors
        self.view: UtteranceView | None = None
        self.original: MarkerSet | ArticulatorSet | None = None
        self.synth: MarkerSet | ArticulatorSet | None = None
        self.side_by_side = False
        self.show_surface = True
        self.show_original = True
        self.show_synth = True
        self.frame = -1
        self.ahead = -1              # a frame rendered ahead, off screen (the window's view)
        self.preset = "three-quarter"
        self._orig = self._syn = None
        self._offset = np.zeros(3)              # the synthesized face's (the original: minus it)
        self.pins: list = []                    # the pinned results shown (app/pins.py: Pin)
        # by colour: made once per region, reused
        self._pin_sets: dict[str, MarkerSet | ArticulatorSet] = {}
        self._pin_frames: list[np.ndarray] = []
        self._pin_offsets: list[np.ndarray] = []
        self._keep: np.ndarray | None = None    # the markers drawn (None: all; the close-up's)
        # the close-up's grid laid out for another view's aspect (its camera's: set_camera_state)
        self._grid_aspect: float | None = None

    # ------------------------------------------------------------------ scene
    def set_model(self, model: Model, closed: ClosedLips | None = None) -> None:
        """Build the scene for ``model``'s marker set; ``closed``: the talker's lips at closure
        (``facetraj_engine.analysis.lips.closed_lips``, made here if not given), where the mouth shuts."""
        self.model = model
        self.articulators = is_articulograph(model)     # sensors drawn as articulators, no face
        # the previous model's view and pins are of its marker set, not this one's: forgotten
        # (the window shows this model's first utterance next)
        self.view, self._orig, self._syn = None, None, None
        self.pins, self._pin_frames, self._pin_offsets = [], [], []
        self.frame = self.ahead = -1
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
        self._across = gap_axis(model)          # the axis the faces are put apart along
        self._tri = self._mouth = None          # the faces' surface and lips (the pins' too)
        if self.articulators:
            self._lips = lip_sensors(model.roles)
        else:
            self._lips = mouth_region(neutral, self.contours)
            self._tri = stored_face_triangles(neutral, self.contours)
            closed = closed if closed is not None else closed_lips(model)
            if self.closed_mouth:
                self._mouth = Mouth.between(neutral, self.contours, closed.markers)
        self._build_sets(self._lips if self.preset == CLOSE_UP else None)
        # no VTK text (legend, caption): re-rasterizing text costs more than the whole scene on a
        # software renderer; the window shows the legend and the time in Qt widgets instead
        self.set_camera(self.preset, render=False)
        self.request_render()       # once: the meshes were added without a render each

    def _build_sets(self, keep: np.ndarray | None) -> None:
        """The synthesized and original face (and the pins', when asked for) with the markers
        ``keep`` (None: all), replacing those drawn (same actor names)."""
        self._keep = keep
        for old in self._pin_sets.values():         # made again for the new region when shown
            old.set_visible(False, False)
        self._pin_sets = {}
        self.synth = self._new_set("synthesized", SYNTH_COLOR)
        # the original markers have a surface too: shown when the synthesized ones are hidden
        self.original = self._new_set("original", ORIGINAL_COLOR)
        self._show_palate()
        drawn = self.neutral if keep is None else self.neutral[keep]
        width, height = float(np.ptp(drawn[:, self._across])), float(np.ptp(drawn[:, 1]))
        self._cell = (1.1 * width + 20.0, 1.1 * height + 20.0) if keep is None else \
            (1.15 * width + 6.0, 1.15 * height + 6.0)
        self._add_pin_sets()
        self._update_visibility()
        if self.frame >= 0:
            self.move_points(self.frame)

    def _new_set(self, name: str, color: str) -> MarkerSet | ArticulatorSet:
        """A marker set of the model in the scene, with the markers drawn now (``_keep``): a face
        (points, lip lines, surface) or, for articulograph sensors, the articulators."""
        if self.articulators:
            return ArticulatorSet(self.plotter, name, color, self.neutral, self.model.roles,
                                  self._keep)
        return MarkerSet(self.plotter, name, color, self.neutral, self.contours, self._tri,
                         self._mouth, self._keep)

    def _show_palate(self) -> None:
        """Articulators: the recording's palate trace on the original set, if it has one."""
        if self.articulators and self.original is not None:
            self.original.set_palate(None if self.view is None else self.view.original)

    @property
    def n_frames(self) -> int:
        """The frames of the view shown (0 without one)."""
        return 0 if self._syn is None else len(self._syn)

    def set_view(self, view: UtteranceView) -> None:
        self.view = view
        self._syn = _fill_nan(view.shown, self.neutral)
        self._orig = None if view.original is None else _fill_nan(view.original, self.neutral)
        self._show_palate()
        self._update_visibility()
        self.frame = -1

    def set_pins(self, pins: list) -> None:
        """Show ``pins`` (results kept to compare, ``app/pins.py``: each with its ``view`` and
        ``color``) beside the current face, each with its surface and lips, in its colour."""
        if self.synth is None:
            return
        refit = len(pins) != len(self.pins)         # the faces' row changed: the camera fits it
        self.pins = list(pins)
        self._pin_frames = [_fill_nan(p.view.shown, self.neutral) for p in self.pins]
        self._add_pin_sets()
        self._update_visibility()
        if self.frame >= 0:
            self.move_points(self.frame)
        if refit:
            self.set_camera(self.preset)
        else:
            self.request_render()

    def _add_pin_sets(self) -> None:
        """A face for each pin's colour not drawn yet (made once per region, reused)."""
        for pin in self.pins:
            if pin.color not in self._pin_sets:
                self._pin_sets[pin.color] = self._new_set(f"pin-{pin.color}", pin.color)
            self._pin_sets[pin.color].name = pin.name     # the hover's "UL_C (pin 1)"

    def _layout(self) -> None:
        """Where each face goes: the original (side by side), the synthesized one and each pin
        in a row, to the talker's left (articulators: to the front, the profile's right; the
        close-up: in the grid of columns that shows them largest in the view); the original
        overlaid on the synthesized one otherwise."""
        has_orig = self._orig is not None or self.view is None
        apart = self.side_by_side and has_orig
        n = 1 + int(apart) + len(self.pins)
        aspect = 1e9
        if self.preset == CLOSE_UP and self.plotter is not None:
            w, h = self.plotter.renderer.GetSize()
            aspect = self._grid_aspect or w / max(h, 1)
        columns = grid_columns(n, self._cell, aspect) if self.preset == CLOSE_UP else n
        across, up = np.eye(3)[self._across], np.eye(3)[1]
        cells = [(k % columns) * self._cell[0] * across - (k // columns) * self._cell[1] * up
                 for k in range(n)]
        # the original is drawn at minus the synthesized face's offset: overlaid, both at 0;
        # side by side, the pair centred
        centre = 0.5 * (cells[0] + cells[1]) if apart else cells[0]
        cells = [c - centre for c in cells]
        self._offset = cells[1] if apart else cells[0]
        self._pin_offsets = cells[1 + int(apart):]

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
        self._layout()

    def show_frame(self, k: int, render: bool = True) -> None:
        """Put frame ``k`` of the current view in the scene (the points move in place) and
        render it (:meth:`request_render`)."""
        if self._syn is None:
            return
        k = int(np.clip(k, 0, len(self._syn) - 1))
        self.move_points(k)
        self.frame = k
        if render:
            self.request_render()

    def move_points(self, k: int) -> None:
        """Every face to frame ``k`` (no render)."""
        self.synth.set_points(self._syn[k] + self._offset)
        if self._orig is not None:
            self.original.set_points(self._orig[min(k, len(self._orig) - 1)] - self._offset)
        for pin, frames, offset in zip(self.pins, self._pin_frames, self._pin_offsets, strict=True):
            self._pin_sets[pin.color].set_points(frames[min(k, len(frames) - 1)] + offset)

    def request_render(self) -> None:
        """Render the changed scene (the window's view renders at its next paint)."""
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

    def options(self) -> SceneOptions:
        """What the scene shows beyond its data (another scene shows the same with
        :meth:`set_options`)."""
        return SceneOptions(self.side_by_side, self.show_surface, self.show_original,
                            self.show_synth, self.preset)

    def set_options(self, options: SceneOptions) -> None:
        self.side_by_side, self.show_surface = options.side_by_side, options.show_surface
        self.show_original, self.show_synth = options.show_original, options.show_synth
        self._update_visibility()
        self.set_camera(options.preset, render=False)

    def set_camera(self, preset: str, render: bool = True) -> None:
        """Front, profile, three-quarter view of the faces or the close-up of their lips
        (:data:`CLOSE_UP`), fitted to the faces shown."""
        if self.model is None:
            return
        keep = self._lips if preset == CLOSE_UP else None
        self.preset = preset
        self._grid_aspect = None                # the grid fitted to this view
        if (keep is None) != (self._keep is None):
            self._build_sets(keep)
        self._layout()
        if self.frame >= 0:
            self.move_points(self.frame)
        drawn = self.neutral if self._keep is None else self.neutral[self._keep]
        if self.articulators and self._keep is None:    # the reference sensors, far off, left out
            drawn = self.neutral[list(self.model.roles.moving)]
        faces = [self._offset, -self._offset, *self._pin_offsets]
        points = np.concatenate([drawn + o for o in faces])
        # articulators in a parallel projection: the midsagittal profile true to scale
        self.plotter.camera.SetParallelProjection(self.articulators)
        if self.articulators:                  # their close-up in profile too (2-D data has no front)
            direction, up = CAMERA_PRESETS["profile" if preset == CLOSE_UP else preset]
            self._fit_articulators(points, direction, up)
        else:
            fit_camera(self.plotter, points, *CAMERA_PRESETS[preset])
        self._fitted = self._pose()
        if render:
            self.plotter.render()
        else:
            self.ahead = -1                     # a frame rendered ahead has the old camera

    def _fit_articulators(self, points: np.ndarray, direction, up) -> None:
        """Look at the articulators ``points`` from ``direction`` with ``up`` up, their parallel
        projection fitted to the view with room for their motion (``fit_parallel``)."""
        d = np.asarray(direction, float) / np.linalg.norm(direction)
        centre = (points.min(axis=0) + points.max(axis=0)) / 2
        self.plotter.camera_position = [tuple(centre + 400 * d), tuple(centre), up]
        margin = ARTICULATOR_MARGIN_MM if self._keep is None else LIPS_MARGIN_MM
        lo, hi = points.min(axis=0) - margin, points.max(axis=0) + margin
        self.plotter.renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
        fit_parallel(self.plotter, points, margin, self._view_size())

    def _view_size(self) -> tuple[int, int]:
        """The view's size in pixels (1 x 1 before it has one)."""
        w, h = self.plotter.renderer.GetSize()
        return (w, h) if w > 0 and h > 0 else (1, 1)

    def _pose(self) -> tuple:
        """Where the camera is and how it looks (the parallel projection's scale too: a zoom)."""
        state = self.camera_state()
        return (*state[:3], state[5])

    @property
    def camera_moved(self) -> bool:
        """Whether the camera moved (the user's drag or zoom) since the last preset fitted it."""
        return self._pose() != getattr(self, "_fitted", None)

    def camera_state(self) -> tuple:
        """The camera as it is (after the user's drags too): position, focal point, view up,
        view angle, the view's aspect (width / height) and the parallel projection's scale
        (None: a perspective; articulators are seen in a parallel projection)."""
        cam = self.plotter.camera
        w, h = self.plotter.renderer.GetSize()
        scale = float(cam.parallel_scale) if cam.GetParallelProjection() else None
        return (tuple(cam.position), tuple(cam.focal_point), tuple(cam.up), float(cam.view_angle),
                w / max(h, 1), scale)

    def set_camera_state(self, state: tuple) -> None:
        """The camera of another view (:meth:`camera_state`): in a view narrower than that one,
        the view angle (a parallel projection's scale) widened so that it shows at least the
        same width (and more height); the close-up's faces in that view's grid (the camera
        looks at them there)."""
        position, focal, up, angle, aspect, scale = state
        self._grid_aspect = aspect
        self._layout()
        if self.frame >= 0:
            self.move_points(self.frame)
        cam = self.plotter.camera
        cam.position, cam.focal_point, cam.up = position, focal, up
        w, h = self.plotter.renderer.GetSize()
        mine = w / max(h, 1)
        widen = max(aspect / mine, 1.0)
        if widen > 1.0:
            angle = float(np.degrees(2 * np.arctan(np.tan(np.radians(angle) / 2) * widen)))
        cam.view_angle = angle
        cam.SetParallelProjection(scale is not None)
        if scale is not None:
            cam.parallel_scale = scale * widen
        self.plotter.renderer.ResetCameraClippingRange()

    # ------------------------------------------------------------------ markers on screen
    def project(self, pts: np.ndarray) -> np.ndarray:
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

    def face_sets(self) -> list[tuple[MarkerSet | ArticulatorSet, bool]]:
        """Every face of the scene and whether it is shown: synthesized, original, the pins'."""
        if self.synth is None:
            return []
        return [(self.synth, self.show_synth), (self.original, self.show_original),
                *((self._pin_sets[p.color], True) for p in self.pins)]

    def marker_at(self, x: float, y: float, radius: float = 9.0) -> str | None:
        """The marker under display position ``(x, y)`` (VTK pixels), as "NAME (set)"."""
        if self.model is None:
            return None
        best, label = radius, None
        for mset, visible in self.face_sets():
            if not visible or not mset.actor.GetVisibility():
                continue
            drawn = self._keep if self._keep is not None else np.arange(len(mset.current))
            d = np.linalg.norm(self.project(mset.current[drawn]) - np.array([x, y]), axis=1)
            i = int(np.nanargmin(d))
            if d[i] < best:
                best, label = float(d[i]), f"{self.model.marker_names[drawn[i]]} ({mset.name})"
        return label


__all__ = ["CAMERA_PRESETS", "CLOSE_UP", "FaceScene", "MarkerSet", "SceneOptions", "grid_columns"]
