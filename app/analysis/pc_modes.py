"""The principal component mode explorer (the paper's Figure 2).

Pick a PC and drag its coefficient over +-3 standard deviations (the slider's ends say which way
the mouth opens; the line under it gives the coefficient in mm and the lip aperture against the
talker's closure): the 3-D view shows the neutral face (grey), the displaced face (orange, its
lips closing where they meet, as in the main view) and displacement arrows; beside it the front projection
as in Figure 2 (circles: neutral, arrows: displacement) and the variance share of every PC.
"Animate" sweeps the mode back and forth. All shapes come from ``model.mode_shape``.

For articulograph sensors (``model.roles.articulograph``) the mode is shown as articulators move
(``app/articulators.py``): in 3-D the neutral articulators (grey) and the displaced ones (orange:
tongue curve, lips, jaw), seen in profile; in 2-D the midsagittal profile (z-y), where the tongue
shows, with the displaced articulators drawn at the arrows' scale and every sensor named.

The view opens at once and builds its 3-D scene and its plots in the passes of the event loop
that follow (``ready`` when done), so that the window does not freeze while it opens.
"""

from __future__ import annotations

import logging
import math
from functools import partial

import numpy as np
import pyvista as pv
from matplotlib.figure import Figure
from PyQt6.QtCore import Qt, QTimer, pyqtSignal
from PyQt6.QtWidgets import (
    QComboBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from facetraj_app.articulators import ArticulatorSet, ProfileDrawing, fit_parallel, is_articulograph
from facetraj_app.face_scene import MarkerSet
from facetraj_app.plotter_widget import make_plotter
from facetraj_app.style import BACKGROUND, SYNTH_COLOR
from facetraj_app.surface import Mouth, lip_contours, stored_face_triangles
from facetraj_engine.analysis.lips import closed_lips
from facetraj_engine.analysis.pc_modes import (
    describe_mode,
    mode_aperture,
    mode_displacement,
    mode_sd,
    opening_direction,
    variance_shares,
)
from facetraj_engine.method.model import Model

from ..workers import one_per_pass
from .common import Canvas, vertical_split

log = logging.getLogger(__name__)

SLIDER_STEPS = 100          # slider units per standard deviation
#: 3-D camera presets: direction from the face to the camera, view up (x right, y up, z forward)
CAMERAS = {
    "front": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "profile": ((-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    "three-quarter": ((-0.75, 0.18, 1.0), (0.0, 1.0, 0.0)),
}
#: 2-D projections (Figure 2): horizontal and vertical coordinate
PROJECTIONS = {"front (x-y)": (0, 1), "profile (z-y)": (2, 1)}
NEUTRAL_COLOR = "#8c8c8c"


def _fit_limits(ax, points: np.ndarray, axes2d: tuple[int, int]) -> None:
    """``ax``'s limits around ``points`` in the plane ``axes2d``, with 15 % of their extent to
    spare."""
    h, v = axes2d
    pad = 0.15 * np.ptp(points[:, [h, v]], axis=0).max()
    ax.set_xlim(points[:, h].min() - pad, points[:, h].max() + pad)
    ax.set_ylim(points[:, v].min() - pad, points[:, v].max() + pad)


class PCModeExplorer(QWidget):
    """Explore one PC at a time: slider over +-3 SD, 3-D view, Figure 2 projection, variance."""

    valueChanged = pyqtSignal(int, float)     # component, coefficient value (mm units of the PC)
    ready = pyqtSignal()

    def __init__(self, model: Model, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.model = model
        self.window_ = window
        self.sd = mode_sd(model)
        self.neutral = model.neutral_face()
        # the talker's lips at closure: the mouth shuts there (as in the main view) and the
        # readout says how far from it the lips are
        self.closed = getattr(window, "closed_lips", None) or closed_lips(model)
        self.closed_aperture = float(self.closed.gap(model.upper_lip, model.lower_lip))
        self.component = 0
        self.value = 0.0
        self._phase = 0.0
        self.articulators = is_articulograph(model)    # shown as articulators, in profile
        self.profile: ProfileDrawing | None = None      # the displaced articulators in 2-D
        rows = self._build_controls()

        self.plotter = None                  # made in the first pass after the view opens
        self.scene_box = QWidget()
        self.scene_box.setMinimumHeight(240)
        QVBoxLayout(self.scene_box).setContentsMargins(0, 0, 0, 0)
        self.canvas = Canvas(6, 3.4)
        self.canvas.setMinimumHeight(220)
        split = vertical_split(self.scene_box, self.canvas, (520, 340))
        lay = QVBoxLayout(self)
        lay.addLayout(rows[0])
        lay.addLayout(rows[1])
        lay.addWidget(self.value_label)
        lay.addWidget(self.description)
        lay.addLayout(rows[2])
        lay.addWidget(split, 1)

        self.timer = QTimer(self)
        self.timer.setInterval(40)
        self.timer.timeout.connect(self._tick)
        self.is_ready = False
        self.heads = None
        one_per_pass(self, [self._make_plotter, self._build_scene, self._build_guides,
                            lambda: self.canvas.rebuild(partial(self._build_plots,
                                                                axes2d=self._axes2d())),
                            lambda: self.set_component(0), self._set_ready])

    def _build_controls(self) -> tuple[QHBoxLayout, QHBoxLayout, QHBoxLayout]:
        """The rows of controls: component, slider, cameras and 2-D projection."""
        self.combo = QComboBox()
        for k, share in enumerate(self.model.pca.explained_ratio):
            self.combo.addItem(f"PC{k + 1}  ({100 * share:.1f} %)")
        self.combo.currentIndexChanged.connect(self.set_component)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(-3 * SLIDER_STEPS, 3 * SLIDER_STEPS)
        self.slider.setTickInterval(SLIDER_STEPS)
        self.slider.setTickPosition(QSlider.TickPosition.TicksBelow)
        self.slider.valueChanged.connect(self._slider_moved)
        self.slider.setMinimumWidth(220)
        self.value_label = QLabel()
        self.value_label.setWordWrap(True)
        self.animate_btn = QPushButton("Animate")
        self.animate_btn.setCheckable(True)
        self.animate_btn.toggled.connect(self.set_animating)
        reset = QPushButton("Reset")
        reset.clicked.connect(lambda: self.slider.setValue(0))
        self.description = QLabel()
        self.description.setWordWrap(True)
        self.projection = QComboBox()
        self.projection.addItems(list(PROJECTIONS))
        if self.articulators or self.model.is_planar:   # the midsagittal profile shows a tongue
            self.projection.setCurrentText("profile (z-y)")
        self.projection.setToolTip("the 2-D projection of Figure 2")
        self.projection.currentIndexChanged.connect(self._projection_changed)
        self.arrow_scale = QSpinBox()
        self.arrow_scale.setRange(1, 20)
        self.arrow_scale.setValue(1 if self.articulators else 3)   # articulators: true to scale
        self.arrow_scale.setPrefix("arrows x")
        self.arrow_scale.setToolTip("lengthen the 2-D arrows for legibility (the 3-D view is true to scale)")
        self.arrow_scale.valueChanged.connect(lambda _v: self.set_value(self.value, move_slider=False))
        # four short rows: the view fits a dock of 520 px (one row of everything pushed the
        # window past the screen and squeezed the slider to 19 px)
        component = QHBoxLayout()
        component.addWidget(QLabel("component:"))
        component.addWidget(self.combo, 1)
        component.addWidget(reset)
        component.addWidget(self.animate_btn)
        # the slider's ends say which way the mouth opens (the component's effect on the lip
        # aperture), the line under it the value with its unit and the aperture it gives
        self.minus_label, self.plus_label = QLabel("−3 SD"), QLabel("+3 SD")
        slider_row = QHBoxLayout()
        slider_row.addWidget(self.minus_label)
        slider_row.addWidget(self.slider, 1)
        slider_row.addWidget(self.plus_label)
        view_bar = QHBoxLayout()
        view_bar.addWidget(QLabel("3-D:"))
        for name in CAMERAS:
            b = QToolButton()
            b.setText({"three-quarter": "¾ view"}.get(name, name))
            b.setToolTip(f"3-D camera: {name}")
            b.clicked.connect(lambda _c=False, n=name: self.set_camera(n))
            view_bar.addWidget(b)
        view_bar.addStretch(1)
        view_bar.addWidget(QLabel("2-D:"))
        view_bar.addWidget(self.projection)
        view_bar.addWidget(self.arrow_scale)

        return component, slider_row, view_bar

    def _make_plotter(self) -> None:
        """The 3-D view (a native window on X11: the main window stays raster), in a pass of its
        own: creating its render window takes 60-120 ms."""
        self.plotter = make_plotter(self.scene_box)
        self.plotter.set_background(BACKGROUND)
        self.scene_box.layout().addWidget(self.plotter.interactor)

    def _set_ready(self) -> None:
        self.is_ready = True
        self.ready.emit()

    # ------------------------------------------------------------------ scene
    def _build_scene(self) -> None:
        """The displaced face: its points, lip contours and surface as the main view draws them
        (``MarkerSet``: opaque, under the points; a translucent one cost a transparency pass);
        articulograph sensors as articulators (``ArticulatorSet``)."""
        if self.articulators:
            self.face_set = ArticulatorSet(self.plotter, "displaced", SYNTH_COLOR, self.neutral,
                                           self.model.roles)
            self.displaced = self.face_set.points
            return
        contours = lip_contours(self.neutral, self.model.upper_lip, self.model.lower_lip,
                                list(self.model.lip_corners))
        try:
            tri = stored_face_triangles(self.neutral, contours)   # the main view made it
        except Exception:   # a degenerate marker layout: points and arrows only
            log.debug("no face surface for the PC explorer", exc_info=True)
            tri = None
        mouth = Mouth.between(self.neutral, contours, self.closed.markers)
        self.face_set = MarkerSet(self.plotter, "displaced", SYNTH_COLOR, self.neutral, contours, tri,
                                  mouth)
        self.displaced = self.face_set.points

    def _build_guides(self) -> None:
        """The neutral face's points (grey) and the displacement arrows; the camera."""
        n = len(self.neutral)
        self.neutral_poly = pv.PolyData(self.neutral.copy())
        self.neutral_poly.verts = np.column_stack([np.ones(n, int), np.arange(n)]).ravel()
        self.arrows = pv.PolyData(np.vstack([self.neutral, self.neutral]))
        self.arrows.lines = np.column_stack([np.full(n, 2), np.arange(n), np.arange(n) + n]).ravel()
        if self.articulators:           # the neutral articulators, grey
            ArticulatorSet(self.plotter, "neutral", NEUTRAL_COLOR, self.neutral, self.model.roles)
        else:
            self.plotter.add_mesh(self.neutral_poly, color=NEUTRAL_COLOR, point_size=11,
                                  render_points_as_spheres=True, style="points", name="neutral",
                                  pickable=False, reset_camera=False, render=False)
        self.plotter.add_mesh(self.arrows, color="#222222", line_width=2.5, name="arrows",
                              pickable=False, reset_camera=False, render=False)
        self.set_camera("profile" if self.articulators else "three-quarter", render=False)

    def set_camera(self, name: str, render: bool = True) -> None:
        """Look at the face from the ``front``, in ``profile`` or at ``three-quarter``."""
        if self.plotter is None:
            return
        direction, up = CAMERAS[name]
        self.plotter.renderer.GetActiveCamera().SetParallelProjection(self.articulators)
        pts = self._articulators() if self.articulators else self.neutral
        centre = pts.mean(axis=0)
        dist = 3.0 * float(np.ptp(pts, axis=0).max())
        d = np.asarray(direction, dtype=float)
        d /= np.linalg.norm(d)
        self.plotter.camera_position = [tuple(centre + dist * d), tuple(centre), up]
        if self.articulators:           # fitted to the articulators and their motion
            lo, hi = pts.min(axis=0) - 15.0, pts.max(axis=0) + 15.0
            self.plotter.renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
            fit_parallel(self.plotter, pts, 15.0, self._scene_size())
        else:
            self.plotter.renderer.reset_camera(render=False)
        if render:
            self.plotter.render()

    def _scene_size(self) -> tuple[int, int]:
        return self.scene_box.width(), self.scene_box.height()

    def resizeEvent(self, event) -> None:
        """Articulators fill the resized 3-D view (the parallel projection fitted again)."""
        super().resizeEvent(event)
        if self.articulators and self.plotter is not None:
            fit_parallel(self.plotter, self._articulators(), 15.0, self._scene_size())
            self.plotter.render()

    def _articulators(self) -> np.ndarray:
        """The neutral sensors on the articulators (the reference sensors, far off, left out)."""
        return self.neutral[list(self.model.roles.moving)]

    def _build_plots(self, fig: Figure, axes2d: tuple[int, int]) -> None:
        """The 2-D projection and the variance of each PC (built in the drawing thread:
        ``BackgroundCanvas.rebuild``; ``axes2d`` read from the projection box beforehand)."""
        fig.clear()
        # side by side under the 3-D view; constrained layout keeps every label inside at any size
        self.ax_face, self.ax_var = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.1, 1]})
        fig.set_layout_engine("constrained")
        share, cumulative = variance_shares(self.model)
        k = np.arange(1, len(share) + 1)
        self.bars = self.ax_var.bar(k, share, color="#9fb7d9")
        self.ax_var.plot(k, cumulative, color="#333333", lw=1, marker=".", ms=3,
                         label="cumulative")
        self.ax_var.set_xlabel("principal component", fontsize=8)
        self.ax_var.set_ylabel("variance explained (%)", fontsize=8)
        self.ax_var.set_ylim(0, 105)
        self.ax_var.set_title("variance of each PC", fontsize=9)
        self.ax_var.tick_params(labelsize=7)
        self.ax_var.legend(fontsize=7, loc="center right")
        self._draw_projection_base(None, axes2d)

    def _axes2d(self) -> tuple[int, int]:
        return PROJECTIONS[self.projection.currentText()]

    def _draw_projection_base(self, _fig: Figure | None, axes2d: tuple[int, int]) -> None:
        ax = self.ax_face
        ax.clear()
        h, v = axes2d
        ax.plot(self.neutral[:, h], self.neutral[:, v], "o", mfc="none", mec="#333333", ms=6)
        self.profile = None
        if self.articulators:           # neutral (grey, named) and displaced articulators
            ProfileDrawing(ax, self.model.roles, self.neutral, NEUTRAL_COLOR, axes2d,
                           label="neutral", names=True)
            self.profile = ProfileDrawing(ax, self.model.roles, self.neutral, SYNTH_COLOR, axes2d,
                                          label="displaced (at the arrows' scale)", lw=2.0)
        self.quiver = ax.quiver(self.neutral[:, h], self.neutral[:, v], np.zeros(len(self.neutral)),
                                np.zeros(len(self.neutral)), angles="xy", scale_units="xy", scale=1,
                                color=SYNTH_COLOR, width=0.006)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel(f"{'xyz'[h]} (mm)", fontsize=8)
        ax.set_ylabel(f"{'xyz'[v]} (mm)", fontsize=8)
        ax.tick_params(labelsize=7)
        _fit_limits(ax, self._articulators() if self.articulators else self.neutral, (h, v))

    def _projection_changed(self) -> None:
        if hasattr(self, "ax_face") or self.canvas.busy:
            self.canvas.rebuild(partial(self._draw_projection_base, axes2d=self._axes2d()))
            self.canvas.when_idle(self._update_plots)

    # ------------------------------------------------------------------ state
    def set_component(self, k: int) -> None:
        self.component = int(k)
        if self.combo.currentIndex() != k:
            self.combo.setCurrentIndex(k)
        self.description.setText(describe_mode(self.model, k).text())
        ends = mode_aperture(self.model, k, np.array([-3.0, 3.0]))
        way = opening_direction((float(ends[0]), float(ends[1])))
        self.minus_label.setText("−3 SD" + {1: " · closes", -1: " · opens", 0: ""}[way])
        self.plus_label.setText("+3 SD" + {1: " · opens", -1: " · closes", 0: ""}[way])
        self.slider.setToolTip(f"PC{k + 1}: the lip aperture goes from {ends[0]:.1f} mm at −3 SD to "
                               f"{ends[1]:.1f} mm at +3 SD (the lips meet at "
                               f"{self.closed_aperture:.1f} mm)")
        self.set_value(self.slider.value() / SLIDER_STEPS * self.sd[k], move_slider=False)

    def set_sd_units(self, sds: float) -> None:
        """Move the slider to ``sds`` standard deviations (clamped to +-3)."""
        self.slider.setValue(int(round(np.clip(sds, -3, 3) * SLIDER_STEPS)))

    def _slider_moved(self, pos: int) -> None:
        self.set_value(pos / SLIDER_STEPS * self.sd[self.component], move_slider=False)

    def set_value(self, value: float, move_slider: bool = True) -> None:
        """Set the coefficient of the current PC (in the PC's units) and redraw."""
        self.value = float(value)
        if move_slider:
            self.slider.blockSignals(True)
            self.slider.setValue(int(round(value / self.sd[self.component] * SLIDER_STEPS)))
            self.slider.blockSignals(False)
        self.value_label.setText(self.readout())
        if not hasattr(self, "arrows"):
            return                          # the scene is still being built (one_per_pass)
        shape = self.model.mode_shape(self.component, self.value)
        disp = mode_displacement(self.model, self.component, self.value)
        self.face_set.set_points(shape)
        n = len(shape)
        self.arrows.points[n:] = shape
        self.arrows.GetPoints().Modified()
        self._update_heads(shape, disp)
        self.plotter.render()
        self.canvas.when_idle(self._update_plots)
        self.valueChanged.emit(self.component, self.value)

    def readout(self) -> str:
        """The coefficient (a score on the PC: no unit of a marker's, so none shown) in SD, and
        the lip aperture it gives (mm), against closure."""
        k, sd = self.component, self.sd[self.component]
        gap = float(mode_aperture(self.model, k, np.array([self.value / sd]))[0])
        beyond = gap - self.closed_aperture
        state = ("lips closed" if beyond <= 0 else f"open {beyond:.1f} mm beyond closure")
        return (f"PC{k + 1} score {self.value:+.1f} ({self.value / sd:+.2f} SD) · lip aperture "
                f"{gap:.1f} mm: {state} (the lips meet at {self.closed_aperture:.1f} mm)")

    def _update_plots(self) -> None:
        """The 2-D projection's arrows and title and the highlighted variance bar for the current
        component and value (run when the canvas is not being drawn)."""
        if not hasattr(self, "quiver"):
            return
        k, sd = self.component, self.sd[self.component]
        for i, b in enumerate(self.bars):
            b.set_color(SYNTH_COLOR if i == k else "#9fb7d9")
        disp = mode_displacement(self.model, k, self.value)
        h, v = self._axes2d()
        scale = int(self.arrow_scale.value())
        self.quiver.set_UVC(scale * disp[:, h], scale * disp[:, v])
        if self.profile is not None:        # in view over the whole slider (+-3 SD)
            self.profile.set(self.neutral + scale * disp)
            ends = [self.neutral + scale * mode_displacement(self.model, k, e * sd) for e in (-3, 3)]
            moving = list(self.model.roles.moving)
            _fit_limits(self.ax_face, np.concatenate([e[moving] for e in (self.neutral, *ends)]),
                        (h, v))
        self.ax_face.set_title(f"PC{k + 1} = {self.value:+.1f} ({self.value / sd:+.1f} SD)"
                               + (f", arrows x{scale}" if scale != 1 else ""), fontsize=9)
        self.canvas.draw_idle()

    def _update_heads(self, shape: np.ndarray, disp: np.ndarray) -> None:
        length = np.linalg.norm(disp, axis=1)
        keep = length > max(1e-6, 0.05 * float(length.max(initial=0.0)))
        if not keep.any():
            if self.heads is not None:
                self.plotter.remove_actor(self.heads, render=False)
                self.heads = None
            return
        size = 0.02 * float(np.ptp(self.neutral, axis=0).max())
        pts = pv.PolyData(shape[keep])
        pts["v"] = disp[keep] / length[keep, None]
        glyphs = pts.glyph(orient="v", scale=False, factor=size,
                           geom=pv.Cone(center=(-0.5, 0, 0), direction=(1, 0, 0), radius=0.3,
                                        height=1.0, resolution=10))
        self.heads = self.plotter.add_mesh(glyphs, color="#222222", name="heads", pickable=False,
                                           render=False)

    def displaced_points(self) -> np.ndarray:
        """The displaced face as shown in the 3-D view, ``(M, 3)``."""
        return np.array(self.displaced.points)

    # ------------------------------------------------------------------ animation
    def set_animating(self, on: bool) -> None:
        if self.animate_btn.isChecked() != on:
            self.animate_btn.setChecked(on)
            return
        if on:
            self._phase = math.asin(float(np.clip(self.slider.value() / (3 * SLIDER_STEPS), -1, 1)))
            self.timer.start()
        else:
            self.timer.stop()

    def _tick(self) -> None:
        self._phase += 2 * math.pi / 50          # one sweep back and forth in 2 s
        self.set_sd_units(3 * math.sin(self._phase))

    def close_view(self) -> None:
        self.timer.stop()
        if self.plotter is None:
            return
        try:
            self.plotter.close()
        except Exception:
            log.debug("plotter close failed", exc_info=True)

    def closeEvent(self, event) -> None:
        self.close_view()
        super().closeEvent(event)
