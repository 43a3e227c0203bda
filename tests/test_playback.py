"""Playback (issue #15): the scheduler's timing of each frame against the audio clock, and what a
frame update does in the window: the 3-D points move in place with one render, the panels are not
redrawn (the cursor is blitted), and the time read-out does not lay the bars out again."""

from __future__ import annotations

import os

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from PyQt6.QtCore import QEvent, QObject, pyqtSignal

from facetraj_app.playback import MAX_WAIT, PlaybackScheduler

RATE = 60.0


class FakeClock(QObject):
    """A playback clock whose time the test sets."""

    playingChanged = pyqtSignal(bool)

    def __init__(self, duration: float = 10.0, speed: float = 1.0):
        super().__init__()
        self.t, self.duration, self.speed = 0.0, duration, speed
        self.playing, self.looping, self.loop = True, False, None

    def time(self) -> float:
        return self.t

    def poll(self) -> float:
        return self.t


def scheduler(qapp, t: float, shown: int, latency: float = 0.01, speed: float = 1.0,
              duration: float = 10.0) -> PlaybackScheduler:
    clock = FakeClock(duration, speed)
    clock.t = t
    s = PlaybackScheduler(clock)
    s.set_frames(int(duration * RATE), RATE)
    s.shown(shown)
    s.latency = latency
    return s


def test_waits_until_the_next_frame_lands_on_its_time(qapp):
    # 0.5 s + 10 ms of latency = frame 30.6 -> frame 31 is right; frame 32 starts 10 ms before 32/60 s
    s = scheduler(qapp, 0.5, shown=31)
    target, wait = s.plan(0.5)
    assert target is None
    assert wait == pytest.approx(32 / RATE - 0.5 - 0.01)


def test_the_next_frame_is_sent_with_the_latency_as_lookahead(qapp):
    s = scheduler(qapp, 32 / RATE - 0.01, shown=31)
    target, wait = s.plan(32 / RATE - 0.01)
    assert wait == 0.0 and s.frame_at(target) == 32
    assert target == pytest.approx(32 / RATE)


def test_a_frame_is_not_started_to_land_before_its_time(qapp):
    # 14 ms of latency (0.84 frame) right after frame 30 reached the screen: an update started now
    # would land at frame 30.84, nearest to frame 31 but 0.16 frame early; it starts 14 ms
    # before 31/60 s instead, and then lands on time
    s = scheduler(qapp, 30 / RATE, shown=30, latency=0.014)
    target, wait = s.plan(30 / RATE)
    assert target is None
    assert wait == pytest.approx(31 / RATE - 0.014 - 30 / RATE)
    start = 30 / RATE + wait
    target, wait = s.plan(start)
    assert wait == 0.0 and s.frame_at(target) == 31 and target == pytest.approx(31 / RATE)


def test_the_wait_allows_for_the_usual_lateness_of_a_tick(qapp):
    s = scheduler(qapp, 0.5, shown=31)
    s.wake = 0.002
    target, wait = s.plan(0.5)
    assert target is None and wait == pytest.approx(32 / RATE - 0.01 - 0.002 - 0.5)
    # the tick, 2 ms late as usual: the update starts, and lands on frame 32's time
    target, wait = s.plan(0.5 + wait + 0.002)
    assert wait == 0.0 and target == pytest.approx(32 / RATE)


def test_a_late_update_shows_the_frame_nearest_to_its_landing_time(qapp):
    # lands at frame 31.3: frame 31, 0.3 frame late (waiting for 32 would skip 31)
    s = scheduler(qapp, 31.3 / RATE - 0.014, shown=30, latency=0.014)
    target, wait = s.plan(31.3 / RATE - 0.014)
    assert wait == 0.0 and s.frame_at(target) == 31


def test_after_a_flush_the_following_frame_is_rendered_ahead_and_shown_at_its_time(qapp):
    s = scheduler(qapp, 30 / RATE, shown=30, latency=0.005)
    s.prepare_time = 0.008
    asked = []
    s.prepareDue.connect(asked.append)
    assert s.prepare_next(30 / RATE) == 31 and s.ahead == 31
    assert asked == [pytest.approx(31 / RATE)]
    target, wait = s.plan(30 / RATE + 0.008)
    assert target is None                           # rendered: it waits for its time
    assert wait == pytest.approx(31 / RATE - 0.005 - (30 / RATE + 0.008))
    target, wait = s.plan(31 / RATE - 0.005)
    assert wait == 0.0 and s.frame_at(target) == 31
    s.shown(31)
    assert s.ahead is None


def test_a_frame_that_cannot_be_ready_by_its_time_is_not_rendered_ahead(qapp):
    # 13 ms to render ahead and show: frame 31 (due in 1.7 ms) would be late, 32 is rendered
    s = scheduler(qapp, 30.9 / RATE, shown=30, latency=0.005)
    s.prepare_time = 0.008
    assert s.prepare_next(30.9 / RATE) == 32
    target, wait = s.plan(30.9 / RATE + 0.008)
    assert target is None and wait == pytest.approx(32 / RATE - 0.005 - (30.9 / RATE + 0.008))


def test_nothing_is_rendered_ahead_after_the_last_frame(qapp):
    s = scheduler(qapp, 9.99, shown=599, duration=10.0)
    assert s.prepare_next(9.99) is None and s.ahead is None


def test_late_updates_skip_frames_rather_than_drift(qapp):
    s = scheduler(qapp, 40.2 / RATE, shown=31, latency=0.03)
    target, wait = s.plan(40.2 / RATE)
    assert wait == 0.0
    assert s.frame_at(target) == round(40.2 + 0.03 * RATE)      # frame 42: 32-41 never shown


def test_a_jump_back_of_the_clock_is_shown_at_once(qapp):
    s = scheduler(qapp, 0.1, shown=150)                            # the loop wrapped
    target, wait = s.plan(0.1)
    assert wait == 0.0 and s.frame_at(target) == round((0.1 + 0.01) * RATE)


def test_the_wait_is_in_wall_seconds_at_half_speed(qapp):
    # the 10 ms latency is 5 ms of clock at half speed: frame 30.3 -> 30 is right
    s = scheduler(qapp, 0.5, shown=30, speed=0.5)
    target, wait = s.plan(0.5)
    assert target is None
    assert wait == pytest.approx((31 / RATE - 0.5 - 0.005) / 0.5)


def test_after_the_last_frame_the_clock_is_polled_until_the_end(qapp):
    s = scheduler(qapp, 9.99, shown=599, duration=10.0)
    target, wait = s.plan(9.99)
    assert target is None
    assert wait == pytest.approx(0.01)
    s.clock.t = 9.0
    s.shown(round(9.01 * RATE))
    assert s.plan(9.0)[1] <= MAX_WAIT


# ---------------------------------------------------------------------- in the window
gui = pytest.mark.skipif(not os.environ.get("DISPLAY"), reason="needs an X display (xvfb-run)")


@pytest.fixture
def window(qtbot, trained_cache):
    from facetraj.paths import default_corpus
    from facetraj_app.main import build_window

    win = build_window(default_corpus(), use_audio=False)
    qtbot.addWidget(win)
    win.resize(1600, 1000)
    with qtbot.waitSignal(win.synthesisChanged, timeout=240_000):
        win.show()
    qtbot.waitExposed(win)
    qtbot.waitUntil(lambda: win.settled, timeout=240_000)
    win.timeline.canvas.draw()           # any pending full draw (layout, resize) done now
    qtbot.waitUntil(lambda: win.timeline.cursor_ready, timeout=10_000)
    yield win
    win.close()


class _Counter(QObject):
    """Counts the events of some types an object receives."""

    def __init__(self, *types: QEvent.Type):
        super().__init__()
        self.types, self.count = set(types), 0

    def eventFilter(self, obj, event) -> bool:
        if event.type() in self.types:
            self.count += 1
        return False


@gui
@pytest.mark.gui
def test_playback_blits_the_cursor_without_redrawing_the_panels(window, qtbot, monkeypatch):
    win = window
    timeline = win.timeline
    full_draws, blits = [], []
    draw, blit = timeline.figure.draw, timeline.canvas.blit
    monkeypatch.setattr(timeline.figure, "draw", lambda *a, **k: (full_draws.append(1), draw(*a, **k))[1])
    monkeypatch.setattr(timeline.canvas, "blit", lambda *a, **k: (blits.append(1), blit(*a, **k))[1])
    win.seek(0.0)
    win.play()
    qtbot.waitUntil(lambda: win.displayed_frame >= 15, timeout=20_000)
    win.pause()
    qtbot.waitUntil(lambda: not win.playback.pending, timeout=5_000)
    assert blits, "the cursor moved by blitting"
    assert full_draws == [], "no panel data changed: no full draw of the figure"
    assert timeline.cursor_time == pytest.approx(win.current_time())


@gui
@pytest.mark.gui
def test_the_cursor_is_drawn_in_every_panel_at_its_time(window):
    from matplotlib.colors import to_rgb

    from facetraj_app.style import CURSOR_COLOR

    timeline = window.timeline
    t = 0.37 * window.view.duration
    window.seek(t)
    rgba = np.asarray(timeline.canvas.buffer_rgba())
    height = rgba.shape[0]
    want = np.array(to_rgb(CURSOR_COLOR)) * 255
    for ax in timeline.axes:
        x, _ = ax.transData.transform((t, 0))
        y_mid = (ax.bbox.y0 + ax.bbox.y1) / 2
        row = int(height - y_mid)
        column = rgba[row, int(x) - 1:int(x) + 2, :3].astype(float)
        beside = rgba[row, int(x) + 12, :3].astype(float)       # the panel without the cursor
        on = np.min(np.abs(column - want).sum(axis=1))          # a 1.2 px line: partly blended
        assert on < 100 and on < 0.5 * np.abs(beside - want).sum(), ax


@gui
@pytest.mark.gui
def test_a_moved_cursor_leaves_no_trace(window):
    """After the cursor moves on by blitting, the figure is pixel for pixel what a full draw
    with the cursor at its new time gives: the old cursor and its strip are restored in place."""
    timeline = window.timeline
    window.seek(0.30 * window.view.duration)
    window.seek(0.34 * window.view.duration)
    blitted = np.asarray(timeline.canvas.buffer_rgba()).copy()
    timeline.canvas.draw()                     # the reference: a full draw, cursor drawn anew
    timeline.set_cursor(0.34 * window.view.duration)
    drawn = np.asarray(timeline.canvas.buffer_rgba())
    assert (blitted != drawn).any(axis=2).sum() <= 2 * len(timeline.axes)   # cursor-end pixels


@gui
@pytest.mark.gui
def test_a_screenshot_uses_the_panels_as_drawn(window, tmp_path, monkeypatch):
    """A screenshot draws the panels again only when their last full draw is stale (here after
    a zoom); either way the saved picture holds the canvas as a full draw makes it, cursor
    included."""
    from PyQt6.QtCore import QPoint
    from PyQt6.QtGui import QImage

    timeline = window.timeline
    full_draws = []
    draw = timeline.figure.draw
    monkeypatch.setattr(timeline.figure, "draw", lambda *a, **k: (full_draws.append(1), draw(*a, **k))[1])

    def canvas_in_shot(path) -> tuple[np.ndarray, np.ndarray]:
        img = QImage(str(path)).convertToFormat(QImage.Format.Format_RGBA8888)
        ptr = img.constBits()
        ptr.setsize(img.sizeInBytes())
        shot = np.frombuffer(ptr, np.uint8).reshape(img.height(), img.bytesPerLine() // 4, 4)
        p = timeline.canvas.mapTo(window, QPoint(0, 0))
        buf = np.asarray(timeline.canvas.buffer_rgba())
        return (shot[p.y():p.y() + buf.shape[0], p.x():p.x() + buf.shape[1], :3].copy(),
                buf[:, :, :3].copy())

    window.seek(0.3 * window.view.duration)
    window.seek(0.4 * window.view.duration)
    shot, canvas = canvas_in_shot(window.save_screenshot(tmp_path / "current.png"))
    assert full_draws == []
    np.testing.assert_array_equal(shot, canvas)
    timeline.canvas.draw()                          # the reference: a full draw, cursor drawn anew
    np.testing.assert_array_equal(shot, np.asarray(timeline.canvas.buffer_rgba())[:, :, :3])
    full_draws.clear()
    timeline.set_xlim(0.0, 0.5 * window.view.duration)        # zoomed: the last draw is stale
    shot, canvas = canvas_in_shot(window.save_screenshot(tmp_path / "zoomed.png"))
    assert full_draws
    np.testing.assert_array_equal(shot, canvas)


@gui
@pytest.mark.gui
def test_a_new_scene_renders_once(window):
    """Building the scene for a model adds its meshes and renders the finished scene once (a
    render per mesh was four renders too many on the first frame's path)."""
    face = window.face
    renders = []
    face.plotter.ren_win.AddObserver("EndEvent", lambda *_: renders.append(1))
    face.set_model(window.model)
    assert len(renders) == 1


@gui
@pytest.mark.gui
def test_a_frame_update_moves_the_points_in_place_with_one_render(window, qtbot):
    from PyQt6.QtWidgets import QApplication

    from facetraj_app.plotter_widget import is_native

    win = window
    face = win.face
    assert is_native(face.plotter)               # X11 (Xvfb): the native-window plotter
    actor, points, xyz = face.synth.actor, face.synth.points.GetPoints(), face.synth.xyz
    renders = []
    face.plotter.ren_win.AddObserver("EndEvent", lambda *_: renders.append(1))
    QApplication.processEvents()
    renders.clear()
    frames = [10, 11, 30, 31]
    for k in frames:
        win.seek(k / win.view.rate)
        QApplication.processEvents()
    assert len(renders) == len(frames)           # one render per update, none from a repaint
    assert face.synth.actor is actor and face.synth.points.GetPoints() is points
    assert np.shares_memory(face.synth.xyz, xyz)
    np.testing.assert_allclose(np.asarray(face.synth.points.points),
                               face._syn[frames[-1]] + face._offset)


def _on_screen(widget) -> np.ndarray:
    """The pixels of ``widget``'s area as the X server shows them (RGB)."""
    from PyQt6.QtCore import QPoint
    from PyQt6.QtGui import QGuiApplication, QImage
    from PyQt6.QtWidgets import QApplication

    QApplication.processEvents()
    pos = widget.mapToGlobal(QPoint(0, 0))
    image = QGuiApplication.primaryScreen().grabWindow(0, pos.x(), pos.y(), widget.width(),
                                                       widget.height()).toImage()
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    rows = np.frombuffer(image.constBits().asstring(image.sizeInBytes()), np.uint8)
    rows = rows.reshape(image.height(), image.bytesPerLine())[:, :3 * image.width()]
    return rows.reshape(image.height(), image.width(), 3).astype(int)


@gui
@pytest.mark.gui
def test_a_frame_rendered_ahead_reaches_the_screen_only_when_shown(window):
    """The native view copies only its colour to the window, and a frame rendered ahead stays
    off screen until ``show_frame`` puts it there, without another render: the same pixels as
    a full render of that frame."""
    face = window.face
    plotter = face.plotter
    renders = []
    plotter.ren_win.AddObserver("EndEvent", lambda *_: renders.append(1))
    face.show_frame(40)
    frame_40 = _on_screen(plotter)
    assert np.abs(frame_40 - plotter.screenshot()[:, :, :3]).max() == 0    # on screen: VTK's image
    face.show_frame(80)
    frame_80 = _on_screen(plotter)
    assert (frame_80 != frame_40).any(axis=2).sum() > 1000
    renders.clear()
    face.prepare_frame(40)
    assert len(renders) == 1 and face.ahead == 40
    assert np.array_equal(_on_screen(plotter), frame_80)          # still frame 80 on screen
    face.show_frame(40)
    assert len(renders) == 1 and face.frame == 40 and face.ahead == -1
    assert np.array_equal(_on_screen(plotter), frame_40)


@gui
@pytest.mark.gui
def test_the_window_renders_a_due_frame_ahead_and_shows_it_without_another_render(window,
                                                                                   monkeypatch):
    """The scheduler's two requests, as playback sends them: ``prepareDue`` renders the frame
    off screen (the cursor and the frame on screen stay), ``frameDue`` then only presents it."""
    from PyQt6.QtWidgets import QApplication

    win = window
    plotter = win.face.plotter
    rate = win.view.rate
    win.seek(20 / rate)
    QApplication.processEvents()
    renders, presents = [], []
    plotter.ren_win.AddObserver("EndEvent", lambda *_: renders.append(1))
    present = plotter.present
    monkeypatch.setattr(plotter, "present", lambda: (presents.append(1), present())[1])
    win.playback.prepareDue.emit(21 / rate)
    assert (len(renders), len(presents)) == (1, 0)
    assert win.displayed_frame == 20 and win.timeline.cursor_time == pytest.approx(20 / rate)
    win.playback.frameDue.emit(21 / rate)
    QApplication.processEvents()
    assert (len(renders), len(presents)) == (1, 1)
    assert win.displayed_frame == 21 and win.face.frame == 21
    np.testing.assert_allclose(np.asarray(win.face.synth.points.points),
                               win.face._syn[21] + win.face._offset)


@gui
@pytest.mark.gui
def test_the_time_read_out_does_not_lay_the_window_out_again(window):
    from PyQt6.QtWidgets import QApplication

    bar = window.transport
    counter = _Counter(QEvent.Type.LayoutRequest)
    for w in (bar, bar.parentWidget()):
        w.installEventFilter(counter)
    size = bar.time_label.size()
    for k, text in enumerate([" 0.017 / 3.400 s  frame    1  /sil/", " 1.017 / 3.400 s  frame   61",
                              "12.500 / 13.400 s  frame  750  /aa/"]):
        bar.show_frame(k, text)
        QApplication.processEvents()
    assert counter.count == 0
    assert bar.time_label.size() == size and bar.time_label.text().startswith("12.500")


@gui
@pytest.mark.gui
def test_both_plotter_widgets_draw_the_same_face(qtbot, default_model):
    """The native-window plotter (X11) and pyvistaqt's QOpenGLWidget one render the same image."""
    from facetraj_app.view3d import FaceView

    images = []
    for native in (True, False):
        face = FaceView(native=native)
        qtbot.addWidget(face)
        face.set_model(default_model)
        face.resize(500, 400)
        face.show()
        qtbot.waitExposed(face)
        face.rerender()
        images.append(np.asarray(face.plotter.screenshot(), dtype=float))
        face.close_view()
    native_img, qt_img = images
    assert native_img.shape == qt_img.shape and native_img.std() > 10
    assert np.mean(np.abs(native_img - qt_img) > 40) < 0.01
