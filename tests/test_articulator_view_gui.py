"""The articulator view (issue 47), in a real window under Xvfb: articulograph sensors drawn as
articulators -- the tongue a curve through its sensors, lips with their aperture, the jaw, the
reference sensors faint, no skin -- on the MOCHA-TIMIT sample (2-D) and on an MVIEW file in HPRC's
layout made from it (3-D); Measure, pins, the PC modes in profile, the error view's labels,
kinematics and the video on such a model."""

from __future__ import annotations

import json
import os
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("pytestqt")
if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from articulograph import mview_from_mocha
from conftest import MOCHA, shown_corpus_window
from PyQt6.QtGui import QImage
from screens import (
    assert_placed_as_in,
    colour_of,
    face_image,
    image_array,
    near,
    place_in,
    project,
    resynthesize,
)

from facetraj_app import style
from facetraj_app.articulators import REFERENCE_COLOR, ArticulatorSet
from facetraj_engine.analysis.articulators import jaw_top, measure, tongue_curve
from facetraj_engine.io.corpus import init_corpus

if not (MOCHA / "fsew0_001.ema").exists():
    pytest.skip("the MOCHA sample ../shared/data/mocha_fsew0_001 is absent", allow_module_level=True)

pytestmark = pytest.mark.gui
WAIT_MS = 240_000   # a hang guard (a loaded machine is slow), not a speed limit
#: the aim: fewer skin-coloured pixels than this in the 3-D area (a face surface had ~10,000)
SKIN_BAR = 1000
SET_COLOURS = (style.ORIGINAL_COLOR, style.SYNTH_COLOR)


@pytest.fixture(scope="module")
def corpora(tmp_path_factory):
    """The MOCHA sample as a corpus (read in place) and a folder of one MVIEW file made from it."""
    root = tmp_path_factory.mktemp("ema_gui")
    mocha, _ = init_corpus(MOCHA, root / "mocha" / "corpus.json", ["UI", "BN"], "UL", "LL",
                           label_map="mocha", test_fraction=0)
    mview = mview_from_mocha(MOCHA, root / "mview").parent
    path, _ = init_corpus(mview, upper_lip="UL", lower_lip="LL", test_fraction=0)
    return {"mocha": mocha, "mview": path}


def three_d_area(win, tmp_path) -> np.ndarray:
    """The 3-D view's part of the window's screenshot (File > Save screenshot, what
    ``facetraj --screenshot`` writes)."""
    shot = image_array(QImage(str(win.save_screenshot(tmp_path / "window.png"))))
    return place_in(shot, win.face, win)


def colours_near(area: np.ndarray, xy: np.ndarray, radius: int = 4) -> np.ndarray:
    """The pixels of ``area`` within ``radius`` of the point ``xy`` (x right, y down)."""
    x, y = int(round(xy[0])), int(round(xy[1]))
    return area[max(y - radius, 0):y + radius + 1, max(x - radius, 0):x + radius + 1].reshape(-1, 3)


def drawn_in(area, xy, colours=SET_COLOURS, tol=60.0) -> bool:
    return any(near(colours_near(area, xy), c, tol) > 0 for c in colours)


def window_on(qtbot, monkeypatch, path, t=1.0):
    """The window on the corpus at ``path`` as ``facetraj gui --screenshot`` shows it (1600 x
    1000 where the screen has room), at ``t`` seconds."""
    from facetraj_app.main import WINDOW_SIZE

    win = shown_corpus_window(qtbot, path, monkeypatch, WAIT_MS)
    win.set_correlation_sweep(False)
    win.place_on_screen(WINDOW_SIZE)
    win.seek(t)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    return win


@pytest.mark.parametrize("which", ["mview", "mocha"])
def test_articulators_not_a_face(which, corpora, qtbot, monkeypatch, tmp_path, capsys):
    """The aim, for an MVIEW folder (HPRC's sensors, 3-D) and the MOCHA sample (2-D): no skin in
    the 3-D area, the tongue a curve through its sensors tip to rear, lips (with the aperture)
    and jaw drawn, original and synthesized told apart."""
    win = window_on(qtbot, monkeypatch, corpora[which])
    face, roles = win.face, win.model.roles
    assert face.articulators and isinstance(face.synth, ArticulatorSet)
    assert face.preset == "profile" and not win.view_bar.surface.isEnabled()
    assert "articulograph" in win.dimensions_label.text() and win.dimensions_label.isVisible()
    tongue = [roles.names[i] for i in roles.tongue]
    assert tongue == (["TT", "TB", "TR"] if which == "mview" else ["TT", "TB", "TD"])
    area = three_d_area(win, tmp_path)
    skin = near(area.reshape(-1, 3), style.SURFACE_COLOR, 40)
    with capsys.disabled():
        print(f"\n{which}: {skin} skin-coloured pixels in the 3-D area ({area.shape[1]}x{area.shape[0]})")
    assert skin < SKIN_BAR
    k = face.frame
    for mset, frames in ((face.synth, win.view.shown), (face.original, win.view.original)):
        pts = frames[k]
        curve = mset.tongue_points()                 # through TT, TB, TR (TD) in that order
        np.testing.assert_allclose(curve[::12], pts[list(roles.tongue)], atol=1e-9)
        if which == "mocha":
            assert np.abs(curve[:, 0]).max() < 1e-9      # 2-D: in the midsagittal plane
        # drawn: halfway along the curve between the sensors, the lips and the aperture between
        # them, the jaw
        where = [curve[6], curve[18], pts[roles.upper_lip], pts[roles.lower_lip],
                 (pts[roles.upper_lip] + pts[roles.lower_lip]) / 2, pts[roles.jaw[0]]]
        for name, xy in zip(["tongue", "tongue", "UL", "LL", "aperture", "jaw"],
                            project(win.plotter, np.array(where)), strict=True):
            assert drawn_in(area, xy), (mset.name, name)
    # told apart: each in its colour, overlaid; side by side, each sensor set in its own
    assert near(area.reshape(-1, 3), style.ORIGINAL_COLOR, 40) > 100
    assert near(area.reshape(-1, 3), style.SYNTH_COLOR, 40) > 100
    win.view_bar.side_by_side.setChecked(True)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    area = three_d_area(win, tmp_path)
    tip = roles.tongue[0]
    for mset, colour, other in ((face.synth, style.SYNTH_COLOR, style.ORIGINAL_COLOR),
                                (face.original, style.ORIGINAL_COLOR, style.SYNTH_COLOR)):
        xy = project(win.plotter, mset.current[tip][None])[0]
        assert drawn_in(area, xy, (colour,)) and not drawn_in(area, xy, (other,), 40), mset.name
    if which == "mocha":                      # the reference sensors: small and grey
        ui = project(win.plotter, face.original.current[[roles.names.index("UI")]])[0]
        pix = colours_near(area, ui, 3)
        assert near(pix, REFERENCE_COLOR, 30) > 0 and not any(near(pix, c, 60) for c in SET_COLOURS)
    win.close()


def test_skin_without_the_tongue_role(corpora, qtbot, monkeypatch, tmp_path, capsys):
    """The control: the same sensors declared not to be articulators (``sensor_roles`` in
    corpus.json: no tongue) are drawn as a face, whose surface the count sees."""
    obj = json.loads(corpora["mview"].read_text())
    obj.update(sensor_roles={"tongue": []}, data_dir=str(corpora["mview"].parent))
    (tmp_path / "face").mkdir()
    (tmp_path / "face" / "corpus.json").write_text(json.dumps(obj))
    win = window_on(qtbot, monkeypatch, tmp_path / "face")
    assert not win.face.articulators
    skin = near(three_d_area(win, tmp_path).reshape(-1, 3), style.SURFACE_COLOR, 40)
    with capsys.disabled():
        print(f"\nthe same sensors as a face: {skin} skin-coloured pixels in the 3-D area")
    assert skin > 3 * SKIN_BAR
    win.close()


def test_measure_and_pins_on_articulators(corpora, qtbot, monkeypatch):
    win = window_on(qtbot, monkeypatch, corpora["mview"])
    roles = win.model.roles
    k = win.face.frame
    syn = measure(win.view.shown[k], roles, jaw_top(win.model))
    org = measure(win.view.original[k], roles, jaw_top(win.model))
    text = win.extension("measure").readout.text()
    assert f"tongue tip (TT) height {syn.tongue_tip:.1f} mm (original {org.tongue_tip:.1f} mm" in text
    assert f"lip aperture {syn.aperture:.1f} mm" in text
    assert f"jaw opening {syn.jaw_opening:.1f} mm (original {org.jaw_opening:.1f} mm" in text
    # a pin: its articulators beside the current ones, in its colour, and in the readout
    win.extension("compare").pin()
    resynthesize(win, qtbot, lambda: win.set_synth_config(win.synth_config.with_(n_context_phones=1)))
    pin = win.pins.shown(win.view)[0]
    assert isinstance(win.face._pin_sets[pin.color], ArticulatorSet)
    assert "pin 1" in win.extension("measure").readout.text()
    win.close()


def test_pc_modes_of_an_ema_model_in_profile(corpora, qtbot, monkeypatch):
    """PC modes of an EMA corpus as articulators move: the midsagittal profile, the displaced
    tongue curve drawn from the mode's shape."""
    win = window_on(qtbot, monkeypatch, corpora["mocha"])
    views = win.extension("analysis")
    views.open_view("pc_modes")
    qtbot.waitUntil(lambda: "pc_modes" in views.widgets and views.widgets["pc_modes"].is_ready,
                    timeout=WAIT_MS)
    pcs = views.widgets["pc_modes"]
    assert isinstance(pcs.face_set, ArticulatorSet)
    assert pcs.projection.currentText() == "profile (z-y)"
    pcs.set_sd_units(2.0)
    qtbot.waitUntil(lambda: not pcs.canvas.busy, timeout=WAIT_MS)
    pcs.canvas.finish()
    shape = win.model.mode_shape(0, pcs.value)
    expected = tongue_curve(shape[list(win.model.roles.tongue)])
    np.testing.assert_allclose(pcs.profile.tongue.get_xdata(), expected[:, 2])
    np.testing.assert_allclose(pcs.face_set.tongue_points(), expected)
    views.open_view("kinematics")                       # kinematics work on an EMA model
    qtbot.waitUntil(lambda: "kinematics" in views.widgets and win.settled, timeout=WAIT_MS)
    win.close()


def test_metrics_view_per_sensor_tab(corpora, qtbot, monkeypatch, tmp_path):
    """The metrics view's per-sensor table: r and RMSE of every coordinate, the method and the
    baselines side by side, as the engine pools them; its CSV."""
    import csv

    win = window_on(qtbot, monkeypatch, corpora["mocha"])
    views = win.extension("analysis")
    views.open_view("metrics")
    qtbot.waitUntil(lambda: "metrics" in views.widgets, timeout=WAIT_MS)
    m = views.widgets["metrics"]
    with qtbot.waitSignal(m.table2Done, timeout=WAIT_MS):
        m.start_table2()
    table = m.sensor_table
    head = [table.horizontalHeaderItem(c).text() for c in range(table.columnCount())]
    assert head[2:] == ["phonetic N=3\nr", "phonetic N=3\nRMSE mm", "acoustic N=3\nr",
                        "acoustic N=3\nRMSE mm", "viseme\nr", "viseme\nRMSE mm", "ridge\nr",
                        "ridge\nRMSE mm"]
    names = [table.item(r, 0).text() for r in range(table.rowCount())]
    assert names[:3] == ["whole face", "lower lip y", "upper lip y"] and names[-1] == "articulators (mean)"
    tt = m.table2_result.sensor_table("train", "triangular", "phonetic", 3).row("TT y")
    row = names.index("TT y")
    assert table.item(row, 1).text() == "tongue"
    assert table.item(row, 2).text() == f"{tt.r:.3f}" and table.item(row, 3).text() == f"{tt.rmse_mm:.2f}"
    with open(m.export_sensor_csv(tmp_path / "s.csv"), newline="") as fh:
        rows = {r["row"]: r for r in csv.DictReader(fh)}
    assert float(rows["TT y"]["phonetic N=3 rmse_mm"]) == pytest.approx(tt.rmse_mm, rel=1e-5)
    win.close()


def test_worst_segment_labels_never_overprint(corpora, qtbot, monkeypatch):
    """The lip-error panel's worst segments close together (the issue: "sp 9.4", "L", "AE" and
    "9.9" printed over one another near 2.0 s): each label whole and apart; silences ("sp",
    "SIL") never among the worst."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from facetraj_app.analysis.errors_view import LipErrorPanel
    from facetraj_engine.data import PhoneSegment

    win = window_on(qtbot, monkeypatch, corpora["mview"])
    view = win.view
    phones = [PhoneSegment(0.0, 1.95, "SIL"), PhoneSegment(1.95, 1.99, "sp"),
              PhoneSegment(1.99, 2.03, "L"), PhoneSegment(2.03, 2.07, "AE"),
              PhoneSegment(2.07, 2.11, "N"), PhoneSegment(2.11, view.duration, "SIL")]
    original = view.synthesis.markers.copy()
    errors = {"sp": 9.4, "L": 9.9, "AE": 8.0, "N": 7.0}
    for p in phones:
        frames = (view.times >= p.start) & (view.times < p.end)
        original[frames, win.model.lower_lip, 1] += errors.get(p.label, 0.5)
    fake = SimpleNamespace(original=original, synthesis=view.synthesis, times=view.times,
                           utterance=SimpleNamespace(phones=phones, name="u"))
    fig = Figure(figsize=(6, 1.2), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.set_xlim(0, view.duration)
    panel = LipErrorPanel(win.model)
    panel.draw(ax, fake)
    fig.canvas.draw()
    assert [s.label for s in panel.last_segments] == ["L", "AE", "N"]
    drawn = panel.labels.drawn
    assert [d[0] for d in drawn] == ["L 5.0", "AE 4.0", "N 3.5"]
    boxes = [d[1] for d in drawn]
    for i, a in enumerate(boxes):
        assert ax.bbox.x0 <= a.x0 and a.x1 <= ax.bbox.x1 and ax.bbox.y0 <= a.y0
        for b in boxes[i + 1:]:
            assert a.x1 <= b.x0 or b.x1 <= a.x0 or a.y1 <= b.y0 or b.y1 <= a.y0, (a, b)
    win.close()


def test_video_frame_of_articulators(corpora, qtbot, monkeypatch):
    from facetraj_app.video import VideoFrames, VideoSettings

    win = window_on(qtbot, monkeypatch, corpora["mocha"])
    view = win.view
    frames = VideoFrames(win.model, view.synthesis, view.original, view.utterance.phones,
                         VideoSettings(1280, 544), view=view)
    try:
        img = frames.frame(1.0)
        x0, y0, x1, y1 = frames.layout.scene
        scene = img[y0:y1, x0:x1].reshape(-1, 3)
    finally:
        frames.close()
    assert isinstance(frames.scene.synth, ArticulatorSet)      # the window's scene (FaceScene)
    assert near(scene, style.SURFACE_COLOR, 40) < SKIN_BAR
    assert near(scene, style.SYNTH_COLOR, 40) > 50 and near(scene, style.ORIGINAL_COLOR, 40) > 50
    win.close()


@pytest.mark.parametrize("which", ["mview", "mocha"])
def test_the_close_up_of_articulators_shows_their_lips(which, corpora, qtbot, monkeypatch, tmp_path,
                                                       capsys):
    """Issue 49's close-up of the lips (the window's ``FaceScene``) on articulators, side by side:
    each set's lip sensors alone (the upper and lower lip and the aperture line between them;
    no tongue, no jaw), in profile in the parallel projection, the aperture taller on screen than
    in the whole articulators' profile; back to the profile, the articulators whole again."""
    win = window_on(qtbot, monkeypatch, corpora[which])
    face, roles = win.face, win.model.roles
    win.view_bar.side_by_side.setChecked(True)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    lips = [roles.upper_lip, roles.lower_lip]

    def apertures() -> list[float]:
        face.rerender()
        return [float(np.ptp(project(win.plotter, m.current[lips])[:, 1]))
                for m, shown in face.face_sets() if shown]

    whole = apertures()
    win.view_bar.set_camera("lips")
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    close = apertures()
    with capsys.disabled():
        print(f"\n{which}: the aperture on screen {max(whole):.0f} px whole, {min(close):.0f} px in the "
              "close-up")
    assert len(close) == 2 and min(close) >= 1.2 * max(whole), (whole, close)
    cam = win.plotter.camera
    assert cam.GetParallelProjection() and np.allclose(cam.direction, (1.0, 0.0, 0.0))
    area = three_d_area(win, tmp_path)
    for mset, colour in ((face.synth, style.SYNTH_COLOR), (face.original, style.ORIGINAL_COLOR)):
        assert isinstance(mset, ArticulatorSet)
        pts = mset.current
        up, low = project(win.plotter, pts[lips])
        for name, xy in (("UL", up), ("LL", low), ("aperture", (up + low) / 2)):
            assert drawn_in(area, xy, (colour,)), (mset.name, name)
        tongue = mset.tongue_points()
        hidden = [tongue[6], tongue[18], pts[roles.jaw[0]]]
        for name, xy in zip(["tongue", "tongue", "jaw"], project(win.plotter, np.array(hidden)),
                            strict=True):
            assert not drawn_in(area, xy, (colour,), 40), (mset.name, name)
    win.view_bar.set_camera("profile")
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    assert apertures() == pytest.approx(whole, abs=1.0)
    area = three_d_area(win, tmp_path)
    curve = face.synth.tongue_points()
    assert drawn_in(area, project(win.plotter, curve[[6]])[0], (style.SYNTH_COLOR,))
    win.close()


def test_the_video_of_articulators_is_what_the_screen_shows(corpora, qtbot, monkeypatch):
    """Issue 49's video of the screen on articulators: side by side with a pin and the view
    zoomed in by the user, the video's 3-D half draws the articulators (no skin) in the window's
    parallel projection and its zoom (as wide a view: the scale of a narrower one widened), each
    set where the window has it (the original left of the synthesis, the pin's beside)."""
    import facetraj_app.own_data as own_data
    from facetraj_app.video import VideoFrames

    win = window_on(qtbot, monkeypatch, corpora["mview"])
    win.view_bar.side_by_side.setChecked(True)
    win.extension("compare").pin()
    resynthesize(win, qtbot, lambda: win.set_synth_config(win.synth_config.with_(n_context_phones=1)))
    win.seek(1.0)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    win.plotter.camera.zoom(1.25)                  # the wheel's zoom: a smaller parallel scale
    caption, screen = own_data.screen_of(win)
    video = VideoFrames(win.model, win.view.synthesis, view=win.view, pins=win.pins,
                        caption=caption, screen=screen)
    try:
        img = video.frame(1.0)
        x0, y0, x1, y1 = video.layout.scene
        scene = img[y0:y1, x0:x1]
        sets = [m for m, shown in video.scene.face_sets() if shown]
        state = video.scene.camera_state()
    finally:
        video.close()
    assert len(sets) == 3 and all(isinstance(m, ArticulatorSet) for m in sets)
    mine = win.face.camera_state()
    assert mine[5] is not None and state[5] is not None          # both parallel projections
    np.testing.assert_allclose(np.array(state[:3]), np.array(mine[:3]), atol=1e-6)
    assert state[5] == pytest.approx(mine[5] * max(1.0, mine[4] / state[4]), rel=1e-6)
    assert near(scene.reshape(-1, 3), style.SURFACE_COLOR, 40) < SKIN_BAR
    win.face.rerender()
    window = face_image(win.plotter)
    pin = win.pins.pins[0]
    assert_placed_as_in(window, scene, [style.ORIGINAL_COLOR, style.SYNTH_COLOR, pin.color])
    win.close()


def test_colours_of_the_sets_are_apart():
    """Original, synthesized, reference and skin: colours the counts above can tell apart."""
    cols = [colour_of(c) for c in (*SET_COLOURS, REFERENCE_COLOR, style.SURFACE_COLOR)]
    assert min(np.linalg.norm(a - b) for i, a in enumerate(cols) for b in cols[i + 1:]) > 80
