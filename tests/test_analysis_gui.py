"""The analysis views in a real window (run under Xvfb): each opens on the default corpus and shows
the engine's numbers; the PC slider moves the points by eigenvector x value; the inspector's
weights sum to 1; landmarks on a synthetic trajectory land within one frame of the truth; the views
installed in the main window.

The default corpus is ``data_samples/`` (or ``$FACETRAJ_CORPUS``); while it is not built the
tests run on the toy corpus instead, so that the views are still exercised.
"""

from __future__ import annotations

import math
import os
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the GUI tests need an X display (run under xvfb-run)", allow_module_level=True)

from facetraj_engine.analysis.common import subset_corpus
from facetraj_engine.analysis.errors import error_report
from facetraj_engine.analysis.metrics import sweep_curves, table2_rows
from facetraj_engine.analysis.pc_modes import describe_mode
from facetraj_engine.analysis.similarity import cluster_phones
from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment
from facetraj_engine.evaluation.scores import sweep_n, table2
from facetraj_engine.method.similarity import top_similar

pytestmark = pytest.mark.gui
WAIT_MS = 240_000   # a hang guard (a loaded machine is slow), not a speed limit


@pytest.fixture(scope="module")
def corpus(default_corpus):
    return default_corpus


@pytest.fixture(scope="module")
def model(default_model):
    return default_model


@pytest.fixture(scope="module")
def view(model, corpus):
    from facetraj_app.state import build_view

    utt = corpus.utterance(corpus.info.test[0])
    return build_view(model, utt, "test", SynthConfig())


def cell_values(table, col: int) -> list[float]:
    return [table.item(r, col).value for r in range(table.rowCount())]


# ---------------------------------------------------------------------- similarity
def test_similarity_view_shows_engine_matrix(qtbot, model, tmp_path):
    from facetraj_app.analysis.similarity_view import SimilarityView

    w = SimilarityView(model)
    qtbot.addWidget(w)
    with qtbot.waitSignal(w.ready, timeout=WAIT_MS):      # clustered in the background
        w.show()
    qtbot.waitExposed(w)
    order = cluster_phones(model).order
    k = len(order)
    assert w.table.rowCount() == k and w.table.columnCount() == k + 1
    labels = [w.table.item(r, 0).text() for r in range(k)]
    assert labels == [model.phones[i] for i in order]

    def shown() -> np.ndarray:
        return np.array([[w.table.item(r, c + 1).value for c in range(k)] for r in range(k)])

    assert shown() == pytest.approx(model.similarity()[np.ix_(order, order)])
    with qtbot.waitSignal(w.nuChanged):
        w.nu.setValue(4.0)
    assert shown() == pytest.approx(model.similarity(4.0)[np.ix_(order, order)])
    rows = top_similar(model.similarity(4.0), model.phones, 3)
    t1 = w.table1_table
    assert t1.rowCount() == len(rows)
    first = {t1.item(r, 0).text(): (t1.item(r, 1).text(), t1.item(r, 2).value) for r in range(t1.rowCount())}
    for r in rows:
        assert first[r.phone][0] == r.neighbours[0][0]
        assert first[r.phone][1] == pytest.approx(r.neighbours[0][1])
    w.table.sortItems(2)          # sortable: by a column of numbers
    col = [w.table.item(r, 2).value for r in range(k)]
    assert col == sorted(col)
    assert w.export_csv(tmp_path / "s.csv").stat().st_size > 0
    assert w.export_png(tmp_path / "s.png").stat().st_size > 1000


# ---------------------------------------------------------------------- metrics
def test_metrics_view_table2_and_sweep_match_engine(qtbot, model, corpus, tmp_path):
    from facetraj_app.analysis.metrics_view import MetricsView

    w = MetricsView(model, corpus)
    qtbot.addWidget(w)
    w.show()
    w.per_split.setValue(2)
    w.max_n.setValue(2)
    w.acoustic.setChecked(False)
    with qtbot.waitSignal(w.table2Done, timeout=WAIT_MS):
        w.run_table2.click()
    assert w.progress.value() == 1000
    sub = subset_corpus(corpus, 2)
    want = table2_rows(table2(model, sub, acoustic=False))
    names = [w.table.item(r, 0).text() for r in range(w.table.rowCount())]
    ours = [r for r, name in enumerate(names) if not name.strip().startswith("the paper")]
    assert [names[r] for r in ours] == [r.name for r in want]
    assert [r.name for r in want][:4] == ["Train (Triang.)", "Train (Spline)", "Test (Triang.)",
                                          "Test (Spline)"]
    for col, metric in ((1, "whole_face"), (2, "lower_lip"), (3, "upper_lip")):
        assert [w.table.item(r, col).value for r in ours] == pytest.approx(
            [getattr(r, metric) for r in want])
    # each phonetic N = 3 row is followed by the paper's (Table 2 of the paper)
    from facetraj_engine.evaluation.paper import table2_value
    assert names[ours[0] + 1].strip() == "the paper, same condition"
    assert [w.table.item(ours[0] + 1, c).value for c in (1, 2, 3)] == pytest.approx(
        table2_value("train", "triangular"))
    assert w.table.columnCount() == 6
    with qtbot.waitSignal(w.sweepDone, timeout=WAIT_MS):
        w.run_sweep.click()
    curves = {c.split: c for c in sweep_curves(sweep_n(model, sub, (1, 2)))}
    for c in w.curves:
        assert c.ns.tolist() == [1, 2]
        assert c.whole_face == pytest.approx(curves[c.split].whole_face)
    assert w.export_table2_csv(tmp_path / "t2.csv").read_text().startswith("condition,")
    assert w.export_sweep_csv(tmp_path / "n.csv").read_text().startswith("split,N,")
    assert w.export_png(tmp_path / "m.png").stat().st_size > 1000


# ---------------------------------------------------------------------- PC modes
def test_pc_slider_moves_points_by_eigenvector_times_value(qtbot, model):
    from facetraj_app.analysis.pc_modes import SLIDER_STEPS, PCModeExplorer

    w = PCModeExplorer(model)
    qtbot.addWidget(w)
    w.resize(1000, 600)
    with qtbot.waitSignal(w.ready, timeout=WAIT_MS):      # its scene is built in steps
        w.show()
    qtbot.waitExposed(w)
    neutral = model.neutral_face()
    assert w.displaced_points() == pytest.approx(neutral)
    sd = np.sqrt(model.pca.variances)
    for k, sds in ((0, 2.0), (1, -1.5)):
        w.combo.setCurrentIndex(k)
        with qtbot.waitSignal(w.valueChanged):
            w.slider.setValue(int(sds * SLIDER_STEPS))
        value = sds * sd[k]
        assert w.value == pytest.approx(value)
        want = neutral + value * model.pca.components[k].reshape(-1, 3)
        assert w.displaced_points() == pytest.approx(want, abs=1e-9)
    assert w.slider.maximum() == 3 * SLIDER_STEPS and w.slider.minimum() == -3 * SLIDER_STEPS
    # the 2-D projection's arrows follow (its plots are built off the GUI thread first)
    w.canvas.finish()
    disp = want - neutral
    assert w.quiver.U == pytest.approx(w.arrow_scale.value() * disp[:, 0])
    assert w.ax_face.get_title().startswith("PC2 = ")
    # variance share of every PC, from the model
    heights = [b.get_height() for b in w.bars]
    assert heights == pytest.approx(100 * model.pca.explained_ratio)
    # which markers PC1 moves, and how (the engine's reading of the mode)
    w.combo.setCurrentIndex(0)
    assert w.description.text() == describe_mode(model, 0).text()
    # the animation sweeps the mode
    w.animate_btn.setChecked(True)
    seen = set()
    qtbot.waitUntil(lambda: seen.add(round(w.value / sd[0])) or len(seen) >= 3, timeout=10_000)
    w.animate_btn.setChecked(False)
    assert not w.timer.isActive()
    img = w.plotter.screenshot()
    assert float(np.std(img)) > 1.0
    w.close_view()


# ---------------------------------------------------------------------- inspector
def test_inspector_weights_sum_to_one(qtbot, model, view):
    from facetraj_app.analysis.inspector import CodebookInspector

    w = CodebookInspector(model)
    qtbot.addWidget(w)
    w.show()
    res = view.synthesis
    t = float(view.times[len(view.times) // 2])
    with qtbot.waitSignal(w.inspected):
        w.set_synthesis(res, t)
    ins = w.current
    f = int(round(t * model.marker_rate))
    assert ins.frame == f
    v = cell_values(w.codeword_table, 0)
    assert sum(v) == pytest.approx(1.0)
    assert float(w.sum_label.text()) == pytest.approx(1.0)
    assert sorted(v, reverse=True) == pytest.approx(sorted(res.frames.weights[f], reverse=True))
    assert float(w.gamma_label.text()) == pytest.approx(res.frames.gamma[f], abs=1e-3)
    seg = res.segments[res.frame_segment[f]]
    assert w.phone_label.text() == seg.segment.label
    assert cell_values(w.chosen_table, 2) == pytest.approx(seg.scores.tolist(), abs=1e-4)
    assert ins.lsf_hat == pytest.approx(res.frames.lsf_hat[f])
    assert w.codeword_table.rowCount() == 5 * len(seg.chosen)



def test_inspector_robust_mode_explains_choice(qtbot, model, corpus, tmp_path):
    """Robust mode: the table gains target cost, label cost and origin columns, the label
    confidence is shown, and the numbers are the synthesis's."""
    from facetraj_app.analysis.inspector import CodebookInspector
    from facetraj_engine.method.pipeline import synthesize

    utt = corpus.utterance(corpus.info.test[0])
    conf = np.full(len(utt.phones), 0.25)
    res = synthesize(model, utt.audio, utt.sample_rate, utt.phones,
                     SynthConfig(mode="robust", label_weight=8.0), n_frames=utt.n_frames,
                     confidence=conf)
    w = CodebookInspector(model)
    qtbot.addWidget(w)
    w.resize(900, 900)
    w.show()
    f = len(res.times) // 2
    with qtbot.waitSignal(w.inspected):
        w.set_synthesis(res, f / model.marker_rate)
    headers = [w.codeword_table.horizontalHeaderItem(c).text()
               for c in range(w.codeword_table.columnCount())]
    assert headers[-3:] == ["target cost", "label cost", "chosen by"]
    assert w.confidence_label.text().startswith("0.250")
    labels = {w.codeword_table.item(r, 9).text(): float(w.codeword_table.item(r, 8).text())
              for r in range(w.codeword_table.rowCount())}
    assert labels.get("acoustic") == pytest.approx(8.0 * 0.25)       # kappa * confidence
    assert labels.get("eq 4") == 0.0
    assert sum(cell_values(w.codeword_table, 0)) == pytest.approx(1.0, abs=1e-3)
    shot = w.grab().toImage()
    assert shot.save(str(tmp_path / "inspector_robust.png"))
    assert shot.width() >= 800


def test_settings_panel_explains_modes_and_shows_tuned(qtbot):
    from facetraj_app.settings_panel import MODE_NOTES, SynthSettingsPanel

    def choose(key: str) -> None:                   # as a user does
        p.mode.setCurrentIndex(p.mode.findData(key))
        p.mode.activated.emit(p.mode.currentIndex())

    p = SynthSettingsPanel(SynthConfig())
    qtbot.addWidget(p)
    p.show()
    chosen = []
    p.searchChosen.connect(chosen.append)
    assert p.mode_note.text() == MODE_NOTES["phonetic"]
    assert not p.tuned_label.isVisible()              # the robust mode's settings: robust only
    choose("robust")
    assert p.mode_note.text() == MODE_NOTES["robust"] and p.tuned_label.isVisible()
    assert "without cross-validation" in (p.set_tuned({}) or p.tuned_label.text())
    assert "`" not in p.tuned_label.text()
    p.set_limits(3, 10.0, {"settings": {"label_weight": 4.0, "triangle_s": 0.133,
                                        "n_context_phones": 6}, "folds": 2})
    assert "κ (label weight) = 4" in p.tuned_label.text() and "2 folds" in p.tuned_label.text()
    choose("phonetic")
    choose("robust")                                  # picks up the tuned N
    cfg = p.config()
    assert cfg.mode == "robust" and cfg.label_weight == 4.0 and cfg.triangle_s == 0.133
    assert cfg.n_context_phones == 6
    assert [c.mode for c in chosen] == ["robust", "phonetic", "robust"]
    choose("phonetic")
    assert p.config().label_weight == SynthConfig().label_weight
    # the search used is shown, and why it is not the one asked for; the settings still ask
    # for theirs
    p.show_used(SynthConfig(mode="robust"), SynthConfig(),
                "robust mode: aligned labels are not hand-checked")
    assert p.shown_search() == "robust" and p.mode_note.text() == MODE_NOTES["robust"]
    assert p.mode_reason.isVisible() and "aligned labels are not hand-checked" in p.mode_reason.text()
    assert p.config().mode == "phonetic"
    p.show_used(SynthConfig(), SynthConfig(), "phonetic mode: hand-checked labels (the paper)")
    assert p.shown_search() == "phonetic" and not p.mode_reason.isVisible()


# ---------------------------------------------------------------------- errors
def test_error_view_matches_engine_and_jumps(qtbot, model, corpus, view):
    from facetraj_app.analysis.errors_view import ErrorView, LipErrorPanel

    w = ErrorView(model, corpus)
    qtbot.addWidget(w)
    w.show()
    w.per_split.setValue(2)
    with qtbot.waitSignal(w.reportReady, timeout=WAIT_MS):
        w.run_btn.click()
    rep = error_report(model, subset_corpus(corpus, 2), ("test",))
    assert [w.phone_table.item(r, 0).text() for r in range(w.phone_table.rowCount())] == \
        [p.phone for p in rep.phones]
    assert cell_values(w.phone_table, 1) == pytest.approx([p.rms for p in rep.phones])
    assert cell_values(w.phone_table, 2) == pytest.approx([p.frames for p in rep.phones])
    assert cell_values(w.phone_table, 4) == pytest.approx([p.correlation for p in rep.phones], nan_ok=True)
    assert cell_values(w.utt_table, 5) == pytest.approx([u.rms for u in rep.utterances])
    # the closures against the talker's own lips (issue 46): per utterance and pooled
    assert cell_values(w.utt_table, 9) == pytest.approx([u.closure_precision for u in rep.utterances],
                                                        nan_ok=True)
    assert cell_values(w.utt_table, 10) == pytest.approx([u.closure_recall for u in rep.utterances],
                                                         nan_ok=True)
    assert rep.closures.talker > 0 and np.isfinite(rep.talker.closed)
    assert f"recall {100 * rep.closures.recall:.0f} %" in w.status.text()
    assert "1st percentile" in w.status.toolTip()
    # under the table: the per-phone RMS errors as bars, the worst at the top, with frame counts
    w.phone_chart.finish()                              # built and drawn off the GUI thread
    ax = w.phone_chart.figure.axes[0]
    shown = sorted(p.rms for p in rep.phones if p.rms == p.rms)
    assert [b.get_width() for b in ax.patches] == pytest.approx(shown)
    worst = rep.phones[0]
    assert [t.get_text() for t in ax.get_yticklabels()][-1] == f"{worst.phone} ({worst.frames})"
    # the tables' columns fill the width, none narrower than its contents
    w.resize(1400, 700)
    w.tabs.setCurrentIndex(1)
    qtbot.waitUntil(lambda: abs(sum(w.utt_table.columnWidth(c) for c in range(w.utt_table.columnCount()))
                                - w.utt_table.viewport().width()) < w.utt_table.columnCount() + 1)
    for c in range(w.utt_table.columnCount()):
        assert w.utt_table.columnWidth(c) >= w.utt_table.sizeHintForColumn(c)
    w.tabs.setCurrentIndex(0)
    with qtbot.waitSignal(w.jumpRequested) as sig:
        w.utt_table.cellClicked.emit(0, 0)
    u = w.utt_table.item(0, 0).text()
    want = next(x for x in rep.utterances if x.utterance == u)
    assert sig.args == [u, pytest.approx(want.worst_time)]
    # the panel in a matplotlib axes
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    panel = LipErrorPanel(model)
    panel.draw(ax, view)
    assert len(ax.lines) == 2 and panel.last_segments
    assert all(s.label != "sil" for s in panel.last_segments)


# ---------------------------------------------------------------------- kinematics
def synthetic_view(rate: float = 60.0):
    """A view whose lower lip closes (speed bell 120 mm/s, 0.30-0.50 s) and releases (80 mm/s,
    0.50-0.75 s); the synthesized copy is two frames late."""
    t = np.arange(73) / rate

    def bell(a, b, amp):
        u = np.clip((t - a) / (b - a), 0, 1)
        return amp * (b - a) * (u / 2 - np.sin(2 * np.pi * u) / (4 * np.pi))

    y = -bell(0.30, 0.50, 120.0) + bell(0.50, 0.75, 80.0)
    m = np.zeros((len(t), 4, 3))
    m[:, 1, 1] = y
    syn = np.roll(m, 2, axis=0)
    syn[:2] = m[0]
    u20 = math.asin(math.sqrt(0.2)) / math.pi
    truth = {"onset": 0.30 + 0.2 * u20, "pvel": 0.40, "maxc": 0.50, "pvel2": 0.625,
             "offset": 0.75 - 0.25 * u20}
    utt = SimpleNamespace(name="synthetic", duration=t[-1] + 1 / rate,
                          phones=[PhoneSegment(0, 0.44, "aa"), PhoneSegment(0.44, 0.56, "m"),
                                  PhoneSegment(0.56, t[-1] + 1 / rate, "aa")])
    view = SimpleNamespace(utterance=utt, synthesis=SimpleNamespace(markers=syn), original=m,
                           times=t, rate=rate)
    fake_model = SimpleNamespace(marker_names=["UL", "LL", "LC_R", "LC_L"], lower_lip=1, upper_lip=0,
                                 lip_corners=[2, 3], neutral_face=lambda: np.zeros((4, 3)))
    return view, fake_model, truth


def assert_chart_matches_table(w) -> None:
    """The kinematics chart has one bar per table row with a timing error, each as long as that
    row's error and labelled with its gesture, phone and landmark; every label inside the canvas."""
    table = {(w.table.item(r, 0).value, w.table.item(r, 1).text(), w.table.item(r, 2).text()):
             w.table.item(r, 5).value for r in range(w.table.rowCount())}
    finite = {k: v for k, v in table.items() if v == v}
    w.chart.finish()                                        # built and drawn off the GUI thread
    ax = w.chart.figure.axes[0]
    bars = ax.patches
    assert len(bars) == len(finite) > 0
    labels = [t.get_text() for t in ax.get_yticklabels()]
    ticks = list(ax.get_yticks())
    by_label = {}
    for b in bars:
        y = b.get_y() + b.get_height() / 2
        by_label[labels[min(range(len(ticks)), key=lambda i: abs(ticks[i] - y))]] = b.get_width()
    assert by_label == pytest.approx({f"{g:.0f} {ph} {lm}": v for (g, ph, lm), v in finite.items()})
    assert all((b.get_facecolor()[0] > 0.5) == (b.get_width() > 0) for b in bars)   # late orange
    w.chart.draw()
    renderer = w.chart.figure.canvas.get_renderer()
    fw, fh = w.chart.figure.bbox.width, w.chart.figure.bbox.height
    for t in [*ax.get_yticklabels(), ax.xaxis.label, ax.title]:
        e = t.get_window_extent(renderer)
        assert e.x0 >= 0 and e.y0 >= 0 and e.x1 <= fw and e.y1 <= fh, t.get_text()
    e = ax.get_tightbbox(renderer)                  # everything drawn, the x tick labels too
    assert e.x0 >= 0 and e.y0 >= 0 and e.x1 <= fw and e.y1 <= fh


def test_kinematics_landmarks_within_one_frame(qtbot, tmp_path):
    from praatio import textgrid

    from facetraj_app.analysis.kinematics_panels import KinematicsControls, LipMeasurePanel

    view, fake_model, truth = synthetic_view()
    w = KinematicsControls(fake_model)
    qtbot.addWidget(w)
    w.show()
    with qtbot.waitSignal(w.measured):
        w.set_view(view)
    rows = {w.table.item(r, 2).text(): r for r in range(w.table.rowCount())}
    assert set(rows) == set(truth)
    for k, r in rows.items():
        assert w.table.item(r, 1).text() == "m"
        assert abs(w.table.item(r, 3).value - truth[k]) < 1 / 60, k              # original
        assert abs(w.table.item(r, 4).value - (truth[k] + 2 / 60)) < 1 / 60, k   # synthesized
        assert w.table.item(r, 5).value == pytest.approx(2000 / 60, abs=1.0)     # error, ms
    # beside the table: one bar per landmark row, its length the row's error, labels in the canvas
    assert_chart_matches_table(w)
    # the threshold moves onset and offset (sin^2 = 0.5 at a quarter of each bell)
    with qtbot.waitSignal(w.measured):
        w.threshold.setValue(50)
    onset = w.table.item({w.table.item(r, 2).text(): r for r in range(w.table.rowCount())}["onset"], 3)
    assert abs(onset.value - (0.30 + 0.05)) < 1 / 60
    tsv = w.export_tsv(tmp_path / "lm.tsv")
    assert len(tsv.read_text().splitlines()) == 3
    tg = textgrid.openTextgrid(str(w.export_textgrid(tmp_path / "lm.TextGrid")), includeEmptyIntervals=True)
    assert list(tg.tierNames) == ["original", "synthesized"]
    # the panels draw the engine's curves
    from matplotlib.figure import Figure

    fig = Figure()
    ax = fig.add_subplot()
    w.panel.draw(ax, view)
    assert np.asarray(ax.lines[0].get_ydata()) == pytest.approx(w.measurement.v_synthesized)
    ax2 = fig.add_subplot(2, 1, 2)
    LipMeasurePanel(fake_model, "aperture").draw(ax2, view)
    assert np.asarray(ax2.lines[1].get_ydata()) == pytest.approx(np.abs(view.original[:, 1, 1]))


def test_kinematics_chart_without_original_and_in_a_narrow_dock(qtbot):
    from PyQt6.QtCore import Qt

    from facetraj_app.analysis.kinematics_panels import SIDE_BY_SIDE_WIDTH, KinematicsControls

    view, fake_model, _truth = synthetic_view()
    w = KinematicsControls(fake_model)
    qtbot.addWidget(w)
    w.resize(SIDE_BY_SIDE_WIDTH + 200, 600)
    w.show()
    qtbot.waitUntil(lambda: w.split.orientation() == Qt.Orientation.Horizontal)
    assert w.chart.x() > w.table.x() + w.table.width() - 1            # beside the table
    w.resize(SIDE_BY_SIDE_WIDTH - 300, 700)
    qtbot.waitUntil(lambda: w.split.orientation() == Qt.Orientation.Vertical)
    qtbot.waitUntil(lambda: w.chart.y() >= w.table.y() + w.table.height() - 1)   # under it
    # no original: synthesized landmarks in the table, no bars and a note saying why
    view.original = None
    with qtbot.waitSignal(w.measured):
        w.set_view(view)
    assert w.table.rowCount() == 5
    w.chart.finish()                                        # built off the GUI thread
    ax = w.chart.figure.axes[0]
    assert len(ax.patches) == 0
    assert any("no original markers" in t.get_text() for t in ax.texts)


# ---------------------------------------------------------------------- in the main window
def test_installed_in_main_window(qtbot, corpus, model):
    from facetraj_app.analysis import PANELS, VIEWS, install
    from facetraj_app.main_window import MainWindow

    win = MainWindow(corpus.root, use_audio=False)
    qtbot.addWidget(win)
    views = install(win)
    win.resize(1600, 1000)
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        win.show()
    qtbot.waitExposed(win)
    qtbot.waitUntil(lambda: win.settled, timeout=WAIT_MS)
    texts = [a.text() for a in win.analysis_menu.actions()]
    for t in VIEWS.values():
        assert t in texts
    for key in VIEWS:
        if views.open_view(key) is None:                   # its module imported in the background
            qtbot.waitUntil(lambda k=key: k in views.docks, timeout=WAIT_MS)
        assert views.docks[key].widget().widget() is views.widgets[key]   # in a scroll area
    qtbot.waitUntil(lambda: not win.timeline.building, timeout=WAIT_MS)
    # kinematics and errors put their panels into the stack
    titles = [p.title for p in win.timeline.panels]
    assert "lip aperture" in titles and "lip error" in titles
    assert any(t.startswith("tangential velocity") for t in titles)
    views.show_panels(list(PANELS))
    assert all(views.panel_actions[k].isChecked() for k in PANELS)
    qtbot.waitUntil(lambda: not win.timeline.building, timeout=WAIT_MS)
    tl = win.timeline
    assert len(tl.panels) == 5 + len(PANELS)
    # what has no room is left out (app/panel_layout.py): the spectrogram and waveform first
    assert len(tl.axes) == len(tl.shown) == len(tl.panels) - len(tl.hidden)
    assert all(p.title in ("spectrogram", "waveform") for p in tl.hidden), tl.hidden
    # the inspector follows the cursor
    ins = views.widgets["inspector"]
    with qtbot.waitSignal(ins.inspected, timeout=5000):
        win.seek(0.8)
    assert ins.current.frame == int(round(win.current_time() * win.model.marker_rate))
    # a click in the error list jumps to that utterance and time
    errs = views.widgets["errors"]
    other = win.corpus.info.test[1]
    with qtbot.waitSignal(win.synthesisChanged, timeout=WAIT_MS):
        errs.jumpRequested.emit(other, 0.5)
    qtbot.waitUntil(lambda: abs(win.current_time() - 0.5) < 0.02, timeout=5000)
    assert win.view.utterance.name == other
    views.close()
    win.close()


# ---------------------------------------------------------------------- export buttons
def test_export_buttons_write_or_report(qtbot, model, corpus, tmp_path, monkeypatch):
    """Every view's export goes through one dialog helper: the chosen file is written, a cancelled
    dialog writes nothing, and a failure is shown in a message box instead of raised."""
    from PyQt6.QtWidgets import QFileDialog, QMessageBox

    from facetraj_app.analysis.metrics_view import MetricsView
    from facetraj_app.analysis.similarity_view import SimilarityView

    chosen: list[str] = []
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (chosen.pop(0), ""))
    shown: list[tuple[str, str]] = []
    monkeypatch.setattr(QMessageBox, "warning", lambda parent, title, text: shown.append((title, text)))

    sim = SimilarityView(model)
    qtbot.addWidget(sim)
    assert not sim.csv_button.isEnabled()                # until the clustering is there
    qtbot.waitUntil(lambda: sim.clustering is not None, timeout=WAIT_MS)
    assert sim.csv_button.isEnabled()
    chosen.append(str(tmp_path / "sim.csv"))
    sim._export_csv()
    header = (tmp_path / "sim.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "phone" and sorted(header[1:]) == sorted(model.phones)
    chosen.append("")                                    # cancelled
    sim._export_png()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sim.csv"] and not shown

    metrics = MetricsView(model, corpus)
    qtbot.addWidget(metrics)
    chosen.append(str(tmp_path / "t2.csv"))
    metrics._export_table2()                             # nothing computed yet: a ValueError
    assert shown == [("Export failed", "compute Table 2 first")]
    assert not (tmp_path / "t2.csv").exists()
