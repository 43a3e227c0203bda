"""Video export: the 3-D face points beside the lip trajectories, with the speech muxed in.

Rendering is off screen (``pyvista.Plotter(off_screen=True)`` and matplotlib's Agg canvas), so
it runs without a window; frames go to the ffmpeg binary shipped by ``imageio-ffmpeg`` as H.264
with AAC sound. The file is written under a temporary name and renamed into place.
"""

from __future__ import annotations

import logging
import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine.data import Utterance
from engine.formats import atomic_write, write_audio
from engine.model import Model
from engine.pipeline import Synthesis

log = logging.getLogger(__name__)

ORIGINAL_COLOUR = "#1f77b4"
SYNTH_COLOUR = "#d62728"


@dataclass(frozen=True)
class VideoSettings:
    """Video size and frame rate."""

    width: int = 1280
    height: int = 544
    fps: float = 30.0


def _lip_panel(model: Model, times: np.ndarray, synth: np.ndarray, original: np.ndarray | None,
               width: int, height: int):
    """An Agg figure with upper and lower lip y; returns (figure, canvas, background, cursors)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width / 100, height / 100), dpi=100)
    canvas = FigureCanvasAgg(fig)
    axes = fig.subplots(2, 1, sharex=True)
    cursors = []
    for ax, idx, title in ((axes[0], model.upper_lip, "upper lip y (mm)"),
                           (axes[1], model.lower_lip, "lower lip y (mm)")):
        if original is not None:
            ax.plot(times, original[:, idx, 1], color=ORIGINAL_COLOUR, lw=1.5, ls=":",
                    label="original")
        ax.plot(times, synth[:, idx, 1], color=SYNTH_COLOUR, lw=1.5, label="synthesized")
        ax.set_ylabel(title)
        ax.grid(alpha=0.3)
        cursors.append(ax.axvline(times[0], color="k", lw=1, animated=True))
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].set_xlabel("time (s)")
    axes[1].set_xlim(times[0], times[-1])
    fig.tight_layout()
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    return fig, canvas, background, cursors


def render_video(model: Model, synthesis: Synthesis, audio: np.ndarray, sample_rate: int,
                 path: str | os.PathLike[str], original: np.ndarray | None = None,
                 settings: VideoSettings | None = None, overwrite: bool = False,
                 progress: Callable[[float, str], None] | None = None,
                 title: str = "") -> Path:
    """Write an MP4 (H.264 + AAC) of the synthesized (and original) face points and lip panels.

    ``original`` is the head-normalised original ``(T, M, 3)`` or ``None``.
    """
    import imageio_ffmpeg
    import pyvista as pv

    settings = settings or VideoSettings()
    progress = progress or (lambda f, m: None)
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path}: already exists; choose to overwrite it (--overwrite) "
                              "or give another name")
    times = synthesis.times
    synth = synthesis.markers
    half = settings.width // 2
    height = settings.height - settings.height % 16
    half -= half % 8

    plotter = pv.Plotter(off_screen=True, window_size=(half, height))
    plotter.set_background("white")
    synth_cloud = pv.PolyData(synth[0].copy())
    plotter.add_mesh(synth_cloud, color=SYNTH_COLOUR, point_size=11,
                     render_points_as_spheres=True, label="synthesized")
    orig_cloud = None
    if original is not None:
        first = np.nan_to_num(original[0], nan=0.0)
        orig_cloud = pv.PolyData(first.copy())
        plotter.add_mesh(orig_cloud, color=ORIGINAL_COLOUR, point_size=11,
                         render_points_as_spheres=True, label="original")
    plotter.add_legend(bcolor="white", size=(0.42, 0.12), loc="upper right", face="circle")
    if title:
        plotter.add_text(title, font_size=9, color="black")
    plotter.view_xy()
    plotter.camera.zoom(1.2)
    fig, canvas, background, cursors = _lip_panel(model, times, synth, original, half, height)

    n_video = int(np.floor(times[-1] * settings.fps)) + 1
    with tempfile.TemporaryDirectory() as tmpdir:
        wav = Path(tmpdir) / "speech.wav"
        write_audio(wav, audio, sample_rate)
        with atomic_write(path, overwrite=True) as tmp:
            writer = imageio_ffmpeg.write_frames(
                str(tmp), (2 * half, height), fps=settings.fps, codec="libx264",
                audio_path=str(wav), audio_codec="aac", macro_block_size=8,
                output_params=["-shortest"])
            writer.send(None)
            try:
                for k in range(n_video):
                    t = k / settings.fps
                    f = min(int(round(t * model.marker_rate)), len(times) - 1)
                    synth_cloud.points = synth[f]
                    if orig_cloud is not None:
                        pts = original[f]
                        if np.isfinite(pts).all():
                            orig_cloud.points = pts
                    plotter.render()
                    left = np.asarray(plotter.screenshot(return_img=True))[:height, :half, :3]
                    canvas.restore_region(background)
                    for c in cursors:
                        c.set_xdata([t, t])
                        c.axes.draw_artist(c)
                    canvas.blit(fig.bbox)
                    right = np.asarray(canvas.buffer_rgba())[:height, :half, :3]
                    frame = np.ascontiguousarray(np.concatenate([left, right], axis=1))
                    writer.send(frame)
                    if k % 10 == 0:
                        progress(k / n_video, f"frame {k + 1} of {n_video}")
            finally:
                writer.close()
                plotter.close()
    progress(1.0, "done")
    log.info("wrote %s (%d frames at %g fps)", path, n_video, settings.fps)
    return path


def video_for_utterance(model: Model, utt: Utterance, synthesis: Synthesis,
                        path: str | os.PathLike[str], **kwargs) -> Path:
    """:func:`render_video` for a corpus utterance, with its original markers when it has them."""
    original = model.normalise_markers(utt.markers) if utt.markers is not None else None
    return render_video(model, synthesis, utt.audio, utt.sample_rate, path, original=original,
                        title=utt.text or utt.name, **kwargs)
