"""Issue 49's review (the app's third), repeated by tests on a 1920x1200 and a 1366x768 screen
(each test runs on a private Xvfb of each size: the ``screen`` fixture of tests/conftest.py): the
playback keys after a spin box or a filter box, the layout after a shrink and an enlargement,
the time axis, the video against the window, the labels box and the pins' list on a laptop, and
a mouth large enough to judge a closure (the close-up of the lips, the enlarged 3-D view)."""

from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from PyQt6.QtCore import QPoint, Qt
from PyQt6.QtWidgets import QAbstractSpinBox, QApplication, QLineEdit, QToolButton
from screens import (
    assert_placed_as_in,
    face_image,
    middle,
    near,
    project,
    resynthesize,
    screen_window,
    view_settled,
)

from facetraj_app import style

pytestmark = pytest.mark.gui

WAIT_MS = 240_000          # a hang guard (a loaded machine is slow), not a speed limit


@pytest.fixture
def win(screen, qtbot, trained_cache):
    """The main window as ``facetraj`` opens it, on s002 "The boy enjoyed the noisy toy."; None
    when the test runs on its own screen."""
    yield from screen_window(screen, qtbot, "s002", WAIT_MS)


def press(qtbot, w, key, modifier=Qt.KeyboardModifier.NoModifier) -> None:
    """A key pressed as the keyboard does: to the widget that has the focus."""
    qtbot.keyClick(QApplication.focusWidget() or w, key, modifier)


def click_panel(qtbot, w, title: str) -> None:
    """A click in the middle of the timeline's panel ``title``."""
    tl = w.timeline
    tl.canvas.finish()
    box = tl.axes_of(next(p for p in tl.shown if p.title == title)).bbox
    ratio = tl.canvas.devicePixelRatioF()
    at = QPoint(int((box.x0 + box.x1) / 2 / ratio), int(tl.canvas.height() - (box.y0 + box.y1) / 2 / ratio))
    qtbot.mouseClick(tl.canvas, Qt.MouseButton.LeftButton, pos=at)


def open_view(w, qtbot, key: str):
    views = w.extension("analysis")
    views.view_actions[key].trigger()
    qtbot.waitUntil(lambda: view_settled(w, key), timeout=WAIT_MS)
    return views.widgets[key]


# ---------------------------------------------------------------------- 1: keys
def test_the_keys_work_after_a_spin_box_or_a_filter(screen, win, qtbot):
    """N changed in its spin box, then a click on the lower-lip panel: space, the arrows,
    shift+arrows, Home and End act again (they did nothing until the utterance list was
    clicked: the spin box kept the focus); a filter typed, then a click on the 3-D view: the
    same."""
    w = win
    w.activateWindow()
    qtbot.waitUntil(lambda: QApplication.activeWindow() is w, timeout=10_000)
    n = w.settings.n
    qtbot.mouseClick(n, Qt.MouseButton.LeftButton)
    assert isinstance(QApplication.focusWidget(), (QAbstractSpinBox, QLineEdit))
    resynthesize(w, qtbot, lambda: press(qtbot, w, Qt.Key.Key_Up), WAIT_MS)     # N = 4
    assert w.view.synthesis.config.n_context_phones == 4
    for target in ("panel", "3-D view"):
        if target == "panel":
            click_panel(qtbot, w, "lower lip y")
        else:
            qtbot.mouseClick(w.browser.filter, Qt.MouseButton.LeftButton)
            qtbot.keyClicks(w.browser.filter, "boy")
            assert QApplication.focusWidget() is w.browser.filter
            qtbot.mouseClick(w.plotter.interactor, Qt.MouseButton.LeftButton, pos=QPoint(8, 8))
        assert not isinstance(QApplication.focusWidget(), (QAbstractSpinBox, QLineEdit)), target
        press(qtbot, w, Qt.Key.Key_Home)
        assert w.current_time() == 0.0 and w.displayed_frame == 0, target
        press(qtbot, w, Qt.Key.Key_Right)
        assert w.displayed_frame == 1, target
        press(qtbot, w, Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier)
        first = next(p.start for p in w.view.utterance.phones if p.start > 1.0 / 60)
        assert w.current_time() == pytest.approx(first), target
        press(qtbot, w, Qt.Key.Key_End)
        assert w.displayed_frame == w.view.n_frames - 1, target
        press(qtbot, w, Qt.Key.Key_Home)
        press(qtbot, w, Qt.Key.Key_Space)
        assert w.clock.playing, target
        press(qtbot, w, Qt.Key.Key_Space)
        assert not w.clock.playing, target
    w.browser.filter.clear()


# ---------------------------------------------------------------------- 4: layout
def layout_of(w) -> tuple:
    return (w.width(), w.height(), w.browser_dock.width(), w.settings_dock.width(),
            w.plotter.height(), w.timeline.height())


def test_shrinking_and_enlarging_the_window_restores_its_layout(screen, win, qtbot):
    """800x600 (the least the window can be) and back: the left docks, the 3-D view and the
    panels have their sizes again (the docks stayed narrow, "model's" cut to "r", and the 3-D
    view 217 px tall instead of 375), and at every size the settings' controls lie whole inside
    their dock."""
    w = win
    before = layout_of(w)
    assert before[2] == min(400, before[0] // 4)
    size = w.size()
    settings = w.settings
    viewport = w.settings_dock.widget().viewport()
    controls = [settings.n, settings.c, settings.xi, settings.nu, settings.nu_default,
                settings.mode, settings.smoothing, w.audio_opener.box.combo]
    for wanted in ((800, 600), (size.width(), size.height())):
        w.resize(*wanted)
        qtbot.waitUntil(lambda s=wanted: w.settled and w.width() <= max(s[0], w.minimumSizeHint().width()),
                        timeout=WAIT_MS)
        qtbot.wait(50)                      # the docks' and the split's deferred fit
        for control in controls:
            right = control.mapTo(viewport, QPoint(control.width(), 0)).x()
            assert right <= viewport.width(), (wanted, control)
        assert settings.nu_default.width() >= settings.nu_default.sizeHint().width()
    qtbot.waitUntil(lambda: layout_of(w) == before, timeout=10_000)


# ---------------------------------------------------------------------- 6: the time axis
def test_the_time_axis_is_the_utterance(screen, win, qtbot):
    """The panels' time axis runs from 0 to the utterance's end (at 1366x768 it ran from -0.17
    to 3.57 s: a relayout read matplotlib's padded limits), also after the Kinematics dock adds
    panels and after a resize."""
    w = win
    tl = w.timeline

    def limits() -> tuple[float, float]:
        qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)
        tl.canvas.finish()
        return tuple(float(x) for x in tl.axes[0].get_xlim())

    whole = (0.0, w.view.duration)
    assert limits() == pytest.approx(whole, abs=1e-9)
    open_view(w, qtbot, "kinematics")
    assert limits() == pytest.approx(whole, abs=1e-9)
    w.resize(w.width() - 120, w.height() - 80)
    assert limits() == pytest.approx(whole, abs=1e-9)
    assert min(tl.axes[-1].get_xticks()) >= 0.0


# ---------------------------------------------------------------------- 2: the video
def test_the_video_is_what_the_screen_shows(screen, win, qtbot, tmp_path, monkeypatch):
    """With the front camera, side by side, a pin, a 0.1-0.8 s zoom and Kinematics' aperture
    panel on screen, File > Export a video writes frames of 0.1 to 0.8 s with that sound, every
    panel the window shows over that range, and the 3-D faces where the window has them: the
    original left of the synthesis, the pin's face beside, as far apart (the MP4 showed the 3/4
    view overlaid, no pinned face, the whole utterance and the lip panels only)."""
    import imageio_ffmpeg

    import facetraj_app.own_data as own_data
    from facetraj_app.video import VideoFrames, VideoSettings

    w = win
    open_view(w, qtbot, "kinematics")
    w.view_bar.set_camera("front")
    w.view_bar.side_by_side.setChecked(True)
    w.extension("compare").pin()
    resynthesize(w, qtbot, lambda: w.set_synth_config(w.synth_config.with_(n_context_phones=1)), WAIT_MS)
    w.timeline.set_xlim(0.1, 0.8)
    qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)
    w.seek(0.4)
    shown = [p.title for p in w.timeline.shown]
    assert {"lip aperture", "aperture minus pin"} <= set(shown)
    out = tmp_path / "screen.mp4"
    monkeypatch.setattr(own_data, "ask_save_path", lambda *a, **k: out)
    w.extension("own_data").actions["Export a video"].trigger()
    qtbot.waitUntil(lambda: f"wrote {out}" in w.status_label.text(), timeout=WAIT_MS)
    info = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-i", str(out)],
                          capture_output=True, text=True).stderr
    assert "Audio: aac" in info
    reader = imageio_ffmpeg.read_frames(str(out))
    width, height = next(reader)["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader]
    assert len(frames) == int(np.floor(0.7 * VideoSettings().fps + 1e-9)) + 1          # 22
    # the frames' layout: every panel the window shows, over its range
    caption, screen_state = own_data.screen_of(w)
    video = VideoFrames(w.model, w.view.synthesis, view=w.view, pins=w.pins, caption=caption,
                        screen=screen_state)
    try:
        lay = video.layout
        assert lay.panels == tuple(shown) and lay.span == pytest.approx((0.1, 0.8)), (lay.panels, caption)
        assert "pin 1: N=3  ·" in caption       # what tells the pin apart, as the toolbar says
        assert "0.10–0.80 s" in caption
        # the 3-D half of the frame at 0.4 s against the window's 3-D view at 0.4 s
        k = int(round((0.4 - 0.1) * VideoSettings().fps))
        scene = frames[k][lay.scene[1]:lay.scene[3], lay.scene[0]:lay.scene[2]]
    finally:
        video.close()
    w.face.rerender()
    window = face_image(w.plotter)
    pin = w.pins.pins[0]
    assert_placed_as_in(window, scene, [style.ORIGINAL_COLOR, style.SYNTH_COLOR, pin.color])


def test_the_video_of_the_close_up_is_what_the_screen_shows(screen, win, qtbot):
    """The close-up of the lips side by side with a pin: the video's faces in the window's grid
    under the window's camera, each where the window has it (the video laid its narrower half's
    grid out, two rows where the window had one, and showed it through the window's camera:
    the pin's face under the original's, the faces small and off centre)."""
    import facetraj_app.own_data as own_data
    from facetraj_app.video import VideoFrames

    w = win
    w.view_bar.side_by_side.setChecked(True)
    w.extension("compare").pin()
    resynthesize(w, qtbot, lambda: w.set_synth_config(w.synth_config.with_(n_context_phones=1)), WAIT_MS)
    w.view_bar.set_camera("lips")
    w.seek(middle(w, "b"))
    qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)
    caption, screen_state = own_data.screen_of(w)
    video = VideoFrames(w.model, w.view.synthesis, view=w.view, pins=w.pins, caption=caption,
                        screen=screen_state)
    try:
        x0, y0, x1, y1 = video.layout.scene
        scene = video.frame(middle(w, "b"))[y0:y1, x0:x1]
    finally:
        video.close()
    w.face.rerender()
    assert_placed_as_in(face_image(w.plotter), scene,
                        [style.ORIGINAL_COLOR, style.SYNTH_COLOR, w.pins.pins[0].color])


# ---------------------------------------------------------------------- 9: the laptop's docks
def test_the_labels_box_and_the_pins_stay_in_view(screen, win, qtbot):
    """In the robust search (its long note shown) the labels box is in view in the settings
    dock (it was scrolled out at 1366x768); with three pins the toolbar's list of them is on the
    window, not in its overflow menu, and names each pin by what differs."""
    w = win
    resynthesize(w, qtbot, lambda: w.audio_opener.switch("aligned"), WAIT_MS)
    assert w.settings.shown_search() == "robust" and w.settings.tuned_label.isVisible()
    combo = w.audio_opener.box.combo
    viewport = w.settings_dock.widget().viewport()
    top_left = combo.mapTo(viewport, QPoint(0, 0))
    assert combo.isVisible() and 0 <= top_left.y() and top_left.y() + combo.height() <= viewport.height()
    compare = w.extension("compare")
    compare.pin()
    assert "pin 1: the result on screen" in compare.label.text()
    resynthesize(w, qtbot, lambda: w.audio_opener.switch("recognized"), WAIT_MS)
    for n in (1, 2):
        compare.pin()
        resynthesize(w, qtbot, lambda n=n: w.set_synth_config(w.synth_config.with_(n_context_phones=n)),
                     WAIT_MS)
    assert len(w.pins.shown(w.view)) == 3
    bar = compare.label.parentWidget()
    overflow = bar.findChild(QToolButton, "qt_toolbar_ext_button")
    assert overflow is None or not overflow.isVisible()
    assert compare.label.isVisible() and compare.label.width() > 100
    right = compare.label.mapTo(w, QPoint(compare.label.width(), 0)).x()
    assert right <= w.width()
    text = compare.label.text()
    assert all(f"pin {k}:" in text for k in (1, 2, 3)) and "labels: aligned" in text


# ---------------------------------------------------------------------- 5: a mouth to judge
def test_the_close_up_of_the_lips_and_the_enlarged_view_show_a_mouth_to_judge(screen, win, qtbot):
    """Side by side with a pin, at the /b/ of "boy": the close-up of the lips makes each face's
    mouth at least 2.5 times as wide on screen as the front view does (at 1366x768 a face was
    97-133 px tall, 80 px with pins); a face whose lips are at closure shows no dark pixel
    between its lip centres (the original's at the /b/), each face the dark mouth at the /oy/;
    the enlarged 3-D view (the panels hidden) makes it larger again (a third or more)."""
    w = win
    model = w.model
    w.view_bar.side_by_side.setChecked(True)
    w.extension("compare").pin()
    resynthesize(w, qtbot, lambda: w.set_synth_config(w.synth_config.with_(n_context_phones=1)), WAIT_MS)
    w.seek(middle(w, "b"))
    corners = list(model.lip_corners)

    def mouths() -> list[float]:
        w.face.rerender()
        return [float(np.ptp(project(w.plotter, m.current[corners])[:, 0]))
                for m, shown in w.face.face_sets() if shown and m.actor.GetVisibility()]

    def gaps(label: str) -> list[tuple[bool, int]]:
        """Each face's lips at closure (all along) and the dark pixels between its lip centres."""
        w.seek(middle(w, label))
        w.face.rerender()
        image = face_image(w.plotter)
        out = []
        for m, shown in w.face.face_sets():
            if shown and m.actor.GetVisibility():
                (xu, yu), (xl, yl) = project(w.plotter, m.current[[model.upper_lip, model.lower_lip]])
                x = int(round((xu + xl) / 2))
                column = image[int(round(yu)) + 2:int(round(yl)) - 1, x - 2:x + 3].reshape(-1, 3)
                out.append((m.mouth.shut(m.current), near(column, style.CAVITY_COLOR, 40)))
        return out

    w.view_bar.set_camera("front")
    front = mouths()
    w.view_bar.set_camera("lips")
    close = mouths()
    assert len(close) == 3 and min(close) >= 2.5 * max(front), (front, close)
    assert min(close) >= 90, close
    at_b, at_oy = gaps("b"), gaps("oy")
    assert at_b[1][0] and all(dark == 0 for shut, dark in at_b if shut), at_b    # the original's
    assert all(not shut and dark > 0 for shut, dark in at_oy), at_oy
    w.seek(middle(w, "b"))
    height = w.plotter.height()
    w.transport.enlarge.setChecked(True)
    qtbot.waitUntil(lambda: w.plotter.height() > 1.8 * height, timeout=10_000)
    qtbot.waitUntil(lambda: min(mouths()) >= 1.3 * min(close), timeout=10_000)
    assert not w.timeline.isVisible()
    w.transport.enlarge.setChecked(False)
    qtbot.waitUntil(lambda: w.timeline.isVisible() and abs(w.plotter.height() - height) <= 2,
                    timeout=10_000)
