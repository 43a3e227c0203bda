"""Pictures for the GUI tests: Qt images as arrays, a widget's place on the screen as the X
server shows it (3-D views included), a heartbeat that measures how long the event loop
stalls, and screens of a given size (``SCREENS`` of tests/conftest.py: a test asks for its
``screen`` fixture and runs on a private Xvfb of each size)."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from conftest import SCREEN_ENV
from PyQt6.QtCore import QElapsedTimer, QObject, QPoint, QTimer
from PyQt6.QtGui import QGuiApplication, QImage
from PyQt6.QtWidgets import QWidget

from facetraj_app.display import start_xvfb


def image_array(image: QImage) -> np.ndarray:
    """``(h, w, 3)`` uint8 RGB of a QImage."""
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    ptr = image.constBits()
    ptr.setsize(image.sizeInBytes())
    rows = np.frombuffer(ptr, np.uint8).reshape(image.height(), image.bytesPerLine())
    return rows[:, : 3 * image.width()].reshape(image.height(), image.width(), 3).copy()


def on_screen(widget: QWidget) -> np.ndarray:
    """What the screen shows where ``widget`` is (the X server's pixels: an OpenGL view's too)."""
    p = widget.mapToGlobal(QPoint(0, 0))
    pix = QGuiApplication.primaryScreen().grabWindow(0, p.x(), p.y(), widget.width(), widget.height())
    return image_array(pix.toImage())


def place_in(shot: np.ndarray, widget: QWidget, top: QWidget) -> np.ndarray:
    """The part of ``shot`` (a picture of ``top``) where ``widget`` is."""
    p = widget.mapTo(top, QPoint(0, 0))
    return shot[p.y():p.y() + widget.height(), p.x():p.x() + widget.width()]


class Heartbeat(QObject):
    """A 10 ms timer that records the longest gap between its ticks: how long the event loop
    was held up (a stall) while it ran; and, for the same gaps, how much of it the GUI thread
    spent working (its CPU time: the part that is the program's, not the machine's load)."""

    def __init__(self, interval_ms: int = 10):
        super().__init__()
        self.timer = QTimer(self)
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self._beat)
        self.clock = QElapsedTimer()
        self.last = 0
        self.last_cpu = 0.0
        self.longest = 0            # ms, wall time
        self.longest_cpu = 0        # ms, the GUI thread's CPU time within one gap

    def start(self) -> None:
        self.clock.start()
        self.last, self.longest, self.longest_cpu = 0, 0, 0
        self.last_cpu = time.thread_time()
        self.timer.start()

    def _beat(self) -> None:
        now, cpu = self.clock.elapsed(), time.thread_time()
        self.longest = max(self.longest, now - self.last)
        self.longest_cpu = max(self.longest_cpu, int(round(1000 * (cpu - self.last_cpu))))
        self.last, self.last_cpu = now, cpu

    def stop(self) -> int:
        """Stop; the longest gap in ms (wall time)."""
        self._beat()
        self.timer.stop()
        return self.longest


# ---------------------------------------------------------------------- screens of a given size
#: a child run of one screen size is stopped after this long: under pyproject's pytest-timeout
#: (900 s) of the test whose ``screen`` fixture waits for it, which would otherwise end the whole
#: run first (its thread method), the child's output unseen
SCREEN_RUN_TIMEOUT_S = 840


@dataclass(frozen=True)
class Screen:
    """The screen a test is for: ``local`` when this process's display is that size (the test
    runs here), else the test ran in a child process on a private Xvfb of the size."""

    size: str
    local: bool


class ScreenRuns:
    """The tests of a module for one screen size, run once in a child pytest on a private Xvfb of
    that size (a Qt process has one display); each test's outcome is then looked up by its name."""

    def __init__(self):
        self._results: dict[tuple[str, str], dict[str, tuple[str, str]]] = {}

    def outcome(self, path: str, size: str, name: str) -> tuple[str, str]:
        """("passed" | "failed" | "skipped" | "missing", the message) of test ``name`` (its
        function name with the parameters) of the module at ``path`` on a ``size`` screen; a
        child run that ended without its report (a crash, the time limit) fails every test with
        its output."""
        key = (path, size)
        if key not in self._results:
            self._results[key] = self._run(path, size)
        results = self._results[key]
        if "" in results:
            return results[""]
        return results.get(name, ("missing", f"{name} did not run on the {size} screen"))

    @staticmethod
    def _run(path: str, size: str) -> dict[str, tuple[str, str]]:
        """Each test's outcome by its name, or under "" the failure of a run without a report."""
        import xml.etree.ElementTree as ET

        proc, display = start_xvfb(size, terminate=False)
        try:
            with tempfile.TemporaryDirectory(prefix="facetraj-screen-") as tmp:
                report = Path(tmp) / "report.xml"
                env = {**os.environ, "DISPLAY": display, SCREEN_ENV: size}
                env.pop("WAYLAND_DISPLAY", None)
                try:
                    run = subprocess.run([sys.executable, "-m", "pytest", path, "-k", size, "-q",
                                          "-p", "no:cacheprovider", f"--junitxml={report}"], env=env,
                                         capture_output=True, text=True, timeout=SCREEN_RUN_TIMEOUT_S)
                except subprocess.TimeoutExpired as timeout:
                    return {"": ("failed", f"the {size} screen's run took over {SCREEN_RUN_TIMEOUT_S} s:\n"
                                 + _text(timeout.stdout)[-4000:] + _text(timeout.stderr)[-4000:])}
                if not report.exists():
                    return {"": ("failed", f"the {size} screen's run wrote no report (exit "
                                 f"{run.returncode}):\n" + run.stdout[-4000:] + run.stderr[-4000:])}
                out = {}
                for case in ET.parse(report).getroot().iter("testcase"):
                    bad = [c for c in case if c.tag in ("failure", "error")]
                    skip = case.find("skipped")
                    if bad:
                        out[case.get("name")] = ("failed", (bad[0].get("message") or "") + "\n"
                                                 + (bad[0].text or ""))
                    elif skip is not None:
                        out[case.get("name")] = ("skipped", skip.get("message") or "")
                    else:
                        out[case.get("name")] = ("passed", "")
                return out
        finally:
            proc.terminate()
            proc.wait(10)


def _text(output: bytes | str | None) -> str:
    """A timed-out child's captured output (bytes whatever ``text`` asked for) as text."""
    if isinstance(output, bytes):
        return output.decode(errors="replace")
    return output or ""


def project(plotter, points: np.ndarray) -> np.ndarray:
    """Where world ``points`` ``(n, 3)`` are in a 3-D view's widget: pixels ``(n, 2)``, x right
    and y down from its top left (VTK's display y runs up)."""
    from vtkmodules.vtkRenderingCore import vtkCoordinate

    coord = vtkCoordinate()
    coord.SetCoordinateSystemToWorld()
    height = plotter.interactor.height()
    out = []
    for p in np.asarray(points, dtype=float):
        coord.SetValue(*p)
        x, y = coord.GetComputedDoubleDisplayValue(plotter.renderer)
        out.append((x, height - y))
    return np.array(out)


def pixels_inside(image: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """The pixels ``(n, 3)`` of ``image`` whose centres lie inside ``polygon`` ``(k, 2)`` (x, y
    in the image's pixels)."""
    from matplotlib.path import Path as Polygon

    x0, y0 = np.floor(polygon.min(axis=0)).astype(int)
    x1, y1 = np.ceil(polygon.max(axis=0)).astype(int)
    ys, xs = np.mgrid[max(y0, 0):max(y1, 0), max(x0, 0):max(x1, 0)]
    centres = np.column_stack([xs.ravel() + 0.5, ys.ravel() + 0.5])
    inside = Polygon(polygon).contains_points(centres)
    return image[ys.ravel()[inside], xs.ravel()[inside]]


def colour_of(hex_colour: str) -> np.ndarray:
    return np.array([int(hex_colour[i:i + 2], 16) for i in (1, 3, 5)], dtype=float)


def near(pixels: np.ndarray, hex_colour: str, tol: float = 40.0) -> int:
    """How many of ``pixels`` ``(n, 3)`` are within ``tol`` of ``hex_colour``."""
    return int((np.linalg.norm(pixels.astype(float) - colour_of(hex_colour), axis=-1) < tol).sum())


def overlap(a, b) -> bool:
    """Whether two matplotlib bboxes overlap by more than a pixel."""
    return a.x0 < b.x1 - 1 and b.x0 < a.x1 - 1 and a.y0 < b.y1 - 1 and b.y0 < a.y1 - 1


def view_settled(win, key: str) -> bool:
    """Analysis view ``key`` is open, has done its work and drawn it, and so has the window."""
    from facetraj_app.figure_canvas import BackgroundCanvas

    w = win.extension("analysis").widgets.get(key)
    if w is None or not win.settled:
        return False
    if key == "similarity" and w.clustering is None:
        return False
    if key == "pc_modes" and not w.is_ready:
        return False
    return not any(c.busy for c in w.findChildren(BackgroundCanvas))


def figure_texts(fig) -> list:
    """Every visible text of a figure: titles, axis labels, tick labels, legends' texts."""
    out = list(fig.texts)
    for legend in fig.legends:
        out += [*legend.get_texts(), legend.get_title()]
    for ax in fig.axes:
        out += [ax.title, ax.xaxis.label, ax.yaxis.label]
        for axis in (ax.xaxis, ax.yaxis):       # the tick labels drawn: those in the view
            lo, hi = sorted(axis.get_view_interval())
            out += [label for tick, label in zip(axis.get_ticklocs(), axis.get_ticklabels(),
                                                 strict=True) if lo <= tick <= hi]
        legend = ax.get_legend()
        if legend is not None:
            out += [*legend.get_texts(), legend.get_title()]
    return [t for t in out if t.get_visible() and t.get_text().strip()]


def assert_legible(fig, renderer, what: str, overlaps=overlap) -> None:
    """Every text of ``fig`` inside it and none over another; no legend over an axes' data (a
    legend inside an axes must keep clear of its lines, bars and points). ``overlaps(a, b)``
    judges two boxes (default: by more than a pixel)."""
    box = fig.bbox
    texts = [(t.get_text(), t.get_window_extent(renderer)) for t in figure_texts(fig)]
    for text, e in texts:
        assert e.x0 >= box.x0 - 1 and e.y0 >= box.y0 - 1 and e.x1 <= box.x1 + 1 \
            and e.y1 <= box.y1 + 1, (what, text, e)
    for i, (a, ea) in enumerate(texts):
        for b, eb in texts[i + 1:]:
            assert not overlaps(ea, eb), (what, a, b)
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        lb = legend.get_window_extent(renderer)
        for bar in ax.patches:
            assert not overlaps(lb, bar.get_window_extent(renderer)), (what, "legend over a bar")
        for line in ax.lines:
            xy = line.get_transform().transform(line.get_xydata())
            xy = xy[np.isfinite(xy).all(axis=1)]
            inside = ((xy[:, 0] > lb.x0) & (xy[:, 0] < lb.x1) & (xy[:, 1] > lb.y0) & (xy[:, 1] < lb.y1))
            assert not inside.any(), (what, "legend over a line", line.get_label())


def opened_window(qtbot, utterance: str | None = None, wait_ms: int = 240_000):
    """The main window as ``facetraj`` opens it on the default corpus (``place_on_screen``: 1600 x
    1000 where the screen has room; no sound device), shown and ready; closed after the test
    (a generator for a fixture to yield from)."""
    from facetraj.paths import default_corpus
    from facetraj_app.main import WINDOW_SIZE, build_window

    w = build_window(default_corpus(), utterance=utterance, use_audio=False)
    w.set_correlation_sweep(False)
    qtbot.addWidget(w)
    w.place_on_screen(WINDOW_SIZE)
    with qtbot.waitSignal(w.synthesisChanged, timeout=wait_ms):
        w.show()
    qtbot.waitExposed(w)
    w.place_on_screen(WINDOW_SIZE)                # again once shown, as facetraj does
    qtbot.waitUntil(lambda: w.settled, timeout=wait_ms)
    yield w
    w.extension("analysis").close()
    w.close()


def screen_window(screen: Screen, qtbot, utterance: str | None = None, wait_ms: int = 240_000):
    """:func:`opened_window` for a test on ``screen``; None when the test runs on a screen of
    its own (in a child run: its body is not run here). A generator for a fixture to yield from."""
    if not screen.local:
        yield None
        return
    yield from opened_window(qtbot, utterance, wait_ms)


def resynthesize(w, qtbot, change, wait_ms: int = 240_000) -> None:
    """Call ``change()`` (a new utterance, setting or recording) and wait for the window's new
    synthesis, drawn."""
    with qtbot.waitSignal(w.synthesisChanged, timeout=wait_ms):
        change()
    qtbot.waitUntil(lambda: w.settled, timeout=wait_ms)


def middle(w, label: str) -> float:
    """The middle of the first phone ``label`` of the window's utterance, in seconds."""
    seg = next(p for p in w.view.utterance.phones if p.label == label)
    return 0.5 * (seg.start + seg.end)


def face_image(plotter) -> np.ndarray:
    """The 3-D view as rendered now, ``(h, w, 3)``."""
    return np.asarray(plotter.screenshot(return_img=True))[..., :3]


def centre_x(image: np.ndarray, colour: str) -> float:
    """The mean x of ``image``'s pixels near ``colour``, as a share of its width."""
    _ys, xs = np.nonzero(np.linalg.norm(image.astype(float) - colour_of(colour), axis=-1) < 60)
    assert len(xs) > 30, colour
    return float(xs.mean()) / image.shape[1]


def assert_placed_as_in(window: np.ndarray, scene: np.ndarray, colours: list[str]) -> None:
    """Each colour's sets in ``scene`` (a video's 3-D half) where they are in ``window`` (the
    window's 3-D view), within 4 % of the width, and ``colours`` left to right."""
    (wx, wy), (vx, vy) = window.shape[1::-1], scene.shape[1::-1]
    squeeze = min(1.0, (wx / wy) / (vx / vy))     # a view as wide as the window's, or narrower
    for colour in colours:
        expected = 0.5 + (centre_x(window, colour) - 0.5) * squeeze
        assert abs(centre_x(scene, colour) - expected) <= 0.04, (colour, expected)
    order = [centre_x(scene, c) for c in colours]
    assert order == sorted(order)
