"""Outputs checked before any work, and outputs that declare themselves (issue 38): the C3D's
screen axes and its speech in the analog section (checked with ezc3d, the reader motion-capture
users have), the MP4 with exactly the frames the log reports and sound as long as them, progress
lines that log lines do not break."""

from __future__ import annotations

import io
import logging
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from facetraj.cli import main
from facetraj.progress import LogAboveBar, TerminalProgress
from facetraj_engine.io.export import speech_channel

ROOT = Path(__file__).resolve().parent.parent
CLIP = ROOT / "data_samples" / "s002.flac"          # 2.07 s, its TextGrid beside it


@pytest.fixture(scope="module")
def model_file(default_model, tmp_path_factory):
    return default_model.save(tmp_path_factory.mktemp("outputs") / "model.npz")


def test_a_c3d_declares_its_axes_and_carries_the_speech(model_file, tmp_path, caplog):
    ezc3d = pytest.importorskip("ezc3d")
    out = tmp_path / "face.c3d"
    with caplog.at_level(logging.INFO):
        assert main(["synth", str(model_file), str(CLIP), "-o", str(out)]) == 0
    assert "face.c3d: axes declared (POINT:X_SCREEN +X, Y_SCREEN +Y" in caplog.text
    assert "the speech as analog channel SPEECH (by default" in caplog.text
    c3d = ezc3d.c3d(str(out))
    point, analog = c3d["parameters"]["POINT"], c3d["parameters"]["ANALOG"]
    assert point["X_SCREEN"]["value"] == ["+X"] and point["Y_SCREEN"]["value"] == ["+Y"]
    assert list(analog["USED"]["value"]) == [1] and analog["LABELS"]["value"] == ["SPEECH"]
    assert analog["DESCRIPTIONS"]["value"] == ["speech, scaled to a peak of 1"]
    n_frames = c3d["data"]["points"].shape[2]
    assert float(analog["RATE"]["value"][0]) == 16020.0            # 267 samples a 60 Hz frame
    data = c3d["data"]["analogs"]
    assert data.shape == (1, 1, n_frames * 267)
    x, rate = sf.read(CLIP)
    expected = speech_channel((x, rate), 60.0, n_frames).analog.ravel()
    np.testing.assert_allclose(data[0, 0], expected, atol=0.6 / 32767)   # int16 steps
    assert np.abs(data).max() == pytest.approx(1.0, abs=1e-4)
    # and without it, when asked
    quiet = tmp_path / "quiet.c3d"
    assert main(["synth", str(model_file), str(CLIP), "-o", str(quiet), "--no-audio"]) == 0
    c3d = ezc3d.c3d(str(quiet))
    assert list(c3d["parameters"]["ANALOG"]["USED"]["value"]) == [0]
    assert c3d["parameters"]["POINT"]["Y_SCREEN"]["value"] == ["+Y"]
    assert quiet.stat().st_size < out.stat().st_size / 1.5


@pytest.mark.parametrize("output, phrase", [
    ("face.bvh", "facetraj does not write .bvh files here: give a .c3d, .tsv, .csv or .npz name"),
    ("face.glb", "facetraj does not write .glb files here"),
    ("/proc/x.tsv", "/proc/x.tsv: cannot be written: /proc takes no new files (a special file "
                    "system, such as /proc or /sys)"),
])
def test_an_output_is_refused_before_any_work(output, phrase, model_file, tmp_path, capsys,
                                              monkeypatch):
    import facetraj_engine.io.label_rule as label_rule

    work = []
    monkeypatch.setattr(label_rule, "label_audio", lambda *a, **k: work.append(a))
    out = output if output.startswith("/") else str(tmp_path / output)
    code = main(["synth", str(model_file), str(CLIP), "--text", "The boy enjoyed the noisy toy.",
                 "-o", out])
    err = capsys.readouterr().err
    assert code == 2 and phrase in err and len(err.splitlines()) == 1
    assert not work                     # refused before the alignment (and the synthesis)


def test_the_video_has_the_frames_the_log_reports(model_file, tmp_path, caplog):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    pytest.importorskip("facetraj_app")
    out = tmp_path / "s002.mp4"
    with caplog.at_level(logging.INFO):
        assert main(["video", str(model_file), str(CLIP), "-o", str(out), "--size", "640x320",
                     "--fps", "25"]) == 0
    logged = int(re.search(r"wrote .*s002\.mp4 \((\d+) frames at 25 fps\)", caplog.text).group(1))
    frames, _ = imageio_ffmpeg.count_frames_and_secs(str(out))
    assert frames == logged == int(np.floor(2.0666 * 25)) + 1
    pcm = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-i", str(out), "-map",
                          "0:a", "-f", "s16le", "-ac", "1", "-ar", "48000", "-"],
                         capture_output=True, check=True).stdout
    assert abs(len(pcm) / 2 / 48000 - frames / 25) < 1024 / 48000       # within one AAC frame


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_log_lines_print_above_the_progress_bar():
    stream = _Terminal()
    bar = TerminalProgress("synth", stream)
    handler = LogAboveBar(stream)
    handler.setFormatter(logging.Formatter("%(levelname)s: %(message)s"))
    log = logging.getLogger("facetraj.test-bar")
    log.addHandler(handler)
    log.propagate = False
    try:
        bar(0.5, "half")
        log.warning("a line")
        bar(1.0, "done")
    finally:
        log.removeHandler(handler)
    screen = _render(stream.getvalue())
    assert screen[0] == "WARNING: a line"                 # above the bar, whole
    assert screen[1].startswith("synth [#########################] 100% done")
    assert TerminalProgress.active is None


def _render(text: str) -> list[str]:
    """The lines a terminal shows of ``text`` (a carriage return goes back to the line's start,
    what follows overwrites it), blank ones left out."""
    lines, line, col = [], [], 0
    for ch in text:
        if ch == "\n":
            lines.append("".join(line).rstrip())
            line, col = [], 0
        elif ch == "\r":
            col = 0
        else:
            if col < len(line):
                line[col] = ch
            else:
                line.append(ch)
            col += 1
    lines.append("".join(line).rstrip())
    return [ln for ln in lines if ln]
