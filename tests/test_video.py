"""Video export: an H.264 MP4 with the sound muxed in, written atomically."""

import subprocess

import imageio_ffmpeg
import numpy as np
import pytest

from facetraj.cli import main


def _streams(path):
    out = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-i", str(path)],
                         capture_output=True, text=True).stderr
    return out


def test_video_from_corpus_utterance(toy_corpus_dir, tmp_path, capsys):
    model = tmp_path / "m.npz"
    assert main(["-q", "train", str(toy_corpus_dir), "-o", str(model)]) == 0
    out = tmp_path / "v.mp4"
    assert main(["-q", "video", str(model), "--corpus", str(toy_corpus_dir), "--utterance",
                 "toy030", "-o", str(out), "--size", "640x320", "--fps", "20"]) == 0
    info = _streams(out)
    assert "Video: h264" in info and "Audio: aac" in info and "640x320" in info
    dur = next(ln for ln in info.splitlines() if "Duration" in ln)
    _h, _m, s = dur.split("Duration:")[1].split(",")[0].strip().split(":")
    from facetraj_engine.io.corpus import load_corpus

    utt = load_corpus(toy_corpus_dir).utterance("toy030")
    assert float(s) == pytest.approx(utt.duration, abs=0.15)
    # a frame in the middle shows both colours of points and the lip curves
    frame = tmp_path / "f.png"
    subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-loglevel", "error", "-i", str(out),
                    "-vf", "select=eq(n\\,10)", "-frames:v", "1", str(frame)], check=True)
    import imageio.v3 as iio

    img = iio.imread(frame).astype(int)
    red = (img[..., 0] > 170) & (img[..., 1] < 90) & (img[..., 2] < 90)
    blue = (img[..., 2] > 150) & (img[..., 0] < 90)
    assert red[:, :320].sum() > 30 and blue[:, :320].sum() > 30       # 3-D view
    assert red[:, 320:].sum() > 30                                     # lip panel
    # no overwrite without asking
    before = out.read_bytes()
    assert main(["-q", "video", str(model), str(toy_corpus_dir / "toy030.wav"), "-o", str(out)]) == 2
    assert "already exists" in capsys.readouterr().err and out.read_bytes() == before
    assert np.isfinite(img).all()


def _inside(box, outer):
    return box[0] >= outer[0] and box[1] >= outer[1] and box[2] <= outer[2] and box[3] <= outer[3]


def _overlap(a, b):
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _colour_pixels(img, box, hex_colour, tol=40):
    rgb = np.array([int(hex_colour[i:i + 2], 16) for i in (1, 3, 5)])
    part = img[box[1]:box[3], box[0]:box[2]].astype(int)
    return int((np.abs(part - rgb).max(axis=2) <= tol).sum())


@pytest.mark.parametrize("size", [(1280, 544), (640, 320)])
def test_video_frame_has_legend_surface_and_phone_tier_inside(default_model, default_corpus, size):
    """A rendered frame: the legend and the phone tier lie inside the frame and show what they
    should (the legend's colours, phone labels inside the tier); the face surface is drawn."""
    from facetraj_app.style import ORIGINAL_COLOR, SURFACE_COLOR, SYNTH_COLOR
    from facetraj_app.video import VideoFrames, VideoSettings
    from facetraj_engine.config import SynthConfig
    from facetraj_engine.method.modes import choose_mode
    from facetraj_engine.method.pipeline import synthesize

    utt = default_corpus.utterance(default_corpus.info.test[0])
    res = synthesize(default_model, utt.audio, utt.sample_rate, utt.phones,
                     choose_mode(SynthConfig(), utt.phones).config, n_frames=utt.n_frames)
    original = default_model.normalise_markers(utt.markers)
    frames = VideoFrames(default_model, res, original, utt.phones, VideoSettings(*size),
                         title=utt.text or utt.name)
    try:
        t = utt.duration / 2
        img = frames.frame(t)
    finally:
        frames.close()
    lay = frames.layout
    whole = (0, 0, lay.width, lay.height)
    assert img.shape == (lay.height, lay.width, 3) and lay.width == size[0]
    # the legend: inside the frame, clear of the 3-D scene and the panels, showing both colours
    assert _inside(lay.legend, whole)
    assert not _overlap(lay.legend, lay.scene) and not _overlap(lay.legend, lay.tier)
    assert _colour_pixels(img, lay.legend, SYNTH_COLOR) > 10
    assert _colour_pixels(img, lay.legend, ORIGINAL_COLOR) > 10
    assert lay.title is not None and _inside(lay.title, whole)
    assert not _overlap(lay.title, lay.legend)
    # the phone tier: inside the frame, under the lower lip panel, its labels inside it
    assert _inside(lay.tier, whole) and lay.tier[1] >= lay.lips[1][3]
    real = [p for p in utt.phones if p.label != "sil"]
    assert 0 < len(lay.phone_labels) <= len(real)
    if size[0] >= 1280:
        assert len(lay.phone_labels) >= len(real) // 2
    for label in lay.phone_labels:
        assert _inside(label, lay.tier)
    for a, b in zip(lay.phone_labels, lay.phone_labels[1:], strict=False):
        assert not _overlap(a, b)
    tier = img[lay.tier[1]:lay.tier[3], lay.tier[0]:lay.tier[2]]
    assert (tier.max(axis=2) < 100).sum() > 20            # dark label text in the tier
    # the face surface, as the app draws it, in the 3-D half
    assert _colour_pixels(img, lay.scene, SURFACE_COLOR, tol=60) > 0.02 * (
        (lay.scene[2] - lay.scene[0]) * (lay.scene[3] - lay.scene[1]))
