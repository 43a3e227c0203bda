"""Screenshots of the analysis views for ``docs/analysis.md`` (run under a display, e.g. Xvfb):

    xvfb-run -a -s "-screen 0 1600x1200x24" python -m facetraj_app.analysis.figures data_samples docs/figures

Writes ``analysis_<view>.png`` for every view and ``analysis_window.png`` (the main window with the
kinematics and lip error panels in the time-aligned stack).
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Callable
from pathlib import Path

from PyQt6.QtCore import QEventLoop, QTimer
from PyQt6.QtWidgets import QApplication, QWidget

from facetraj_app.figure_canvas import BackgroundCanvas
from facetraj_app.plotter_widget import grab_with_3d

log = logging.getLogger(__name__)


def wait_until(cond: Callable[[], bool], timeout_s: float = 300.0, step_ms: int = 50) -> bool:
    """Run the event loop until ``cond()`` holds (or the timeout)."""
    loop = QEventLoop()
    timer = QTimer()
    timer.setInterval(step_ms)
    elapsed = {"ms": 0}

    def check() -> None:
        elapsed["ms"] += step_ms
        if cond() or elapsed["ms"] > timeout_s * 1000:
            loop.quit()

    timer.timeout.connect(check)
    timer.start()
    if not cond():
        loop.exec()
    timer.stop()
    return cond()


def settle(ms: int = 300) -> None:
    loop = QEventLoop()
    QTimer.singleShot(ms, loop.quit)
    loop.exec()


def _finish(cond: Callable[[], bool], what: str, timeout_s: float = 1800.0) -> None:
    """Wait for a view's background computation; a picture of an unfinished view is an error."""
    if not wait_until(cond, timeout_s):
        raise RuntimeError(f"{what} did not finish within {timeout_s:.0f} s: no picture taken")


def draw_plots(widget: QWidget, after_ms: int = 100) -> None:
    """Let ``widget`` settle, finish the draw of each of its visible plots (they draw off the GUI
    thread), and let it settle again for ``after_ms``."""
    settle()
    for canvas in widget.findChildren(BackgroundCanvas):
        if canvas.isVisible():
            canvas.finish()
    settle(after_ms)


def shoot(widget: QWidget, path: Path) -> Path:
    """Save a picture of ``widget`` once its plots are drawn (they draw off the GUI thread) and
    its 3-D views rendered (as on the screen)."""
    draw_plots(widget)
    grab_with_3d(widget).save(str(path))
    log.info("wrote %s", path)
    return path


def _window_figures(win, views, out: Path, has_test: bool, only: set[str] | None) -> list[Path]:
    """The window with every panel (``analysis_window.png``) and as a phonetician sees it with
    the PC modes docked (``analysis_docked.png``)."""
    written = []
    if only is None or "window" in only:
        for key in ("aperture", "width", "protrusion", "velocity", "lip_error"):
            views.panel_actions[key].setChecked(True)
        win.resize(1600, 1400)
        win.splitter.setSizes([300, 1100])
        if has_test:
            win.seek(0.0)
        _finish(lambda: not win.timeline.building, "the panels")
        written.append(shoot(win, out / "analysis_window.png"))
    if only is None or "docked" in only:        # as a phonetician sees it: PC modes docked
        for key in ("aperture", "width", "protrusion", "velocity", "lip_error"):
            views.panel_actions[key].setChecked(False)
        win.resize(1600, 1000)
        win.splitter.setSizes([480, 520])
        dock = views.docks.get("pc_modes")
        if dock is not None:
            dock.setFloating(False)
            dock.show()
            dock.raise_()
        _finish(lambda: not win.timeline.building and not win.busy, "the window")
        win.seek(min(2.38, win.view.duration / 2))
        settle(500)
        win.timeline.ensure_drawn()
        written.append(win.save_screenshot(out / "analysis_docked.png"))
    return written


def make_figures(corpus_dir: Path, out: Path, per_split: int = 6,
                 only: set[str] | None = None) -> list[Path]:
    """Open the main window on ``corpus_dir`` with the analysis views and save their screenshots
    (``only``: just these views, e.g. ``{"errors"}``; ``"window"`` is the panel stack)."""
    from facetraj_app.main_window import MainWindow
    from facetraj_engine.io.corpus import load_corpus

    from . import install

    out.mkdir(parents=True, exist_ok=True)
    win = MainWindow(corpus_dir, use_audio=False)
    views = install(win)
    win.resize(1600, 1000)
    win.show()
    if not wait_until(lambda: win.view is not None and not win.busy):
        raise RuntimeError("the window did not load the corpus")
    written = []
    info = load_corpus(corpus_dir).info
    # each view at about the size it has docked in a 1600 x 1000 window (a third of its width)
    standalone = {"similarity": (600, 900), "metrics": (600, 950), "pc_modes": (600, 950),
                  "inspector": (600, 950), "errors": (600, 900), "kinematics": (600, 900)}
    for key, size in standalone.items():
        if only is not None and key not in only:
            continue
        views.open_view(key)
        _finish(lambda k=key: k in views.docks and not win.busy, f"opening {key}")
        w = views.widgets[key]
        if key == "similarity":
            _finish(lambda w=w: w.clustering is not None, "the clustering")
        if key == "pc_modes":
            _finish(lambda w=w: w.is_ready, "the PC modes' scene")
        dock = views.docks[key]
        dock.setFloating(True)
        dock.resize(*size)
        if key == "similarity":
            w.tabs.setCurrentIndex(2)
        if key == "metrics":
            w.per_split.setValue(per_split)
            w.max_n.setValue(6)
            w.start_table2()
            _finish(lambda w=w: w.table2_result is not None, "Table 2")
            w.start_sweep()
            _finish(lambda w=w: w.sweep_result is not None, "the N sweep")
        if key == "pc_modes":
            w.set_sd_units(3.0)             # PC1 at its closing end: the lips meet
        if key == "errors":
            w.per_split.setValue(per_split)
            w.start()
            _finish(lambda w=w: w.report is not None, "the error analysis")
            w.tabs.setCurrentIndex(0)
        if key == "inspector":
            win.seek(min(1.0, win.view.duration / 2))
        written.append(shoot(dock, out / f"analysis_{key}.png"))
        if key == "similarity":
            w.tabs.setCurrentIndex(0)
            written.append(shoot(dock, out / "analysis_similarity_table.png"))
            w.tabs.setCurrentIndex(1)
            written.append(shoot(dock, out / "analysis_similarity_table1.png"))
        if key == "metrics":                   # the numbers' tab: the per-sensor table
            w.tabs.setCurrentIndex(1)
            w.table_choice.setCurrentIndex(1)
            written.append(shoot(dock, out / "analysis_metrics_sensors.png"))
            w.table_choice.setCurrentIndex(0)
            w.tabs.setCurrentIndex(0)
        if key == "errors":
            w.tabs.setCurrentIndex(1)
            written.append(shoot(dock, out / "analysis_errors_utterances.png"))
        dock.hide()
    written += _window_figures(win, views, out, bool(info.test), only)
    views.close()
    win.close()
    return written


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("corpus", type=Path)
    p.add_argument("out", type=Path)
    p.add_argument("--per-split", type=int, default=6, help="utterances per split for the metrics")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    app = QApplication.instance() or QApplication(sys.argv[:1])
    make_figures(args.corpus, args.out, args.per_split)
    app.quit()
    return 0


if __name__ == "__main__":
    sys.exit(main())
