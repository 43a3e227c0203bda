"""Video export: the 3-D faces (``app/face_scene.py``: the window's scene, its camera, side by
side or overlaid, the pinned faces, the close-up of the lips) beside the window's panels
(``app/screen_export.py``: the same curves, closed lines, speech dots, phones, pins and every
panel shown, over the time range shown), with the speech of that range muxed in; a caption
naming the utterance, its labels and its settings, and one legend over both halves. From the
window (*File → Export a video…*) a video is what the screen shows; ``facetraj video`` makes the
window's default view of an utterance.

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

from .articulators import is_articulograph
from .face_scene import FaceScene, SceneOptions
from .style import BACKGROUND, CURSOR_COLOR

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
    panels: tuple[str, ...] = ()    # the panels drawn, top down (their titles)
    span: tuple[float, float] = (0.0, 0.0)     # the time range of the frames (s)


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


class _Panels:
    """The window's panels (``panels``: by default its phone tier and upper and lower lip;
    ``screen_export.panels_figure``: the same curves, closed lines, speech dots, phones and pins)
    over the time range ``xlim`` on an Agg canvas; a moving cursor is blitted over a background
    drawn once."""

    def __init__(self, view, panels: list, width: int, height: int,
                 xlim: tuple[float, float] | None = None):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        from .panel_layout import min_scale_to_fit, panel_min_px
        from .screen_export import panels_figure
        from .timeline import BOTTOM_MARGIN_PX, TOP_MARGIN_PX

        self.width, self.height = width, height
        self.panels = panels
        # a small frame's panels as small as they can be read (a 640 x 320 video keeps both
        # lips), and every panel the window shows kept, a little lower, where they can be
        floor = float(np.clip(height / 420, 0.45, 1.0))
        scale = min_scale_to_fit([panel_min_px(p) for p in panels],
                                 height - TOP_MARGIN_PX - BOTTOM_MARGIN_PX, min(floor, 0.6))
        self.fig, self.layout = panels_figure(self.panels, view, (width, height), legend=False,
                                              xlim=xlim, min_scale=min(floor, scale))
        self.canvas = FigureCanvasAgg(self.fig)
        self.cursors = [ax.axvline(view.times[0], color=CURSOR_COLOR, lw=1.2, animated=True)
                        for ax in self.layout.axes]
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(self.fig.bbox)

    def entries(self):
        """The legend entries of the panels' curves."""
        from .panel_layout import legend_entries

        return legend_entries(self.layout.axes)

    def titles(self) -> tuple[str, ...]:
        return tuple(p.title for p in self.layout.shown)

    def boxes(self, dx: int, dy: int) -> tuple[tuple[Box, Box], Box, tuple[Box, ...]]:
        renderer = self.canvas.get_renderer()
        axes = dict(zip(self.titles(), self.layout.axes, strict=True))
        up, lo, tier = (_box(axes[name].get_window_extent(renderer), self.height, dx, dy)
                        if name in axes else (0, 0, 0, 0)
                        for name in ("upper lip y", "lower lip y", "phones"))
        tier_panel = next((p for p in self.layout.shown if p.title == "phones"), None)
        labels = tuple(_box(extent, self.height, dx, dy) for fitted in
                       (tier_panel.labels[:1] if tier_panel is not None else [])
                       for _text, extent, _span in fitted.drawn)
        return (up, lo), tier, labels

    def image(self, t: float) -> np.ndarray:
        self.canvas.restore_region(self.background)
        for c in self.cursors:
            c.set_xdata([t, t])
            c.axes.draw_artist(c)
        self.canvas.blit(self.fig.bbox)
        return np.asarray(self.canvas.buffer_rgba())[:self.height, :self.width, :3]


@dataclass(frozen=True)
class Screen:
    """What the window shows, for a video of it: its panels (copies of those shown), its 3-D
    scene's options and camera (``FaceScene.options``, ``camera_state``) and the time range
    shown (s)."""

    panels: tuple = ()
    options: SceneOptions | None = None
    camera: tuple | None = None
    span: tuple[float, float] | None = None


class VideoFrames:
    """The frames of a video: a header with the caption (the utterance, its labels, how it was
    synthesized) and one legend, the 3-D faces on the left (``app/face_scene.py``: the app's face
    surface under the synthesized points, the original points over it, and the pinned faces;
    with ``screen``, the window's scene options and camera), and on the right the window's
    panels (the phone tier and lip panels by default, with ``screen`` every panel it shows, over
    its time range). ``frame(t)`` is the RGB image at time ``t``; ``layout`` says where each part
    is. Call ``close()`` when done.

    ``view``: the window's :class:`~facetraj_app.state.UtteranceView` (else made of
    ``synthesis``, ``audio`` and ``phones``); ``pins``: the window's
    :class:`~facetraj_app.pins.PinBoard`; ``caption``: else made of ``title`` and the settings."""

    def __init__(self, model: Model, synthesis: Synthesis, original: np.ndarray | None = None,
                 phones: Sequence[PhoneSegment] | None = None, settings: VideoSettings | None = None,
                 title: str = "", *, audio: np.ndarray | None = None, sample_rate: int = 16000,
                 view=None, pins=None, caption: str = "", screen: Screen | None = None):
        from .pins import PinBoard
        from .screen_export import PanelContext, caption_text, main_panels, point_entries
        from .state import view_of_synthesis

        settings, screen = settings or VideoSettings(), screen or Screen()
        view = view or view_of_synthesis(model, synthesis, audio, sample_rate, phones or (),
                                         original, text=title)
        self.model, self.view = model, view
        self.synthesis, self.original = view.synthesis, view.original
        self.span = tuple(screen.span) if screen.span else (0.0, float(view.times[-1]))
        width = settings.width - settings.width % 16
        height = settings.height - settings.height % 16
        pins = pins if pins is not None else PinBoard()
        panels = list(screen.panels) or main_panels(PanelContext(model, closed_lips(model), pins))
        caption = caption or caption_text(view, heading=title or "")
        if width < 640:
            raise ValueError(f"video size {settings.width}x{settings.height} is too small "
                             "(at least 640x304)")
        half = width // 2
        self._half = half
        entries = point_entries(view.original is not None)
        header_h = _header(width, caption, entries)[0].shape[0]        # the panels' entries below
        body = height - header_h
        if body < 240:
            raise ValueError(f"video size {settings.width}x{settings.height} is too small "
                             "(at least 640x304)")
        self.panels = _Panels(view, panels, width - half, body, self.span)
        header, title_box, legend_box = _header(width, caption, entries + self.panels.entries())
        if header.shape[0] != header_h:            # more legend rows: the panels a little lower
            body = height - header.shape[0]
            self.panels = _Panels(view, panels, width - half, body, self.span)
        self.header, self.size, self._body = header, (width, height), body
        self._scene(model, (half, body), view, pins.shown(view), screen)
        lips, tier, labels = self.panels.boxes(half, header.shape[0])
        self.layout = VideoLayout(width, height, (0, header.shape[0], half, height), legend_box,
                                  title_box, lips, tier, labels, self.panels.titles(), self.span)

    def _scene(self, model: Model, size: tuple[int, int], view, pins: list, screen: Screen) -> None:
        """The off-screen 3-D scene: the window's (its options, its pinned faces, its camera),
        else the synthesized face with its surface, mouth and lip contours and the original
        points over it, in the three-quarter view (a profile for midsagittal data); articulograph
        sensors as articulators (``app/articulators.py``), as the window draws them."""
        import pyvista as pv

        self.plotter = pv.Plotter(off_screen=True, window_size=size)
        self.plotter.set_background(BACKGROUND)
        self.scene = FaceScene(self.plotter)
        self.scene.set_model(model, closed_lips(model))          # the mouth shuts at /p b m/
        self.scene.set_view(view)
        self.scene.set_pins(pins)
        profile = model.is_planar or is_articulograph(model)    # as the window looks at them
        options = screen.options or SceneOptions(preset="profile" if profile else "three-quarter")
        self.scene.set_options(options)
        if screen.camera is not None:
            self.scene.set_camera_state(screen.camera)

    def frame(self, t: float) -> np.ndarray:
        """The RGB frame ``(height, width, 3)`` at ``t`` seconds."""
        self.scene.show_frame(self.view.frame_at(t), render=False)
        self.plotter.render()
        left = np.asarray(self.plotter.screenshot(return_img=True))[:self._body, :self._half, :3]
        right = self.panels.image(t)
        return np.ascontiguousarray(
            np.concatenate([self.header, np.concatenate([left, right], axis=1)], axis=0))

    def times(self, fps: float) -> np.ndarray:
        """The times of the video's frames at ``fps``: its time range's."""
        t0, t1 = self.span
        return t0 + np.arange(int(np.floor((t1 - t0) * fps + 1e-9)) + 1) / fps

    def close(self) -> None:
        self.plotter.close()


def render_video(model: Model, synthesis: Synthesis, audio: np.ndarray, sample_rate: int,
                 path: str | os.PathLike[str], original: np.ndarray | None = None,
                 settings: VideoSettings | None = None, overwrite: bool = False,
                 progress: Callable[[float, str], None] | None = None,
                 title: str = "", phones: Sequence[PhoneSegment] | None = None,
                 view=None, pins=None, caption: str = "", screen: Screen | None = None) -> Path:
    """Write an MP4 (H.264 + AAC) of the synthesized (and original) face points and lip panels.

    ``original`` is the head-normalised original ``(T, M, 3)`` or ``None``; ``phones`` the phone
    segments shown in the tier over the lip panels (none: the tier says so). From the window:
    its ``view``, ``pins``, ``caption`` and ``screen`` (what is on screen, over the time range
    shown, its sound too; :class:`VideoFrames`).
    """
    import imageio_ffmpeg

    settings = settings or VideoSettings()
    progress = progress or (lambda f, m: None)
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path}: already exists; choose to overwrite it (--overwrite) "
                              "or give another name")
    frames = VideoFrames(model, synthesis, original, phones, settings, title, audio=audio,
                         sample_rate=sample_rate, view=view, pins=pins, caption=caption,
                         screen=screen)
    times = frames.times(settings.fps)
    n_video = len(times)
    try:
        with tempfile.TemporaryDirectory() as tmpdir:
            wav = Path(tmpdir) / "speech.wav"
            first = int(round(times[0] * sample_rate))
            write_audio(wav, *sound_for_frames(audio[first:], sample_rate, n_video, settings.fps))
            with atomic_write(path, overwrite=True) as tmp:
                # the sound exactly as long as the frames, and both cut there: every frame kept
                # (``-shortest`` dropped the last, the AAC stream ending a few ms early)
                writer = imageio_ffmpeg.write_frames(
                    str(tmp), frames.size, fps=settings.fps, codec="libx264",
                    audio_path=str(wav), audio_codec="aac", macro_block_size=8,
                    ffmpeg_log_level="error", output_params=["-t", f"{n_video / settings.fps:.6f}"])
                writer.send(None)
                try:
                    for k, t in enumerate(times):
                        writer.send(frames.frame(float(t)))
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
