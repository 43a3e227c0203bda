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
    from engine.corpus import load_corpus

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
