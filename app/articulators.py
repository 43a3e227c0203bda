"""The articulator view: articulograph sensors drawn as articulators, not as a face.

For a marker set that is articulograph sensors (``Model.roles.articulograph``: a tongue among
them, :mod:`facetraj_engine.io.sensor_roles`) the 3-D view shows, per marker set (original,
synthesized, each pin) in its colour, as VisArtico and MVIEW draw such data:

* the **tongue** as a smooth curve through its sensors, tip to rear
  (:func:`facetraj_engine.analysis.articulators.tongue_curve`), the sensors on it;
* the **lips** as points with the **aperture** between them (a thin line upper to lower lip) and
  the lip corners joined to both lips;
* the **jaw** sensors, joined when there are two (HPRC's JAW and JAWL);
* the velum and other sensors as points; the head-correction's **reference** sensors small and
  grey; a **palate** trace (a sensor named PAL or PALATE) as the line of every position it took
  in the recording (the original's);
* no face surface.

The window looks at it in profile (the midsagittal plane: front to the right, up up) with a
parallel projection, so that 2-D (midsagittal) data is drawn true to scale; 3-D data can be turned
with the other cameras; the close-up of the lips shows the lip sensors alone (:func:`lip_sensors`),
in profile. :class:`ArticulatorSet` has :class:`facetraj_app.face_scene.MarkerSet`'s interface
(``set_points``, ``set_visible``, ``current``, ``actor``, ``name``, ``keep``), so that
``app/face_scene.py: FaceScene`` draws them in the window and in the video with playback, pins,
side by side, the close-up and hover unchanged.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from facetraj_engine.analysis.articulators import CURVE_STEPS, tongue_curve
from facetraj_engine.io.sensor_roles import SensorRoles
from facetraj_engine.method.model import Model

#: the reference sensors' colour: faint, the same for every set
REFERENCE_COLOR = "#a0a8b0"
#: the palate trace's colour
PALATE_COLOR = "#6e6e6e"
TONGUE_WIDTH = 7.0
POINT_SIZE = 13.0


def is_articulograph(model: Model | None) -> bool:
    """Whether ``model``'s markers are articulograph sensors (drawn as articulators)."""
    return model is not None and model.roles.articulograph


def dimensions_note(model: Model) -> str:
    """The status bar's note on how the markers are shown ("" for a 3-D face)."""
    if model.roles.articulograph:
        roles = model.roles
        tongue = " ".join(roles.names[i] for i in roles.tongue)
        what = "midsagittal (2-D)" if model.is_planar else "3-D"
        return f"{what} articulograph: articulator view in profile (tongue {tongue} tip to rear)"
    if model.is_planar:
        return "midsagittal (2-D) data: profile view, y up, z forward"
    return ""


def _lines(segments: list[list[int]]) -> np.ndarray:
    return np.concatenate([[len(s), *s] for s in segments]) if segments else np.zeros(0, int)


def link_segments(roles: SensorRoles) -> list[list[int]]:
    """The thin lines between sensors: the aperture (upper to lower lip), each lip corner to both
    lips, the jaw sensors joined."""
    segs = [[roles.upper_lip, roles.lower_lip]]
    segs += [[roles.upper_lip, c, roles.lower_lip] for c in roles.lip_corners]
    if len(roles.jaw) > 1:
        segs.append(list(roles.jaw))
    return segs


def lip_sensors(roles: SensorRoles) -> np.ndarray:
    """The lips' sensors (indices): the upper and lower lip and the lip corners (the close-up of
    the lips draws them alone)."""
    return np.array(sorted({roles.upper_lip, roles.lower_lip, *roles.lip_corners}), dtype=int)


def _verts(indices) -> np.ndarray:
    return np.column_stack([np.ones(len(indices), int), np.asarray(indices, int)]).ravel()


class ArticulatorSet:
    """One set of articulograph sensors in a scene (see the module docstring): points, the tongue
    curve, the lip and jaw lines, the faint reference sensors; ``keep``: the sensors drawn (the
    close-up of the lips: :func:`lip_sensors`; default all), a line only where all its sensors
    are; adding it renders nothing."""

    def __init__(self, plotter: pv.BasePlotter, name: str, color: str, neutral: np.ndarray,
                 roles: SensorRoles, keep: np.ndarray | None = None):
        self.name = name
        self.roles = roles
        self.n_markers = len(neutral)
        self.current = np.array(neutral, dtype=np.float64)
        kept = set(range(len(neutral))) if keep is None else {int(i) for i in keep}
        faint = set(roles.reference) | set(roles.palate)
        self.points = pv.PolyData(self.current.copy())
        self.points.verts = _verts([i for i in sorted(kept) if i not in faint])
        common = dict(reset_camera=False, pickable=False, render=False)
        self.actor = plotter.add_mesh(self.points, color=color, render_points_as_spheres=True,
                                      point_size=POINT_SIZE, style="points", name=f"{name}-points",
                                      ambient=0.3, diffuse=0.8, specular=0.0, **common)
        self.reference = pv.PolyData()
        self.reference.SetPoints(self.points.GetPoints())
        self.reference.verts = _verts(sorted(set(roles.reference) & kept))
        self.reference_actor = plotter.add_mesh(self.reference, color=REFERENCE_COLOR, style="points",
                                                point_size=6, render_points_as_spheres=True,
                                                name=f"{name}-reference", **common)
        self.links = pv.PolyData()
        self.links.SetPoints(self.points.GetPoints())
        self.links.lines = _lines([seg for seg in link_segments(roles) if set(seg) <= kept])
        self.link_actor = plotter.add_mesh(self.links, color=color, line_width=2.0,
                                           name=f"{name}-links", **common)
        self.tongue = pv.PolyData(tongue_curve(self.current[list(roles.tongue)]))
        n = len(self.tongue.points)
        self.tongue.lines = _lines([list(range(n))] if n > 1 else [])
        self.tongue_actor = plotter.add_mesh(self.tongue, color=color, line_width=TONGUE_WIDTH,
                                             render_lines_as_tubes=True, name=f"{name}-tongue",
                                             ambient=0.35, diffuse=0.7, specular=0.0, **common)
        tongue_kept = set(roles.tongue) <= kept     # else no curve (its points neither)
        self.palate = pv.PolyData()
        self.palate_actor = plotter.add_mesh(pv.PolyData(np.zeros((1, 3))), color=PALATE_COLOR,
                                             line_width=3.0, name=f"{name}-palate", **common)
        self.palate_actor.SetVisibility(False)
        self.has_palate = False
        self._palate_kept = set(roles.palate) <= kept
        self._actors = [self.actor, self.reference_actor, self.link_actor,
                        *([self.tongue_actor] if tongue_kept else [])]
        self.tongue_actor.SetVisibility(tongue_kept)

    def tongue_points(self) -> np.ndarray:
        """The tongue curve as drawn, ``(n, 3)``."""
        return np.array(self.tongue.points)

    def set_points(self, pts: np.ndarray) -> None:
        """Move the sensors, the tongue curve and the lines to ``pts`` ``(M, 3)``, in place."""
        self.current = pts
        np.copyto(self.points.points, pts)
        self.points.GetPoints().Modified()
        if self.roles.tongue:
            self.tongue.points[:] = tongue_curve(pts[list(self.roles.tongue)], CURVE_STEPS)
            self.tongue.GetPoints().Modified()

    def set_palate(self, frames: np.ndarray | None) -> None:
        """Draw the palate trace: every position the palate sensor took in ``frames``
        ``(T, M, 3)``, front to back (None, or no palate sensor: none)."""
        trace = np.zeros((0, 3))
        if frames is not None and self.roles.palate and self._palate_kept:
            trace = np.asarray(frames, dtype=np.float64)[:, self.roles.palate[0]]
            trace = trace[np.isfinite(trace).all(axis=1)]
        self.has_palate = len(trace) >= 2
        if self.has_palate:
            trace = trace[np.argsort(-trace[:, 2])]             # z forward: front first
            line = pv.PolyData(trace)
            line.lines = _lines([list(range(len(trace)))])
            self.palate_actor.GetMapper().SetInputData(line)
        self.palate_actor.SetVisibility(self.has_palate and self.actor.GetVisibility())

    def set_visible(self, visible: bool, surface: bool = False) -> None:
        """Show or hide the set (there is no surface: ``surface`` is ignored)."""
        for actor in self._actors:
            actor.SetVisibility(visible)
        self.palate_actor.SetVisibility(visible and self.has_palate)


def fit_parallel(plotter: pv.BasePlotter, points: np.ndarray, margin: float,
                 size: tuple[int, int]) -> None:
    """Fit the parallel projection of ``plotter``'s camera (its direction and view up kept) to
    ``points`` with ``margin`` (mm) to spare, on a view of ``size`` (width, height, px): the
    articulators fill the view whatever its shape (call it again when the view is resized)."""
    cam = plotter.camera
    up = np.asarray(cam.up, dtype=np.float64)
    right = np.cross(np.asarray(cam.direction, dtype=np.float64), up)
    across = np.ptp(points @ right) + 2 * margin
    height = np.ptp(points @ up) + 2 * margin
    cam.parallel_scale = float(max(height / 2, across / (2 * max(size[0] / max(size[1], 1), 1e-3))))


def gap_axis(model: Model) -> int:
    """The axis along which side-by-side sets are put apart: z (front-back) for articulators
    seen in profile, x for a face seen from the front."""
    return 2 if model.roles.articulograph else 0




class ProfileDrawing:
    """Articulators drawn on a matplotlib axes ``ax`` in the plane of coordinates ``axes2d``
    (horizontal, vertical; (2, 1): the midsagittal profile, z forward and y up), as the 3-D view
    draws them: the tongue curve, the sensors, the aperture and lip-corner lines, the jaw line, the
    reference sensors faint. ``set(points)`` moves it; ``names``: each sensor named beside it."""

    def __init__(self, ax, roles: SensorRoles, points: np.ndarray, color: str,
                 axes2d: tuple[int, int] = (2, 1), label: str = "", names: bool = False,
                 lw: float = 2.5):
        self.ax, self.roles, self.axes2d = ax, roles, axes2d
        faint = set(roles.reference) | set(roles.palate)
        self.moving = [i for i in range(len(roles.names)) if i not in faint]
        (self.tongue,) = ax.plot([], [], color=color, lw=lw, solid_capstyle="round", label=label)
        (self.points,) = ax.plot([], [], "o", color=color, ms=5)
        (self.links,) = ax.plot([], [], color=color, lw=0.9)
        (self.reference,) = ax.plot([], [], "o", color=REFERENCE_COLOR, ms=3)
        self.set(points)
        if names:
            h, v = axes2d
            for i in self.moving:
                ax.annotate(roles.names[i], (points[i, h], points[i, v]), xytext=(4, 4),
                            textcoords="offset points", fontsize=7, color="#333333")

    def set(self, points: np.ndarray) -> None:
        """Draw the articulators at ``points`` ``(M, 3)``."""
        h, v = self.axes2d
        r = self.roles
        curve = tongue_curve(points[list(r.tongue)]) if r.tongue else np.zeros((0, 3))
        self.tongue.set_data(curve[:, h], curve[:, v])
        self.points.set_data(points[self.moving, h], points[self.moving, v])
        xs, ys = [], []
        for seg in link_segments(r):                          # one line, broken by NaN between the segments
            xs += [*points[seg, h], np.nan]
            ys += [*points[seg, v], np.nan]
        self.links.set_data(xs, ys)
        ref = list(r.reference)
        self.reference.set_data(points[ref, h], points[ref, v])


__all__ = [
    "ArticulatorSet",
    "ProfileDrawing",
    "dimensions_note",
    "fit_parallel",
    "gap_axis",
    "is_articulograph",
    "lip_sensors",
]
