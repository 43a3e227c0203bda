"""Video export: the 3-D face (points and the app's face surface) beside the lip trajectories
and the phones, with the speech muxed in; one legend over both halves.

Rendering is off screen (``pyvista.Plotter(off_screen=True)`` and matplotlib's Agg canvas), so
it runs without a window; frames go to the ffmpeg binary shipped by ``imageio-ffmpeg`` as H.264
with AAC sound. The file is written under a temporary name and renamed into place.
"""

from __future__ import annotations

import logging
import os
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facetraj_engine.analysis.lips import closed_lips
from facetraj_engine.data import PhoneSegment, Utterance
from facetraj_engine.io.audio import write_audio
from facetraj_engine.io.files import atomic_write
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import Synthesis

from .style import BACKGROUND, CURSOR_COLOR, ORIGINAL_COLOR, SURFACE_COLOR, SYNTH_COLOR
from .surface import Mouth, face_triangles, lip_contours
from .view3d import CAMERA_PRESETS, MarkerSet

log = logging.getLogger(__name__)

HEADER_HEIGHT = 56          # px: the band over both halves with the title and the legend
PANEL_LEFT_PX = 76          # px left of the lip panels: their tick labels and two-line y labels
TIER_SHARE = 0.16           # of the lip panels' height: the phone tier under them


@dataclass(frozen=True)
class VideoSettings:
    """Video size and frame rate."""

    width: int = 1280
    height: int = 544
    fps: float = 30.0


Box = tuple[int, int, int, int]
"""A rectangle in frame pixels: ``(left, top, right, bottom)``, y down from the frame's top."""


@dataclass(frozen=True)
class VideoLayout:
    """Where things are in a frame (pixels, y down), for tests and for whoever composes frames."""

    width: int
    height: int
    scene: Box                  # the 3-D face
    legend: Box                 # the legend (explains both halves)
    title: Box | None           # the utterance's text (None without a title)
    lips: tuple[Box, Box]       # upper and lower lip y panels
    tier: Box                   # the phone tier under the lip panels
    phone_labels: tuple[Box, ...]   # each phone label drawn in the tier


def _box(bbox, fig_height: float, dx: int = 0, dy: int = 0) -> Box:
    """A matplotlib display bbox (y up) as a frame :data:`Box` (y down), shifted by (dx, dy)."""
    return (int(np.floor(bbox.x0)) + dx, int(np.floor(fig_height - bbox.y1)) + dy,
            int(np.ceil(bbox.x1)) + dx, int(np.ceil(fig_height - bbox.y0)) + dy)


def _header(width: int, height: int, title: str, original: bool, surface: bool):
    """The band over the frame: the utterance's text on the left, one legend on the right that
    explains both halves (the point colours of the 3-D face and the curves of the lip panels).
    Returns (RGB image, title box or None, legend box)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fig = Figure(figsize=(width / 100, height / 100), dpi=100, facecolor="white")
    canvas = FigureCanvasAgg(fig)
    handles = []
    if original:
        handles.append(Line2D([], [], color=ORIGINAL_COLOR, ls=":", lw=1.5, marker="o", ms=7,
                              label="original"))
    handles.append(Line2D([], [], color=SYNTH_COLOR, lw=1.5, marker="o", ms=7, label="synthesized"))
    if surface:
        handles.append(Patch(facecolor=SURFACE_COLOR, edgecolor="#9a7b62",
                             label="face surface (synthesized)"))
    legend = fig.legend(handles=handles, loc="center right", ncol=len(handles), fontsize=10,
                        frameon=True, borderaxespad=0.5, handlelength=2.6)
    canvas.draw()
    renderer = canvas.get_renderer()
    title_box = None
    if title:
        text = fig.text(0.01, 0.5, title, fontsize=11, va="center", ha="left")
        room = legend.get_window_extent(renderer).x0 - 0.02 * width
        if text.get_window_extent(renderer).width > room:
            # no room beside the legend: the title on a top row, the legend on a row under it
            legend.set_loc("lower right")
            legend.set_bbox_to_anchor((1.0, 0.0), transform=fig.transFigure)
            for item in legend.get_texts():
                item.set_fontsize(9)
            text.set_fontsize(10)
            text.set_y(0.75)
            room = 0.98 * width
            shown = title
            while text.get_window_extent(renderer).width > room and len(shown) > 4:
                shown = shown[:-2]
                text.set_text(shown.rstrip() + "…")
        canvas.draw()
        title_box = _box(text.get_window_extent(renderer), height)
    legend_box = _box(legend.get_window_extent(renderer), height)
    image = np.asarray(canvas.buffer_rgba())[:height, :width, :3].copy()
    return image, title_box, legend_box


class _LipPanels:
    """Upper and lower lip y with a phone tier under them, on an Agg canvas; a moving cursor is
    blitted over a background drawn once."""

    def __init__(self, model: Model, times: np.ndarray, synth: np.ndarray,
                 original: np.ndarray | None, phones: Sequence[PhoneSegment] | None,
                 width: int, height: int):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.width, self.height = width, height
        self.fig = Figure(figsize=(width / 100, height / 100), dpi=100, facecolor="white")
        self.canvas = FigureCanvasAgg(self.fig)
        grid = self.fig.add_gridspec(3, 1, height_ratios=[(1 - TIER_SHARE) / 2] * 2 + [TIER_SHARE],
                                     hspace=0.12, left=PANEL_LEFT_PX / width, right=0.97,
                                     top=0.97, bottom=44 / height)
        upper = self.fig.add_subplot(grid[0])
        lower = self.fig.add_subplot(grid[1], sharex=upper)
        tier = self.fig.add_subplot(grid[2], sharex=upper)
        self.axes = (upper, lower, tier)
        self.cursors = []
        for ax, idx, name in ((upper, model.upper_lip, "upper lip\ny (mm)"),
                              (lower, model.lower_lip, "lower lip\ny (mm)")):
            if original is not None:
                ax.plot(times, original[:, idx, 1], color=ORIGINAL_COLOR, lw=1.5, ls=":")
            ax.plot(times, synth[:, idx, 1], color=SYNTH_COLOR, lw=1.5)
            ax.set_ylabel(name, fontsize=9)
            ax.tick_params(labelsize=8, labelbottom=False)
            ax.grid(alpha=0.3)
        upper.set_xlim(times[0], times[-1])
        self.phone_texts = self._draw_tier(tier, phones or [], times)
        for ax in self.axes:
            self.cursors.append(ax.axvline(times[0], color=CURSOR_COLOR, lw=1.2, animated=True))
        self.canvas.draw()
        self._hide_crowded_labels()
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(self.fig.bbox)

    @staticmethod
    def _draw_tier(ax, phones: Sequence[PhoneSegment], times: np.ndarray) -> list:
        ax.set_yticks([])
        ax.set_ylim(0, 1)
        ax.set_ylabel("phones", fontsize=9, rotation=0, ha="right", va="center")
        ax.tick_params(labelsize=8)
        ax.set_xlabel("time (s)", fontsize=9)
        texts = []
        if not phones:
            texts.append(ax.text(0.5, 0.5, "no phone labels (acoustic-only synthesis)",
                                 transform=ax.transAxes, ha="center", va="center", fontsize=9,
                                 color="#555555"))
            return texts
        for k, seg in enumerate(phones):
            if seg.end <= times[0] or seg.start >= times[-1]:
                continue
            ax.axvspan(seg.start, seg.end, color="#e9ecef" if k % 2 else "#f8f9fa", lw=0)
            ax.axvline(seg.start, color="#adb5bd", lw=0.6)
            if seg.label != "sil":
                mid = (max(seg.start, times[0]) + min(seg.end, times[-1])) / 2
                texts.append(ax.text(mid, 0.5, seg.label, ha="center", va="center", fontsize=9,
                                     clip_on=True))
        return texts

    def _hide_crowded_labels(self) -> None:
        """A phone label wider than its segment, or overlapping the one before, is not drawn
        (short phones at a long file's scale): the tier shows no overlapping text."""
        renderer = self.canvas.get_renderer()
        tier_box = self.axes[2].get_window_extent(renderer)
        last_right = -np.inf
        for t in self.phone_texts:
            bb = t.get_window_extent(renderer)
            inside = bb.x0 >= tier_box.x0 and bb.x1 <= tier_box.x1
            if not inside or bb.x0 < last_right + 2:
                t.set_visible(False)
            else:
                last_right = bb.x1

    def boxes(self, dx: int, dy: int) -> tuple[tuple[Box, Box], Box, tuple[Box, ...]]:
        renderer = self.canvas.get_renderer()
        up, lo, tier = (_box(ax.get_window_extent(renderer), self.height, dx, dy) for ax in self.axes)
        labels = tuple(_box(t.get_window_extent(renderer), self.height, dx, dy)
                       for t in self.phone_texts if t.get_visible())
        return (up, lo), tier, labels

    def image(self, t: float) -> np.ndarray:
        self.canvas.restore_region(self.background)
        for c in self.cursors:
            c.set_xdata([t, t])
            c.axes.draw_artist(c)
        self.canvas.blit(self.fig.bbox)
        return np.asarray(self.canvas.buffer_rgba())[:self.height, :self.width, :3]


def _fit_camera(plotter, neutral: np.ndarray, planar: bool) -> None:
    """The three-quarter view of the app's 3-D view (a profile for midsagittal data), fitted."""
    direction, up = CAMERA_PRESETS["profile" if planar else "three-quarter"]
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    lo, hi = neutral.min(axis=0) - 5, neutral.max(axis=0) + 5
    centre = (lo + hi) / 2
    plotter.camera_position = [tuple(centre + 400 * d), tuple(centre), up]
    plotter.renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
    plotter.camera.zoom(1.3)


class VideoFrames:
    """The frames of a video: a header with the utterance's text and the legend, the 3-D face (the
    app's face surface under the synthesized points, the original points over it) on the left,
    and the lip panels with the phone tier on the right. ``frame(t)`` is the RGB image at time
    ``t``; ``layout`` says where each part is. Call ``close()`` when done."""

    def __init__(self, model: Model, synthesis: Synthesis, original: np.ndarray | None = None,
                 phones: Sequence[PhoneSegment] | None = None, settings: VideoSettings | None = None,
                 title: str = ""):
        import pyvista as pv

        settings = settings or VideoSettings()
        self.model, self.synthesis, self.original = model, synthesis, original
        width = settings.width - settings.width % 16
        height = settings.height - settings.height % 16
        if height < HEADER_HEIGHT + 240 or width < 640:
            raise ValueError(f"video size {settings.width}x{settings.height} is too small "
                             "(at least 640x304)")
        half = width // 2
        body = height - HEADER_HEIGHT
        self.size = (width, height)

        neutral = model.neutral_face()
        contours = lip_contours(neutral, model.upper_lip, model.lower_lip, list(model.lip_corners))
        triangles = face_triangles(neutral, contours)
        self.plotter = pv.Plotter(off_screen=True, window_size=(half, body))
        self.plotter.set_background(BACKGROUND)
        self.plotter.remove_all_lights()
        self.plotter.add_light(pv.Light(light_type="headlight", intensity=0.75))
        self.plotter.add_light(pv.Light(position=(0.4, 1.0, 0.6), light_type="camera light",
                                        intensity=0.35))
        mouth = Mouth.between(neutral, contours, closed_lips(model).markers)   # it shuts at /p b m/
        self.synth_set = MarkerSet(self.plotter, "synthesized", SYNTH_COLOR, neutral, contours,
                                   triangles, mouth)
        self.orig_set = None
        if original is not None:
            self.orig_set = MarkerSet(self.plotter, "original", ORIGINAL_COLOR, neutral, contours, None)
        _fit_camera(self.plotter, neutral, model.is_planar)

        header, title_box, legend_box = _header(width, HEADER_HEIGHT, title, original is not None,
                                                len(triangles) > 0)
        self.header = header
        self.panels = _LipPanels(model, synthesis.times, synthesis.markers, original, phones,
                                 width - half, body)
        lips, tier, labels = self.panels.boxes(half, HEADER_HEIGHT)
        self.layout = VideoLayout(width, height, (0, HEADER_HEIGHT, half, height), legend_box,
                                  title_box, lips, tier, labels)
        self._half = half

    def frame(self, t: float) -> np.ndarray:
        """The RGB frame ``(height, width, 3)`` at ``t`` seconds."""
        times = self.synthesis.times
        f = int(np.clip(round(t * self.model.marker_rate), 0, len(times) - 1))
        self.synth_set.set_points(self.synthesis.markers[f])
        if self.orig_set is not None:
            pts = self.original[min(f, len(self.original) - 1)]
            if np.isfinite(pts).all():       # a frame with a marker not seen keeps the last one
                self.orig_set.set_points(pts)
        self.plotter.render()
        body = self.size[1] - HEADER_HEIGHT
        left = np.asarray(self.plotter.screenshot(return_img=True))[:body, :self._half, :3]
        right = self.panels.image(t)
        return np.ascontiguousarray(
            np.concatenate([self.header, np.concatenate([left, right], axis=1)], axis=0))

    def close(self) -> None:
        self.plotter.close()


def render_video(model: Model, synthesis: Synthesis, audio: np.ndarray, sample_rate: int,
                 path: str | os.PathLike[str], original: np.ndarray | None = None,
                 settings: VideoSettings | None = None, overwrite: bool = False,
                 progress: Callable[[float, str], None] | None = None,
                 title: str = "", phones: Sequence[PhoneSegment] | None = None) -> Path:
    """Write an MP4 (H.264 + AAC) of the synthesized (and original) face points and lip panels.

    ``original`` is the head-normalised original ``(T, M, 3)`` or ``None``; ``phones`` the phone
    segments shown in the tier under the lip panels (none: the tier says so).
    """
    import imageio_ffmpeg

    settings = settings or VideoSettings()
    progress = progress or (lambda f, m: None)
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path}: already exists; choose to overwrite it (--overwrite) "
                              "or give another name")
    frames = VideoFrames(model, synthesis, original, phones, settings, title)
    n_video = int(np.floor(synthesis.times[-1] * settings.fps)) + 1
    try:
        with tempfile.TemporaryDirectory() as tmpdir:
            wav = Path(tmpdir) / "speech.wav"
            write_audio(wav, audio, sample_rate)
            with atomic_write(path, overwrite=True) as tmp:
                writer = imageio_ffmpeg.write_frames(
                    str(tmp), frames.size, fps=settings.fps, codec="libx264",
                    audio_path=str(wav), audio_codec="aac", macro_block_size=8,
                    output_params=["-shortest"])
                writer.send(None)
                try:
                    for k in range(n_video):
                        writer.send(frames.frame(k / settings.fps))
                        if k % 10 == 0:
                            progress(k / n_video, f"frame {k + 1} of {n_video}")
                finally:
                    writer.close()
    finally:
        frames.close()
    progress(1.0, "done")
    log.info("wrote %s (%d frames at %g fps)", path, n_video, settings.fps)
    return path


def video_for_utterance(model: Model, utt: Utterance, synthesis: Synthesis,
                        path: str | os.PathLike[str], **kwargs) -> Path:
    """:func:`render_video` for a corpus utterance, with its original markers when it has them."""
    original = model.normalise_markers(utt.markers) if utt.markers is not None else None
    return render_video(model, synthesis, utt.audio, utt.sample_rate, path, original=original,
                        title=utt.text or utt.name, phones=utt.phones, **kwargs)
