"""The main window in a real X display (run under Xvfb): opening, playback, seeking, changing the
utterance and the settings, the screenshot (checked on its pixels), and a corrupt file."""

from __future__ import annotations

import os
import subprocess
import sys
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from PyQt6.QtCore import QPoint, Qt
from PyQt6.QtGui import QImage
from PyQt6.QtWidgets import QFileDialog, QMessageBox
from screens import near

from facetraj.paths import default_corpus
from facetraj_app import style
from facetraj_app.browser import normalise_text
from facetraj_app.main import build_window
from facetraj_app.main_window import DEFAULT_SENTENCE, MainWindow
from facetraj_engine.config import SynthConfig

pytestmark = pytest.mark.gui

ROOT = Path(__file__).resolve().parent.parent
WAIT_MS = 240_000   # a hang guard (a loaded machine is slow), not a speed limit


@pytest.fixture
def window(qtbot, trained_cache):
    """The main window on the default corpus, shown, with its first utterance synthesized."""
    win = build_window(default_corpus(), use_audio=False)
    qtbot.addWidget(win)
    win.resize(1600, 1000)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.show()
    qtbot.waitExposed(win)
    win.activateWindow()
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    yield win
    win.close()


def _canvas_point(win: MainWindow, ax, t: float) -> QPoint:
    """The canvas widget position of time ``t`` in the middle of ``ax``."""
    canvas = win.timeline.canvas
    y_mid = sum(ax.get_ylim()) / 2
    x, y = ax.transData.transform((t, y_mid))
    dpr = canvas.devicePixelRatioF()
    return QPoint(int(round(x / dpr)), int(round((canvas.figure.bbox.height - y) / dpr)))


def test_window_opens_on_default_corpus(window):
    win = window
    assert win.corpus is not None and win.corpus.root.resolve() == default_corpus().resolve()
    assert win.model is not None and win.model.n_markers == len(win.corpus.info.marker_names)
    view = win.view
    assert view is not None
    assert view.split == "test"
    assert normalise_text(view.utterance.text) == normalise_text(DEFAULT_SENTENCE)
    assert view.original is not None and view.original.shape == view.shown.shape
    assert view.speech.any() and not view.speech.all()
    assert set(win.browser.groups) == {"train", "test"}
    assert len(win.browser.items) == len(win.corpus.info.ids)
    assert len(win.timeline.axes) == len(win.timeline.panels) >= 5
    assert win.analysis_menu.title().replace("&", "") == "Analysis"


def test_play_moves_cursor_and_3d_frame(window, qtbot):
    win = window
    win.seek(0.0)
    start_points = win.face.synth.current.copy()
    moved: list[float] = []
    win.cursorMoved.connect(moved.append)
    win.play()
    qtbot.waitUntil(lambda: win.displayed_frame >= 20, timeout=10_000)
    win.pause()
    assert win.timeline.cursor_time > 0.2
    assert moved and moved[-1] == pytest.approx(win.timeline.cursor_time)
    assert not np.allclose(win.face.synth.current, start_points)
    k = win.displayed_frame
    np.testing.assert_allclose(win.face.synth.current, win.face._syn[k] + win.face._offset)
    # the frame shown is the one at the clock, within a frame
    assert abs(win.current_time() * win.view.rate - k) <= 1.0


def test_click_on_lip_panel_seeks(window, qtbot):
    win = window
    lower = next(p for p in win.timeline.panels if getattr(p, "title", "") == "lower lip y")
    ax = win.timeline.axes_of(lower)
    target = 0.4 * win.view.duration
    with qtbot.waitSignal(win.cursorMoved, timeout=5000):
        qtbot.mouseClick(win.timeline.canvas, Qt.MouseButton.LeftButton,
                         pos=_canvas_point(win, ax, target))
    assert win.current_time() == pytest.approx(target, abs=0.02)
    assert win.timeline.cursor_time == pytest.approx(target, abs=0.02)
    assert win.displayed_frame == pytest.approx(target * win.view.rate, abs=1.5)
    # keys: one frame forward, then back to the start
    k = win.displayed_frame
    qtbot.waitActive(win)
    qtbot.keyClick(win, Qt.Key.Key_Right)
    assert win.displayed_frame == k + 1
    qtbot.keyClick(win, Qt.Key.Key_Home)
    assert win.displayed_frame == 0


def test_drag_selects_a_loop_and_playback_wraps_in_it(window, qtbot):
    win = window
    lower = next(p for p in win.timeline.panels if getattr(p, "title", "") == "lower lip y")
    ax = win.timeline.axes_of(lower)
    dur = win.view.duration
    a, b = 0.3 * dur, 0.45 * dur
    canvas = win.timeline.canvas
    qtbot.mousePress(canvas, Qt.MouseButton.LeftButton, pos=_canvas_point(win, ax, a))
    qtbot.mouseMove(canvas, pos=_canvas_point(win, ax, (a + b) / 2))
    qtbot.mouseMove(canvas, pos=_canvas_point(win, ax, b))
    qtbot.mouseRelease(canvas, Qt.MouseButton.LeftButton, pos=_canvas_point(win, ax, b))
    assert win.loop_box.isChecked()
    assert win.clock.loop == pytest.approx((a, b), abs=0.02)
    times: list[float] = []
    win.cursorMoved.connect(times.append)
    win.play()
    qtbot.waitUntil(lambda: any(t1 < t0 for t0, t1 in pairwise(times)),
                    timeout=10_000)
    win.pause()
    lo, hi = win.clock.loop
    assert all(lo - 0.05 <= t <= hi + 0.05 for t in times)


def test_marker_name_on_hover(window, qtbot):
    win = window
    face = win.face
    k = win.model.upper_lip
    x, y = face.project(face.synth.current)[k]          # VTK display pixels, origin bottom left
    widget = face.plotter
    dpr = widget.devicePixelRatioF()
    qtbot.mouseMove(widget, pos=QPoint(int(x / dpr), int(widget.height() - y / dpr)))
    qtbot.waitUntil(lambda: bool(face._hover_name), timeout=5000)
    assert face._hover_name.startswith(win.model.marker_names[k])


def test_changing_utterance_updates_every_view(window, qtbot):
    win = window
    other = next(u for u in win.corpus.info.test if u != win.view.utterance.name)
    item = win.browser.items[other]
    with qtbot.waitSignals([win.utteranceChanged, win.synthesisChanged], timeout=WAIT_MS):
        win.browser.tree.setCurrentItem(item)     # as a click in the browser does
    view = win.view
    assert view.utterance.name == other
    assert win.face.view is view and win.timeline.view is view
    np.testing.assert_allclose(win.face.synth.current, view.shown[win.displayed_frame])
    assert win.clock.duration == pytest.approx(view.utterance.duration)
    assert win.slider.maximum() == view.n_frames - 1
    assert other in win.title.text()
    assert win.timeline.xlim()[1] == pytest.approx(view.duration)
    assert win.browser.tree.currentItem() is item


def test_changing_n_resynthesizes(window, qtbot):
    win = window
    before = win.view
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.settings.n.setValue(1)
    after = win.view
    assert after is not before
    assert after.utterance.name == before.utterance.name
    assert win.synth_config.n_context_phones == 1
    assert after.synthesis.config.n_context_phones == 1
    assert not np.allclose(after.shown, before.shown)
    assert win.timeline.view is after and win.face.view is after
    # a new utterance asked for, then N changed before it arrived: both apply
    other = next(u for u in win.corpus.info.test if u != after.utterance.name)
    win.set_utterance(other)
    win.set_synth_config(win.synth_config.with_(n_context_phones=2))
    qtbot.waitUntil(lambda: win.view.utterance.name == other
                    and win.view.synthesis.config.n_context_phones == 2, timeout=WAIT_MS)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    assert win.view.utterance.name == other and win.settings.n.value() == 2


def test_closure_parts_switched_from_the_settings(window, qtbot):
    """The closure step's parts (issue 46) are boxes in the settings, as the command's
    --no-closure-labels, --no-rest and --closure-detector: the defaults shown as the engine's,
    each box resynthesizes, and with every box off the face is the paper's (no closure step)."""
    win = window
    s, default = win.settings, SynthConfig()
    assert (s.closure_labels.isChecked(), s.rest.isChecked(), s.closure_detector.isChecked()) == \
        (default.closure_labels, default.rest, default.closure_detector)
    before = win.view
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        s.closure_labels.click()
    cfg = win.view.synthesis.config
    assert not cfg.closure_labels and cfg.rest and cfg.closure
    assert not np.allclose(win.view.shown, before.shown)          # the /p b m/ no longer closed
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        s.rest.click()
    assert not win.view.synthesis.config.closure
    paper = win.view.synthesis
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    from facetraj_engine.method.pipeline import synthesize

    u = win.view.utterance
    plain = synthesize(win.model, u.audio, u.sample_rate, u.phones,
                       paper.config.with_(closure=True, closure_labels=False, rest=False),
                       n_frames=u.n_frames)
    np.testing.assert_allclose(paper.markers, plain.markers, atol=1e-9)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        s.reset.click()
    assert s.closure_labels.isChecked() and s.rest.isChecked() and win.view.synthesis.config.closure


def choose(combo, key) -> None:
    """Pick the entry of ``combo`` whose data is ``key``, as a user does (``activated``)."""
    combo.setCurrentIndex(combo.findData(key))
    combo.activated.emit(combo.currentIndex())


def test_acoustic_search_choice(window, qtbot):
    """The search menu: indexed acoustic-only weights K codewords per frame, the whole-codebook
    entry (the paper's) weights all 5L, and phonetic comes back with the default K; the title
    names the one used (both used to read "acoustic")."""
    win = window
    n_codewords = len(win.model.codebook.lsf)
    mode = win.settings.mode
    for key, width, title in (("acoustic", SynthConfig().acoustic_prefilter,
                               "acoustic only, indexed (K = 128)"),
                              ("acoustic-full", n_codewords, "acoustic only, whole codebook")):
        with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
            choose(mode, key)
        qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
        synthesis = win.view.synthesis
        assert synthesis.config.mode == "acoustic"
        assert synthesis.frames.candidates.shape == (win.view.n_frames, width)
        assert title in win.title.text() and win.settings.shown_search() == key
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        choose(mode, "phonetic")
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    assert win.synth_config == SynthConfig(n_context_phones=win.synth_config.n_context_phones)


def _read_png(path: Path) -> np.ndarray:
    img = QImage(str(path)).convertToFormat(QImage.Format.Format_RGB888)
    assert not img.isNull(), path
    h, w = img.height(), img.width()
    ptr = img.constBits()
    ptr.setsize(img.sizeInBytes())
    return np.frombuffer(ptr, np.uint8).reshape(h, img.bytesPerLine())[:, :3 * w].reshape(h, w, 3).copy()


def test_screenshot_shows_both_point_sets_and_lip_panels(window, tmp_path):
    win = window
    win.seek(0.5 * win.view.duration)
    out = win.save_screenshot(tmp_path / "app.png")
    img = _read_png(out)
    assert img.shape[:2] == (win.height(), win.width())
    # the 3-D area: both marker colours are there
    p = win.face.mapTo(win, QPoint(0, 0))
    area = img[p.y():p.y() + win.face.height(), p.x():p.x() + win.face.width()]
    assert near(area, style.ORIGINAL_COLOR, 60.0) > 150
    assert near(area, style.SYNTH_COLOR, 60.0) > 150
    # the lip panels: curves drawn (non-white pixels, the spline and original colours)
    canvas = win.timeline.canvas
    c = canvas.mapTo(win, QPoint(0, 0))
    fig_h = canvas.figure.bbox.height
    for title in ("upper lip y", "lower lip y"):
        panel = next(pp for pp in win.timeline.panels if getattr(pp, "title", "") == title)
        bb = win.timeline.axes_of(panel).bbox
        y0 = c.y() + int(fig_h - bb.y1) + 2
        y1 = c.y() + int(fig_h - bb.y0) - 2
        x0, x1 = c.x() + int(bb.x0) + 2, c.x() + int(bb.x1) - 2
        lip = img[y0:y1, x0:x1]
        non_white = (lip.astype(int).sum(axis=2) < 720).mean()
        assert non_white > 0.01, title
        assert near(lip, style.SPLINE_COLOR, 50.0) > 100, title
        assert near(lip, style.ORIGINAL_COLOR, 50.0) > 100, title


def test_screenshot_command_line(trained_cache, tmp_path):
    out = tmp_path / "cli.png"
    env = {**os.environ, "FACETRAJ_CACHE_DIR": str(trained_cache)}
    proc = subprocess.run([sys.executable, "-m", "facetraj", "--screenshot", str(out), "--time", "1.0"],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stderr[-2000:]
    img = _read_png(out)
    assert img.shape[0] >= 800 and img.shape[1] >= 1200
    assert near(img, style.ORIGINAL_COLOR, 60.0) > 300
    assert near(img, style.SYNTH_COLOR, 60.0) > 150


def test_screenshot_error_is_printed_once(trained_cache, tmp_path):
    """A bad utterance id in screenshot mode: exit 2 and the message once (the window's error
    report used to log it and the screenshot handler print it again)."""
    env = {**os.environ, "FACETRAJ_CACHE_DIR": str(trained_cache)}
    proc = subprocess.run([sys.executable, "-m", "facetraj", "--screenshot", str(tmp_path / "x.png"),
                           "--utterance", "nosuchid"], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=180)
    assert proc.returncode == 2
    lines = [ln for ln in proc.stderr.splitlines() if "nosuchid" in ln]
    assert lines == [f"facetraj: error: nosuchid: no such utterance in {default_corpus()}"], proc.stderr
    assert not (tmp_path / "x.png").exists()


def test_corrupt_file_shows_error_and_app_keeps_working(window, qtbot, tmp_path, monkeypatch):
    win = window
    bad = tmp_path / "broken.wav"
    bad.write_bytes(b"RIFF\x10\x00\x00\x00WAVEfmt garbage, not audio")
    answers = iter([(str(bad), ""), ("", "")])
    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(lambda *a, **k: next(answers)))
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "critical", staticmethod(lambda parent, title, text, *a, **k:
                                                              shown.append(text)))
    name = win.view.utterance.name
    win.action_open_audio.trigger()
    assert len(shown) == 1 and "broken.wav" in shown[0]
    assert win.view.utterance.name == name
    # still working: play moves the frame
    win.seek(0.0)
    win.play()
    qtbot.waitUntil(lambda: win.displayed_frame >= 5, timeout=10_000)
    win.pause()
    # a corrupt corpus folder too
    (tmp_path / "corpus.json").write_text("{not json")
    monkeypatch.setattr(QFileDialog, "getExistingDirectory", staticmethod(lambda *a, **k: str(tmp_path)))
    win.action_open_corpus.trigger()
    assert len(shown) == 2 and "corpus.json" in shown[1]
    assert win.corpus.root.resolve() == default_corpus().resolve()
    # a good audio file without labels, opened with "No labels": acoustic-only synthesis, no
    # original markers
    import shutil

    from facetraj_app.open_audio import SentenceDialog
    from facetraj_engine.io.corpus import audio_path

    good = tmp_path / audio_path(win.corpus.root, win.corpus.info.test[-1]).name
    shutil.copy(audio_path(win.corpus.root, win.corpus.info.test[-1]), good)
    answers = iter([(str(good), "")])
    monkeypatch.setattr(SentenceDialog, "exec", lambda self: (self._acoustic_only(), 1)[1])
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.action_open_audio.trigger()
    assert len(shown) == 2
    assert win.view.split == "external" and win.view.original is None
    assert win.view.synthesis.config.mode == "acoustic"
    assert win.browser.tree.currentItem() is win.browser.items[win.view.utterance.name]
    # no original markers: the "original" box is off and unticked (it stayed ticked), and comes
    # back as it was with a corpus utterance
    box = win.view_bar.show_original
    assert not box.isEnabled() and not box.isChecked() and "no original" in box.toolTip()
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.set_utterance(win.corpus.info.test[0])
    assert box.isEnabled() and box.isChecked()


def test_browser_scores_are_kept_per_settings(qtbot, toy_corpus, toy_model, monkeypatch):
    """The lip-correlation sweep computes each utterance once per settings: after a change only
    the new settings' scores are computed (the old ones stay shown, greyed), and going back to
    earlier settings shows theirs at once with nothing computed (the sweep used to restart from
    nothing after every change); the browser's columns say what they hold."""
    from facetraj_app import correlations
    from facetraj_app.browser import UtteranceBrowser
    from facetraj_app.viewer_model import ViewerModel
    from facetraj_app.workers import Gate, TaskRunner

    browser = UtteranceBrowser()
    qtbot.addWidget(browser)
    assert browser.COLUMNS[1:] == ("lower lip r", "upper lip r")
    state = ViewerModel()
    state.set_model(toy_corpus, toy_model, {})
    info = toy_corpus.info
    browser.populate({"test": list(info.test), "train": list(info.train)}, {})
    scores = correlations.BrowserScores(browser, TaskRunner(browser), Gate())
    computed: list[str] = []
    sweep = correlations.correlation_sweep
    monkeypatch.setattr(correlations, "correlation_sweep",
                        lambda m, c, ids, cfg, before: (computed.extend(u for _s, u in ids),
                                                        sweep(m, c, ids, cfg, before))[1])
    finished: list = []
    n = len(state.correlation_ids())
    texts = lambda: {u: browser.items[u].text(1) for u in info.ids}  # noqa: E731
    scores.start(state, finished.append)
    qtbot.waitUntil(lambda: len(finished) == 1, timeout=WAIT_MS)
    first = texts()
    assert len(computed) == n and "…" not in first.values()
    state.set_config(state.synth_config.with_(n_context_phones=5))
    scores.start(state, finished.append)
    stale = browser.palette().placeholderText().color()
    assert all(browser.items[u].foreground(1).color() == stale for u in info.ids)   # old: greyed
    qtbot.waitUntil(lambda: len(finished) == 2, timeout=WAIT_MS)
    assert len(computed) == 2 * n
    state.set_config(state.synth_config.with_(n_context_phones=3))
    scores.start(state, finished.append)
    assert len(finished) == 3 and len(computed) == 2 * n          # known: shown, nothing computed
    assert texts() == first
    assert all(browser.items[u].foreground(1).color() != stale for u in info.ids)
