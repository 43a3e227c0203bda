"""The main window with its analysis views, as a phonetician opens them on a 1600 x 1000 window
(real window under Xvfb): the window stays on the screen while every dock opens and closes and
the panels' labels stay legible and apart; no view freezes the event loop while it opens; the
saved screenshot shows each 3-D view as the screen does (issue 29)."""

from __future__ import annotations

import os

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from matplotlib.transforms import Bbox
from PyQt6.QtGui import QImage
from PyQt6.QtWidgets import QAbstractButton, QSlider
from screens import Heartbeat, assert_legible, colour_of, image_array, on_screen, place_in, view_settled

from facetraj.paths import default_corpus
from facetraj_app.analysis import PANELS, VIEWS
from facetraj_app.main import build_window

pytestmark = pytest.mark.gui

WAIT_MS = 240_000          # a hang guard (a loaded machine is slow), not a speed limit
MAX_STALL_MS = 200         # issue 29: no event-loop stall over 200 ms while a view opens
SIZE = (1600, 1000)


@pytest.fixture
def window(qtbot, trained_cache):
    win = build_window(default_corpus(), use_audio=False)
    qtbot.addWidget(win)
    win.resize(*SIZE)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.show()
    qtbot.waitExposed(win)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    yield win
    win.extension("analysis").close()
    win.close()


def open_all(win, qtbot) -> dict[str, tuple[int, int]]:
    """Open every analysis view from the menu, one after the other, each until it has settled;
    the longest event-loop stall of each: (wall ms, the GUI thread's CPU ms in that stall)."""
    views = win.extension("analysis")
    beat, longest = Heartbeat(), {}
    for key in VIEWS:
        beat.start()
        views.view_actions[key].trigger()
        qtbot.waitUntil(lambda k=key: view_settled(win, k), timeout=WAIT_MS)
        longest[key] = (beat.stop(), beat.longest_cpu)
    return longest


def test_no_view_freezes_the_window_while_it_opens(window, qtbot):
    """Every view (its module imported, its work done, its plots drawn, the panels it adds to the
    timeline) opens without holding up the event loop over 200 ms; before: similarity 2.3-4.4 s,
    kinematics 3.3 s, PC modes 1.4 s.

    Two measures of the same heartbeat: the gap (wall time), and the GUI thread's own work in
    it (CPU time). The first is what the user sees; on a machine whose cores other processes
    share it also holds their time, so the test checks the second against 200 ms and the first
    against 200 ms times the machine's load average per core (at least 1)."""
    longest = open_all(window, qtbot)
    views = window.extension("analysis")
    beat = Heartbeat()
    for key in PANELS:                                  # the panels not opened by a view
        beat.start()
        views.panel_actions[key].setChecked(True)
        qtbot.waitUntil(lambda: window.settled, timeout=WAIT_MS)
        longest[f"panel {key}"] = (beat.stop(), beat.longest_cpu)
    print("longest event-loop stall per view (wall ms, GUI-thread CPU ms):", longest)
    assert max(cpu for _wall, cpu in longest.values()) <= MAX_STALL_MS, longest
    load = max(1.0, os.getloadavg()[0] / max(os.cpu_count() or 1, 1))
    assert max(wall for wall, _cpu in longest.values()) <= MAX_STALL_MS * load, (load, longest)


def test_docks_keep_the_window_on_the_screen(window, qtbot):
    """Opening every view and closing them all leaves the window 1600 px wide and on the screen
    (it grew to 1635-1864 px and stayed so), every control of every view inside the screen (the
    PC modes' buttons were past its edge, its slider 19 px wide); with every panel in the
    timeline the y labels are inside the figure and do not overlap."""
    win = window
    screen = win.screen().availableGeometry()
    views = win.extension("analysis")
    widths = []
    for key in VIEWS:
        views.view_actions[key].trigger()
        qtbot.waitUntil(lambda k=key: view_settled(win, k), timeout=WAIT_MS)
        widths.append(win.frameGeometry().width())
        assert screen.contains(win.frameGeometry()), (key, win.frameGeometry())
        for control in views.widgets[key].findChildren((QAbstractButton, QSlider)):
            if control.isVisible():
                right = control.mapToGlobal(control.rect().topRight()).x()
                assert right <= screen.right(), (key, control.text() if hasattr(control, "text") else control)
    assert widths == [SIZE[0]] * len(VIEWS)
    slider = views.widgets["pc_modes"].slider
    views.docks["pc_modes"].raise_()
    qtbot.waitUntil(lambda: slider.isVisible(), timeout=5000)
    assert slider.width() >= 200
    # every panel: the labels legible and apart
    views.show_panels(list(PANELS))
    qtbot.waitUntil(lambda: not win.timeline.building, timeout=WAIT_MS)
    canvas = win.timeline.canvas
    canvas.finish()
    renderer = canvas.get_renderer()
    fig_w, fig_h = canvas.figure.bbox.width, canvas.figure.bbox.height
    boxes = []
    for ax in win.timeline.axes:
        texts = [ax.yaxis.label] if ax.get_ylabel() else list(ax.get_yticklabels())[-1:]
        for text in texts:
            e = text.get_window_extent(renderer)
            assert e.x0 >= 0 and e.y0 >= 0 and e.x1 <= fig_w and e.y1 <= fig_h, text.get_text()
            assert text.get_fontsize() >= 4.5, text.get_text()
            boxes.append((text.get_text(), e))
    for i, (a, ea) in enumerate(boxes):
        for b, eb in boxes[i + 1:]:
            assert not ea.overlaps(eb), (a, b)
    for dock in list(views.docks.values()):
        dock.close()
    qtbot.waitUntil(lambda: not win.timeline.building, timeout=WAIT_MS)
    assert win.frameGeometry().width() == SIZE[0] and screen.contains(win.frameGeometry())


def test_saved_screenshot_shows_each_3d_view_as_the_screen_does(window, qtbot, tmp_path):
    """File > Save screenshot with the PC modes open: the main face and the PC modes' 3-D view in
    the PNG are what the screen shows there, not noise or black (the PC modes' pane was)."""
    win = window
    views = win.extension("analysis")
    views.view_actions["pc_modes"].trigger()
    qtbot.waitUntil(lambda: view_settled(win, "pc_modes"), timeout=WAIT_MS)
    win.activateWindow()
    win.raise_()
    qtbot.wait(300)                                    # the 3-D views painted on the screen
    shot = image_array(QImage(str(win.save_screenshot(tmp_path / "shot.png"))))
    for name, view in (("face", win.plotter.interactor),
                       ("PC modes", views.widgets["pc_modes"].plotter.interactor)):
        saved, screen = place_in(shot, view, win).astype(float), on_screen(view).astype(float)
        assert saved.shape == screen.shape, name
        assert saved.std() > 20, f"{name}: flat (black) in the screenshot"
        assert np.abs(saved - screen).mean() < 6, f"{name}: the screenshot differs from the screen"


def test_the_face_shows_the_mouth_closed_at_a_b_and_the_lip_panels_where_closed_is(window, qtbot,
                                                                                   tmp_path):
    """The original markers of s002 ("The boy ...") with the face surface on them, from the
    front: between the lip centre markers the picture is skin at the /b/ (the surface had a hole
    there) and the dark mouth at the /oy/ after it; the lip panels draw the talker's closed lip
    positions as a reference line."""
    from facetraj_app import style

    win = window
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.set_utterance("s002")
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    win.view_bar.show_synth.setChecked(False)             # the surface follows the original set
    win.view_bar.set_camera("front")
    model, face = win.model, win.face
    phones = {p.label: p for p in win.view.utterance.phones}
    cavity = colour_of(style.CAVITY_COLOR)
    counts = {}
    for label in ("b", "oy"):
        seg = phones[label]
        win.seek((seg.start + seg.end) / 2)
        shot = image_array(QImage(str(win.save_screenshot(tmp_path / f"{label}.png")))).astype(float)
        view = win.plotter.interactor
        pts = face.original.current
        xy = face.project(pts[[model.upper_lip, model.lower_lip]])
        origin = view.mapTo(win, view.rect().topLeft())
        x = origin.x() + int(round(xy[:, 0].mean()))
        y_top = origin.y() + view.height() - int(round(xy[0, 1])) + 8     # under the markers'
        y_bottom = origin.y() + view.height() - int(round(xy[1, 1])) - 8  # dots and lines
        box = shot[y_top:y_bottom, x - 15:x + 15]
        assert box.size, label
        counts[label] = (int((np.linalg.norm(box - cavity, axis=2) < 40).sum()),
                         int((box.min(axis=2) > 245).sum()))           # dark mouth, white hole
    assert counts["b"] == (0, 0), counts
    assert counts["oy"][0] > 30, counts
    closed = win.closed_lips
    for panel, marker in (("upper lip y", model.upper_lip), ("lower lip y", model.lower_lip)):
        ax = win.timeline.axes_of(next(p for p in win.timeline.panels if p.title == panel))
        ys = [line.get_ydata() for line in ax.lines if len(set(line.get_ydata())) == 1]
        assert any(np.allclose(y, closed.markers[marker, 1]) for y in ys), panel


def assert_plots_legible(canvas, what: str) -> None:
    """``canvas``'s figure legible (``screens.assert_legible``), no two boxes even touching."""
    canvas.finish()
    assert_legible(canvas.figure, canvas.get_renderer(), what, overlaps=Bbox.overlaps)


def test_the_views_plots_are_legible_in_their_docks(window, qtbot):
    """Metrics (Table 2 and the N sweep, computed on one utterance per split), errors and PC
    modes docked at 1600 x 1000: no title, label, tick label or legend cut or over another, no
    legend over the bars (the Metrics titles overlapped, its bar labels ran together as "train
    triangspline", its y label was cut, its legend covered bars; the Errors chart's title and x
    label were cut; the PC modes had no y labels); the Table 2 rows need no scrolling, the
    paper's values in rows under ours."""
    win = window
    views = win.extension("analysis")
    for key in ("metrics", "errors", "pc_modes"):
        views.view_actions[key].trigger()
        qtbot.waitUntil(lambda k=key: view_settled(win, k), timeout=WAIT_MS)
    metrics = views.widgets["metrics"]
    views.docks["metrics"].raise_()
    metrics.per_split.setValue(1)
    metrics.max_n.setValue(2)
    with qtbot.waitSignal(metrics.table2Done, timeout=WAIT_MS):
        metrics.run_table2.click()
    with qtbot.waitSignal(metrics.sweepDone, timeout=WAIT_MS):
        metrics.run_sweep.click()
    assert_plots_legible(metrics.canvas, "metrics")
    table = metrics.table
    assert table.verticalScrollBar().maximum() == 0 and table.horizontalScrollBar().maximum() == 0
    assert table.columnCount() == 6
    errors = views.widgets["errors"]
    views.docks["errors"].raise_()
    errors.per_split.setValue(1)
    with qtbot.waitSignal(errors.reportReady, timeout=WAIT_MS):
        errors.run_btn.click()
    assert_plots_legible(errors.phone_chart, "errors")
    pc = views.widgets["pc_modes"]
    views.docks["pc_modes"].raise_()
    qtbot.waitUntil(lambda: pc.canvas.isVisible(), timeout=5000)
    assert_plots_legible(pc.canvas, "PC modes")
    assert pc.ax_face.get_ylabel() and pc.ax_var.get_ylabel()
