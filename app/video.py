"""Video export: the 3-D face (points and the app's face surface) beside the window's lip panels
and phones (``app/screen_export.py``: the same curves, closed lines, speech dots and pins), with
the speech muxed in; a caption naming the utterance, its labels and its settings, and one
legend over both halves.

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

from .articulators import ArticulatorSet, is_articulograph
from .style import BACKGROUND, CURSOR_COLOR, ORIGINAL_COLOR, SYNTH_COLOR
from .surface import Mouth, face_triangles, lip_contours
from .view3d import CAMERA_PRESETS, MarkerSet

log = logging.getLogger(__name__)

CAPTION_PT = 10.0           # the caption's size in the header band over both halves
#: the legend's look under it
HEADER_LEGEND = dict(fontsize=8.5, frameon=False, borderaxespad=0.0, borderpad=0.2,
                     handlelength=2.0, columnspacing=1.0, handletextpad=0.5)


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
    title: Box | None           # the caption (None without one)
    lips: tuple[Box, Box]       # upper and lower lip y panels
    tier: Box                   # the phone tier over the lip panels (as in the window)
    phone_labels: tuple[Box, ...]   # each phone label drawn in the tier


def _box(bbox, fig_height: float, dx: int = 0, dy: int = 0) -> Box:
    """A matplotlib display bbox (y up) as a frame :data:`Box` (y down), shifted by (dx, dy)."""
    return (int(np.floor(bbox.x0)) + dx, int(np.floor(fig_height - bbox.y1)) + dy,
            int(np.ceil(bbox.x1)) + dx, int(np.ceil(fig_height - bbox.y0)) + dy)


def _header(width: int, caption: str, entries) -> tuple[np.ndarray, Box | None, Box]:
    """The band over the frame: the caption (the utterance, its labels, how it was synthesized)
    wrapped on top, and under it one legend that explains both halves (the point colours of the
    3-D face and the curves of the lip panels) in as many columns as fit. Its height follows
    what it holds. Returns (RGB image, caption box or None, legend box)."""
    import textwrap

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .panel_layout import legend_handles
    from .screen_export import fitting_columns

    px = 100 / 72.0
    lines = textwrap.wrap(caption, max(20, int(width / (0.55 * CAPTION_PT * px)))) if caption else []
    caption_h = len(lines) * 1.3 * CAPTION_PT * px + (4 if lines else 0)
    ncol = fitting_columns(Figure(figsize=(width / 100, 1), dpi=100), entries, width - 12,
                           HEADER_LEGEND)
    rows = -(-len(entries) // ncol)
    height = int(np.ceil(8 + caption_h + rows * 1.45 * HEADER_LEGEND["fontsize"] * px + 6))
    height += height % 2
    fig = Figure(figsize=(width / 100, height / 100), dpi=100, facecolor="white")
    canvas = FigureCanvasAgg(fig)
    text = (fig.text(6 / width, 1 - 6 / height, "\n".join(lines), ha="left", va="top",
                     fontsize=CAPTION_PT, color="#222222") if lines else None)
    legend = fig.legend(handles=legend_handles(entries), ncol=ncol, loc="upper left",
                        bbox_to_anchor=(6 / width, 1 - (8 + caption_h) / height), **HEADER_LEGEND)
    canvas.draw()
    renderer = canvas.get_renderer()
    title_box = _box(text.get_window_extent(renderer), height) if text is not None else None
    legend_box = _box(legend.get_window_extent(renderer), height)
    image = np.asarray(canvas.buffer_rgba())[:height, :width, :3].copy()
    return image, title_box, legend_box


class _LipPanels:
    """The window's phone tier and upper and lower lip panels (``screen_export.panels_figure``:
    the same curves, closed lines, speech dots, phones and pins) on an Agg canvas; a moving
    cursor is blitted over a background drawn once."""

    def __init__(self, view, context, width: int, height: int):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        from .screen_export import main_panels, panels_figure

        self.width, self.height = width, height
        self.panels = main_panels(context)
        # a small frame's panels as small as they can be read (a 640 x 320 video keeps both lips)
        self.fig, self.layout = panels_figure(self.panels, view, (width, height), legend=False,
                                              min_scale=float(np.clip(height / 420, 0.45, 1.0)))
        self.canvas = FigureCanvasAgg(self.fig)
        self.cursors = [ax.axvline(view.times[0], color=CURSOR_COLOR, lw=1.2, animated=True)
                        for ax in self.layout.axes]
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(self.fig.bbox)

    def entries(self):
        """The legend entries of the panels' curves."""
        from .panel_layout import legend_entries

        return legend_entries(self.layout.axes)

    def boxes(self, dx: int, dy: int) -> tuple[tuple[Box, Box], Box, tuple[Box, ...]]:
        renderer = self.canvas.get_renderer()
        axes = dict(zip([p.title for p in self.layout.shown], self.layout.axes, strict=True))
        up, lo, tier = (_box(axes[name].get_window_extent(renderer), self.height, dx, dy)
                        for name in ("upper lip y", "lower lip y", "phones"))
        tier_panel = self.panels[0]
        labels = tuple(_box(extent, self.height, dx, dy) for fitted in tier_panel.labels[:1]
                       for _text, extent, _span in fitted.drawn)
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
    """The frames of a video: a header with the caption (the utterance, its labels, how it was
    synthesized) and one legend, the 3-D face (the app's face surface under the synthesized
    points, the original points over it) on the left, and on the right the window's phone tier
    and lip panels (the same curves, closed lines, speech dots and pinned results as on screen).
    ``frame(t)`` is the RGB image at time ``t``; ``layout`` says where each part is. Call
    ``close()`` when done.

    ``view``: the window's :class:`~facetraj_app.state.UtteranceView` (else made of
    ``synthesis``, ``audio`` and ``phones``); ``pins``: the window's
    :class:`~facetraj_app.pins.PinBoard`; ``caption``: else made of ``title`` and the settings."""

    def __init__(self, model: Model, synthesis: Synthesis, original: np.ndarray | None = None,
                 phones: Sequence[PhoneSegment] | None = None, settings: VideoSettings | None = None,
                 title: str = "", *, audio: np.ndarray | None = None, sample_rate: int = 16000,
                 view=None, pins=None, caption: str = ""):
        from .pins import PinBoard
        from .screen_export import PanelContext, caption_text, point_entries
        from .state import view_of_synthesis

        settings = settings or VideoSettings()
        view = view or view_of_synthesis(model, synthesis, audio, sample_rate, phones or (),
                                         original, text=title)
        self.model, self.view = model, view
        self.synthesis, self.original = view.synthesis, view.original
        width = settings.width - settings.width % 16
        height = settings.height - settings.height % 16
        context = PanelContext(model, closed_lips(model), pins if pins is not None else PinBoard())
        caption = caption or caption_text(view, heading=title or "")
        if width < 640:
            raise ValueError(f"video size {settings.width}x{settings.height} is too small "
                             "(at least 640x304)")
        half = width // 2
        self._half = half
        self._scene(model, half, view.original is not None)
        entries = point_entries(view.original is not None)
        header_h = _header(width, caption, entries)[0].shape[0]        # the panels' entries below
        body = height - header_h
        if body < 240:
            raise ValueError(f"video size {settings.width}x{settings.height} is too small "
                             "(at least 640x304)")
        self.panels = _LipPanels(view, context, width - half, body)
        header, title_box, legend_box = _header(width, caption, entries + self.panels.entries())
        if header.shape[0] != header_h:            # more legend rows: the panels a little lower
            body = height - header.shape[0]
            self.panels = _LipPanels(view, context, width - half, body)
        self.header, self.size, self._body = header, (width, height), body
        self.plotter.window_size = (half, body)
        lips, tier, labels = self.panels.boxes(half, header.shape[0])
        self.layout = VideoLayout(width, height, (0, header.shape[0], half, height), legend_box,
                                  title_box, lips, tier, labels)

    def _scene(self, model: Model, half: int, original: bool) -> None:
        """The off-screen 3-D scene: the synthesized face with its surface, mouth and lip
        contours, and the original points over it."""
        import pyvista as pv

        neutral = model.neutral_face()
        self.plotter = pv.Plotter(off_screen=True, window_size=(half, 300))
        self.plotter.set_background(BACKGROUND)
        self.plotter.remove_all_lights()
        self.plotter.add_light(pv.Light(light_type="headlight", intensity=0.75))
        self.plotter.add_light(pv.Light(position=(0.4, 1.0, 0.6), light_type="camera light",
                                        intensity=0.35))
        if is_articulograph(model):      # articulators in profile, as the window draws them
            self.synth_set = ArticulatorSet(self.plotter, "synthesized", SYNTH_COLOR, neutral, model.roles)
            self.orig_set = (ArticulatorSet(self.plotter, "original", ORIGINAL_COLOR, neutral, model.roles)
                             if original else None)
            self.plotter.enable_parallel_projection()
            _fit_camera(self.plotter, neutral[list(model.roles.moving)], True)
            return
        contours = lip_contours(neutral, model.upper_lip, model.lower_lip, list(model.lip_corners))
        triangles = face_triangles(neutral, contours)
        mouth = Mouth.between(neutral, contours, closed_lips(model).markers)   # it shuts at /p b m/
        self.synth_set = MarkerSet(self.plotter, "synthesized", SYNTH_COLOR, neutral, contours,
                                   triangles, mouth)
        self.orig_set = None
        if original:
            self.orig_set = MarkerSet(self.plotter, "original", ORIGINAL_COLOR, neutral, contours, None)
        _fit_camera(self.plotter, neutral, model.is_planar)

    def frame(self, t: float) -> np.ndarray:
        """The RGB frame ``(height, width, 3)`` at ``t`` seconds."""
        times = self.synthesis.times
        f = int(np.clip(round(t * self.model.marker_rate), 0, len(times) - 1))
        self.synth_set.set_points(self.view.shown[f])
        if self.orig_set is not None:
            pts = self.original[min(f, len(self.original) - 1)]
            if np.isfinite(pts).all():       # a frame with a marker not seen keeps the last one
                self.orig_set.set_points(pts)
        self.plotter.render()
        left = np.asarray(self.plotter.screenshot(return_img=True))[:self._body, :self._half, :3]
        right = self.panels.image(t)
        return np.ascontiguousarray(
            np.concatenate([self.header, np.concatenate([left, right], axis=1)], axis=0))

    def close(self) -> None:
        self.plotter.close()


def render_video(model: Model, synthesis: Synthesis, audio: np.ndarray, sample_rate: int,
                 path: str | os.PathLike[str], original: np.ndarray | None = None,
                 settings: VideoSettings | None = None, overwrite: bool = False,
                 progress: Callable[[float, str], None] | None = None,
                 title: str = "", phones: Sequence[PhoneSegment] | None = None,
                 view=None, pins=None, caption: str = "") -> Path:
    """Write an MP4 (H.264 + AAC) of the synthesized (and original) face points and lip panels.

    ``original`` is the head-normalised original ``(T, M, 3)`` or ``None``; ``phones`` the phone
    segments shown in the tier over the lip panels (none: the tier says so). From the window:
    its ``view``, ``pins`` and ``caption`` (what is on screen; :class:`VideoFrames`).
    """
    import imageio_ffmpeg

    settings = settings or VideoSettings()
    progress = progress or (lambda f, m: None)
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path}: already exists; choose to overwrite it (--overwrite) "
                              "or give another name")
    frames = VideoFrames(model, synthesis, original, phones, settings, title, audio=audio,
                         sample_rate=sample_rate, view=view, pins=pins, caption=caption)
    n_video = int(np.floor(synthesis.times[-1] * settings.fps)) + 1
    try:
        with tempfile.TemporaryDirectory() as tmpdir:
            wav = Path(tmpdir) / "speech.wav"
            write_audio(wav, *sound_for_frames(audio, sample_rate, n_video, settings.fps))
            with atomic_write(path, overwrite=True) as tmp:
                # the sound exactly as long as the frames, and both cut there: every frame kept
                # (``-shortest`` dropped the last, the AAC stream ending a few ms early)
                writer = imageio_ffmpeg.write_frames(
                    str(tmp), frames.size, fps=settings.fps, codec="libx264",
                    audio_path=str(wav), audio_codec="aac", macro_block_size=8,
                    ffmpeg_log_level="error", output_params=["-t", f"{n_video / settings.fps:.6f}"])
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


#: the sound's rate in the video: AAC's frames of 1024 samples are 21 ms, under a video frame
VIDEO_AUDIO_RATE = 48000


def sound_for_frames(audio: np.ndarray, sample_rate: int, n_frames: int, fps: float
                     ) -> tuple[np.ndarray, int]:
    """The speech as long as ``n_frames`` video frames at ``fps`` (cut, or silence after it), at
    :data:`VIDEO_AUDIO_RATE`, peak-limited to full scale, and its rate.

    >>> x, rate = sound_for_frames(np.ones(16000), 16000, 30, 30.0)
    >>> len(x), rate
    (48000, 48000)
    """
    from facetraj_engine.level import peak
    from facetraj_engine.method.lsf import resample_audio

    x = resample_audio(audio, sample_rate, VIDEO_AUDIO_RATE)
    top = peak(x)
    if top > 1.0:                                   # over full scale: lowered, not clipped
        x = x / top
    n = int(round(n_frames / fps * VIDEO_AUDIO_RATE))
    return np.concatenate([x[:n], np.zeros(max(0, n - len(x)))]), VIDEO_AUDIO_RATE


def video_for_utterance(model: Model, utt: Utterance, synthesis: Synthesis,
                        path: str | os.PathLike[str], **kwargs) -> Path:
    """:func:`render_video` for a corpus utterance, with its original markers when it has them."""
    original = model.normalise_markers(utt.markers) if utt.markers is not None else None
    return render_video(model, synthesis, utt.audio, utt.sample_rate, path, original=original,
                        title=utt.text or utt.name, phones=utt.phones, **kwargs)
