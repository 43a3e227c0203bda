"""Issue 39's review, repeated by tests: the window as a phonetician meets it on a 1920x1200 and a
1366x768 screen (each test runs on a private Xvfb of each size: the ``screen`` fixture of
tests/conftest.py), every defect of the review checked on the screen's pixels and the figures'
text extents: legends never over data, phone labels never run together, the mouth shut where the
lips meet (PC modes, side by side, the 3/4 view's far corner), the window on the screen, the Live
window's shutdown in every order, the error view's ranking, Figure 5's label, the markers beside
an opened recording, and the small ones."""

from __future__ import annotations

import os
import subprocess
import sys
from itertools import pairwise

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from conftest import DEFAULT_CORPUS
from PyQt6.QtGui import QImage
from PyQt6.QtWidgets import QAbstractButton, QSlider
from screens import (
    assert_legible,
    face_image,
    image_array,
    middle,
    near,
    overlap,
    pixels_inside,
    project,
    resynthesize,
    screen_window,
    view_settled,
)

from facetraj.paths import shared_path
from facetraj_app import style
from facetraj_app.main import WINDOW_SIZE

pytestmark = pytest.mark.gui

WAIT_MS = 240_000          # a hang guard (a loaded machine is slow), not a speed limit


@pytest.fixture
def win(screen, qtbot, trained_cache):
    """The main window as ``facetraj`` opens it (``place_on_screen``: 1600 x 1000 where the
    screen has room), on the Figure 4 sentence; None when the test runs on its own screen."""
    yield from screen_window(screen, qtbot, wait_ms=WAIT_MS)


def open_view(w, qtbot, key: str):
    views = w.extension("analysis")
    views.view_actions[key].trigger()
    qtbot.waitUntil(lambda: view_settled(w, key), timeout=WAIT_MS)     # the window settled too
    return views.widgets[key]


def between_lips(plotter, markers: np.ndarray, upper: int, lower: int, half_width: int = 5,
                 inset: int = 7) -> np.ndarray:
    """The pixels of the 3-D view between the upper and the lower lip centre markers (clear of
    the markers' dots and the contour lines)."""
    (xu, yu), (xl, yl) = project(plotter, markers[[upper, lower]])
    x = 0.5 * (xu + xl)
    box = np.array([[x - half_width, yu + inset], [x + half_width, yu + inset],
                    [x + half_width, yl - inset], [x - half_width, yl - inset]])
    return pixels_inside(face_image(plotter), box)


# ---------------------------------------------------------------------- 1 and 5: screen, lip panels
def test_the_window_fits_the_screen_and_the_lip_panels_stay_readable_with_docks(screen, win, qtbot):
    """The window opens inside the screen (1366x768: it opened at 1600x1000, its lip panels and
    status bar off screen); with Kinematics and Errors docked the lip panels keep their readable
    height (40 px at 1366x740, under the legend), no legend sits in a panel (the legend row is
    above them), and no two phone or word labels touch, each inside its own segment ("taorn",
    "dowz" were overprinted)."""
    w = win
    free = w.screen().availableGeometry()
    assert free.contains(w.frameGeometry())
    assert (w.width(), w.height()) == (min(WINDOW_SIZE[0], free.width()), min(WINDOW_SIZE[1], free.height()))
    for key in ("kinematics", "errors"):
        view = open_view(w, qtbot, key)
        assert free.contains(w.frameGeometry()), key
        dock = w.extension("analysis").docks[key]
        right = dock.mapToGlobal(dock.rect().topRight()).x()
        for control in view.findChildren((QAbstractButton, QSlider)):
            if control.isVisible():
                assert control.mapToGlobal(control.rect().topRight()).x() <= right + 1, (key, control)
    tl = w.timeline
    tl.canvas.finish()
    names = [p.title for p in tl.shown]
    assert {"phones", "upper lip y", "lower lip y", "lip aperture", "lip error"} <= set(names), names
    for panel in tl.shown:
        ax = tl.axes_of(panel)
        assert ax.get_legend() is None, panel.title
        if panel.title in ("upper lip y", "lower lip y"):
            assert ax.bbox.height >= panel.min_px - 1, (panel.title, ax.bbox.height)
    assert tl.legend_bar.isVisible()
    assert tl.legend_bar.geometry().bottom() <= tl.canvas.geometry().top()
    assert {"original", "synthesized, triangular", "speech frames",
            "closed (the talker's /p b m/)"} <= {e.label for e in tl.legend}
    tier = next(p for p in tl.shown if p.title == "phones")
    for row in tier.labels:
        drawn = sorted(row.drawn, key=lambda d: d[1].x0)
        assert drawn, "no label drawn"
        for (_t, extent, (left, right)) in drawn:
            assert extent.x0 >= left - 1 and extent.x1 <= right + 1, _t
        for (a, ea, _), (b, eb, _) in pairwise(drawn):
            assert ea.x1 <= eb.x0, (a, b)


# ---------------------------------------------------------------------- 2: PC modes
def test_the_pc_explorer_shows_a_closed_mouth_and_says_which_way_opens(screen, win, qtbot):
    """PC1 at the slider's closing end: between the lip centre markers the PC view shows skin,
    no background (the mouth was a see-through hole at -3, 0 and +3 SD); at the opening end the
    dark mouth. The slider's ends say which opens; the value has its unit."""
    pc = open_view(win, qtbot, "pc_modes")
    win.extension("analysis").docks["pc_modes"].raise_()
    qtbot.waitUntil(lambda: pc.plotter.interactor.isVisible(), timeout=5000)
    pc.set_component(0)
    ends = (pc.minus_label.text(), pc.plus_label.text())
    assert sorted(e.split("·")[-1].strip() for e in ends) == ["closes", "opens"], ends
    closing = 3.0 if "closes" in ends[1] else -3.0
    pc.set_camera("front")
    model = win.model
    counts = {}
    for sds in (closing, -closing):
        pc.set_sd_units(sds)
        box = between_lips(pc.plotter, pc.displaced_points(), model.upper_lip, model.lower_lip)
        assert box.size
        counts[sds] = (near(box, style.BACKGROUND, 30), near(box, style.CAVITY_COLOR, 12))   # not the arrows
        assert "mm" in pc.value_label.text() and "SD" in pc.value_label.text()
    assert counts[closing] == (0, 0), counts
    assert counts[-closing][0] == 0 and counts[-closing][1] > 10, counts
    pc.set_sd_units(closing)
    assert "lips closed" in pc.value_label.text()


# ---------------------------------------------------------------------- 3 and the ¾ view's corner
def test_side_by_side_both_faces_have_their_surface_and_close(screen, win, qtbot):
    """s002 at the /b/ of "boy", side by side: the original face has its surface and lips (it
    had points only) and its mouth is shut, like the synthesized face beside it; no face shows
    the background through its mouth."""
    w = win
    resynthesize(w, qtbot, lambda: w.set_utterance("s002"), WAIT_MS)
    w.view_bar.side_by_side.setChecked(True)
    w.view_bar.set_camera("front")
    w.seek(middle(w, "b"))
    w.face.rerender()
    model, face = w.model, w.face
    for mset in (face.original, face.synth):
        assert mset.surface_actor.GetVisibility() and mset.line_actor.GetVisibility(), mset.name
        box = between_lips(w.plotter, mset.current, model.upper_lip, model.lower_lip)
        assert near(box, style.BACKGROUND, 30) == 0, mset.name
    closed = between_lips(w.plotter, face.original.current, model.upper_lip, model.lower_lip)
    assert near(closed, style.CAVITY_COLOR) == 0                   # the original lips meet at /b/
    image = face_image(w.plotter)
    for mset in (face.original, face.synth):                       # both faces have skin
        xy = project(w.plotter, mset.current)
        # around the face's middle (the cameras fit the faces to the view's height: its
        # forehead marker is at the top edge, where a box around it is mostly background)
        centre = xy.mean(axis=0)
        assert near(pixels_inside(image, centre + np.array([[-40, -40], [40, -40], [0, 40]])),
                    style.SURFACE_COLOR, 70) > 50, mset.name


def test_the_open_mouth_has_no_see_through_corner_in_the_three_quarter_view(screen, win, qtbot):
    """s002's /oy/, the synthesized face alone in the 3/4 view: inside the mouth opening's outline
    every pixel is the dark mouth or skin, none the background (a sliver at the far corner was)."""
    w = win
    resynthesize(w, qtbot, lambda: w.set_utterance("s002"), WAIT_MS)
    w.view_bar.show_original.setChecked(False)
    w.view_bar.set_camera("three-quarter")
    w.seek(middle(w, "oy"))
    w.face.rerender()
    mset = w.face.synth
    mouth = mset.mouth
    edge = np.vstack([mset.current, mouth.points(mset.current)])[mouth.opening_loop(len(mset.current))]
    inside = pixels_inside(face_image(w.plotter), project(w.plotter, edge))
    assert len(inside) > 30
    assert near(inside, style.BACKGROUND, 30) == 0
    assert near(inside, style.CAVITY_COLOR) > 10


# ---------------------------------------------------------------------- 4: Live shutdown
LIVE_SCRIPT = r"""
import sys
from PyQt6.QtCore import QTimer
from PyQt6.QtWidgets import QApplication
app = QApplication(sys.argv[:1])
from facetraj_app.main import build_window
win = build_window(sys.argv[1], use_audio=False)
win.set_correlation_sweep(False)
win.show()
order = sys.argv[2]
live = win.extension("live")

def toggle(on):
    live.action.setChecked(on)
    print("live window:", live.live is not None, "toggle:", live.action.isChecked(), flush=True)

def steps():
    if win.model is None or win.view is None:
        QTimer.singleShot(100, steps)
        return
    toggle(True)
    if order == "close-live-first":
        live.live.close()                        # its close button
        app.processEvents()
        print("after closing it: toggle", live.action.isChecked(), flush=True)
    elif order == "toggle-off-and-on":
        toggle(False)
        toggle(True)
    QTimer.singleShot(300, win.close)            # File > Quit

QTimer.singleShot(0, steps)
app.exec()
print("exited", flush=True)
"""


@pytest.mark.parametrize("order", ["quit-with-live-open", "close-live-first", "toggle-off-and-on"])
def test_quitting_with_the_live_window_in_every_order_exits_cleanly(screen, trained_cache, order):
    """The app quits with status 0 and no error whichever way the Live window was closed (it hung
    and then aborted with "wrapped C/C++ object of type QAction has been deleted", exit 134), and
    the Live toggle follows the window (it stayed checked after the window's close button)."""
    run = subprocess.run([sys.executable, "-c", LIVE_SCRIPT, str(DEFAULT_CORPUS), order],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    assert "exited" in run.stdout
    for bad in ("Traceback", "RuntimeError", "wrapped C/C++"):
        assert bad not in run.stderr, run.stderr[-3000:]
    assert "live window: True toggle: True" in run.stdout
    if order == "close-live-first":
        assert "after closing it: toggle False" in run.stdout


# ---------------------------------------------------------------------- 6 and 7: the analysis docks
def test_the_error_view_ranks_phones_by_rms_error_with_frame_counts(screen, win, qtbot):
    """Errors docked, computed on four test utterances: the phones worst first by RMS lip error
    in mm (a correlation over a held closure's 14 frames ranked /m/ worst), the correlation left
    empty under 30 frames, the chart's bars in the same order with each phone's frame count, and
    every text of the chart legible."""
    from facetraj_engine.analysis.errors import MIN_CORRELATION_FRAMES

    errors = open_view(win, qtbot, "errors")
    errors.per_split.setValue(4)                 # 34 phones: more bars than a short dock has rows
    with qtbot.waitSignal(errors.reportReady, timeout=WAIT_MS):
        errors.run_btn.click()
    table = errors.phone_table
    rms = [table.item(r, 1).value for r in range(table.rowCount())]
    assert rms == sorted(rms, reverse=True)
    for r in range(table.rowCount()):
        if table.item(r, 2).value < MIN_CORRELATION_FRAMES:
            assert table.item(r, 4).text() == ""
    chart = errors.phone_chart
    chart.finish()
    labels = chart.figure.axes[0].get_yticklabels()
    ticks = [t.get_text() for t in labels]
    worst, second = errors.report.phones[:2]
    assert ticks[-1] == f"{worst.phone} ({worst.frames})"
    # every bar labelled, at 7 pt or more (issue 49: every other bar at about 6 px on a laptop,
    # the 2nd-worst phone without one): the chart scrolls in the dock instead
    assert all(ticks) and ticks[-2] == f"{second.phone} ({second.frames})"
    assert min(t.get_fontsize() for t in labels) >= 7.0
    assert_legible(chart.figure, chart.get_renderer(), "errors")


def test_figure_5_is_whole_in_the_metrics_dock(screen, win, qtbot):
    """Metrics docked with Table 2 (its acoustic-only rows too: eight conditions) and the N sweep
    computed: Figure 5's x label lies inside the part of the dock on the screen (it was cut off),
    its legend above the plot, every text apart (Table 2's tick labels ran together at
    1366x768), and each plot at least 100 px tall (Figure 5 was about 30 px)."""
    metrics = open_view(win, qtbot, "metrics")
    metrics.per_split.setValue(1)
    metrics.max_n.setValue(2)
    with qtbot.waitSignal(metrics.table2Done, timeout=WAIT_MS):
        metrics.run_table2.click()
    with qtbot.waitSignal(metrics.sweepDone, timeout=WAIT_MS):
        metrics.run_sweep.click()
    qtbot.waitUntil(lambda: view_settled(win, "metrics"), timeout=WAIT_MS)
    canvas = metrics.canvas
    canvas.finish()
    renderer = canvas.get_renderer()
    assert_legible(canvas.figure, renderer, "metrics")
    figure5 = canvas.figure.axes[1]
    assert len(metrics.rows) == 8
    ratio = canvas.devicePixelRatioF()
    assert min(ax.bbox.height / ratio for ax in canvas.figure.axes[:2]) >= 100
    label = figure5.xaxis.label.get_window_extent(renderer)
    height = canvas.height()
    top_left = canvas.mapToGlobal(canvas.rect().topLeft())
    y_top = top_left.y() + height - label.y1 / ratio
    y_bottom = top_left.y() + height - label.y0 / ratio
    viewport = win.extension("analysis").docks["metrics"].widget().viewport()
    vp_top = viewport.mapToGlobal(viewport.rect().topLeft()).y()
    assert vp_top <= y_top and y_bottom <= vp_top + viewport.height(), (y_top, y_bottom, vp_top,
                                                                        viewport.height())
    assert not overlap(figure5.get_legend().get_window_extent(renderer), figure5.bbox)


# ---------------------------------------------------------------------- 8: markers beside
def test_a_recording_opened_with_markers_beside_shows_them(screen, win, qtbot):
    """Opening data_samples/s002.flac: its s002.c3d beside it is read as the original markers
    (the blue points and curves, the same as the corpus utterance's); MOCHA's fsew0_001.wav (when
    ../shared has it): its .ema holds other markers, and a note over the panels says so and offers
    the import (it was ignored)."""
    w = win
    with qtbot.waitSignal(w.synthesisChanged, timeout=WAIT_MS):
        assert w.open_audio(DEFAULT_CORPUS / "s002.flac")
    qtbot.waitUntil(lambda: w.settled and w.view.split == "external", timeout=WAIT_MS)
    corpus_utt = w.corpus.utterance("s002")
    assert w.view.original is not None
    np.testing.assert_allclose(w.view.original, w.model.normalise_markers(corpus_utt.markers)[
        :len(w.view.original)], equal_nan=True)
    assert w.view_bar.show_original.isEnabled() and w.view_bar.show_original.isChecked()
    mocha = shared_path("data/mocha_fsew0_001/fsew0_001.wav")
    if not mocha.exists():
        return
    with qtbot.waitSignal(w.synthesisChanged, timeout=WAIT_MS):
        assert w.open_audio(mocha)
    qtbot.waitUntil(lambda: w.settled and w.notice.isVisible(), timeout=WAIT_MS)
    text = w.notice.text.text()
    assert "fsew0_001.ema" in text and "Import" in text and w.view.original is None
    assert w.notice.button.isVisible() and "Import" in w.notice.button.text()
    assert w.frameGeometry().width() <= w.screen().availableGeometry().width()


# ---------------------------------------------------------------------- 9: the small ones
def test_save_screenshot_says_where_it_wrote(screen, win, qtbot, tmp_path, monkeypatch):
    import facetraj_app.main_window as main_window

    out = tmp_path / "shot.png"
    monkeypatch.setattr(main_window, "ask_screenshot_path", lambda parent: (out,))
    win.action_screenshot.trigger()
    assert out.exists() and QImage(str(out)).width() == win.width()
    assert win.status_label.text() == f"wrote {out}" or f"wrote {out}" in win.statusBar().currentMessage()


def test_exported_figure_is_the_screen_with_a_caption(screen, win, qtbot, tmp_path):
    """File > Export the panels as a figure: the window's panels (the same curves, closed lines,
    speech dots and phones) under a caption naming the utterance, its labels and its settings,
    the legend between them: caption, legend and panels apart, the legend over no panel."""
    from facetraj_app.own_data import export_figure
    from facetraj_app.screen_export import caption_text, panels_figure

    w = win
    out = export_figure(w, tmp_path / "panels.png")
    image = image_array(QImage(str(out)))
    assert image.shape[1] >= 640 and image.std() > 20
    tl = w.timeline
    fig, layout = panels_figure(list(tl.panels), w.view, (tl.width(), 900), xlim=tl.xlim(),
                                cursor=w.current_time(), caption=caption_text(w.view))
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = layout.boxes(renderer)
    caption = layout.caption.get_text().replace("\n", " ")
    assert "s001" in caption and "labels: label file s001.TextGrid" in caption
    assert "phonetic" in caption and "N=3" in caption
    assert boxes["caption"].y0 >= boxes["legend"].y1 - 1
    for ax in layout.axes:
        assert not overlap(boxes["legend"], ax.bbox) and ax.get_legend() is None
        assert ax.bbox.y1 <= boxes["legend"].y0 + 1
    assert {"original", "speech frames", "closed (the talker's /p b m/)"} <= \
        {t.get_text() for t in layout.legend.get_texts()}
    assert [p.title for p in layout.shown] == [p.title for p in tl.panels]


def test_the_live_window_follows_the_rules(screen, qtbot, default_model, default_corpus, tmp_path):
    """The Live window on the screen: inside it, its legend above the lip panels (it covered the
    curve), the talker's closed lips as a dashed line in both panels, and a file's whole name in
    its input box ("file: cmu" was all it showed)."""
    from facetraj_app.live import LIVE_SIZE, LiveWindow
    from facetraj_app.window_frame import fit_to_screen
    from facetraj_engine.analysis.lips import closed_lips
    from facetraj_engine.io.audio import write_audio

    utt = default_corpus.utterance("s002")
    wav = tmp_path / "cmu_arctic_us_aew_a0001_boy.wav"
    write_audio(wav, utt.audio, utt.sample_rate)
    window = LiveWindow(default_model, None, None, block_s=0.05, fast=True, phones=False)
    qtbot.addWidget(window)
    fit_to_screen(window, LIVE_SIZE)
    window.show()
    qtbot.waitExposed(window)
    with qtbot.waitSignal(window.takeFinished, timeout=WAIT_MS):
        assert window.open_recording(wav)
    assert window.screen().availableGeometry().contains(window.frameGeometry())
    box = window.device_box
    assert box.currentText() == f"file: {wav.name}"
    assert box.width() >= box.fontMetrics().horizontalAdvance(box.currentText()) + 16
    window.canvas.draw()
    renderer = window.canvas.get_renderer()
    legend = window.legend.get_window_extent(renderer)
    closed = closed_lips(default_model).markers
    for ax, k in zip(window.axes, (default_model.upper_lip, default_model.lower_lip), strict=True):
        assert not overlap(legend, ax.bbox)
        flat = [line for line in ax.lines if len(set(np.asarray(line.get_ydata(), float))) == 1]
        assert any(np.isclose(line.get_ydata()[0], closed[k, 1]) for line in flat)
    assert {"closed (the talker's /p b m/)", "speech frames (live energy)"} <= \
        {t.get_text() for t in window.legend.get_texts()}
    window.close()


def test_live_without_a_microphone_says_one_line(screen, trained_cache):
    """``facetraj live -q`` without an input device: its one-line error and nothing else (a dozen
    qt.multimedia lines came first)."""
    from facetraj_app.live_input import input_devices

    if input_devices():
        pytest.skip("this machine has an audio input device")
    run = subprocess.run([sys.executable, "-m", "facetraj", "live", "-q"], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 2
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("facetraj: error: no audio input device"), lines
