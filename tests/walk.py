"""A user's walk through the window, for the order test and the monkey test (issue 54): every kind
of data the app opens (:func:`make_kinds`), opened through the File menu, and the things a
phonetician does with it -- play, seek, pin, change a setting, open every dock and panel, run
every export, resize, Live on and off -- each as a named action of :class:`Walker` that goes
through the window's menus, buttons and keys. File dialogs answer as the user would (a folder of
data, a file name in a temporary folder: :class:`ScriptedDialogs`); every error the window shows
or logs is kept (:class:`Errors`), so that a walk can assert that none happened.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from conftest import DEFAULT_CORPUS, MOCHA
from PyQt6.QtCore import QPoint, Qt
from PyQt6.QtWidgets import (
    QApplication,
    QDialog,
    QFileDialog,
    QMessageBox,
    QPushButton,
    QWidget,
)

ARCTIC = MOCHA.parent / "arctic_samples"
#: a hang guard for a step (a loaded machine is slow), not a speed limit
WAIT_MS = 240_000
#: the kinds of data the app opens, in the order the walks name them
KINDS = ("default", "own", "mocha", "mview", "recording", "recordings")


def make_kinds(root: Path) -> dict[str, Path]:
    """A folder (or file) of each kind of data in ``root``: the default corpus, a face corpus of
    the user's own (C3D, 12 markers), the MOCHA-TIMIT sample (2-D EMA, 9 coils, read in place), an
    MVIEW articulograph corpus (HPRC's 8 sensors, 3-D), one recording (ARCTIC, its transcript
    beside it) and a folder of two recordings (another voice)."""
    from articulograph import mview_from_mocha
    from toycorpus import build_toy_corpus

    from facetraj_engine.io.corpus import init_corpus

    kinds = {"default": DEFAULT_CORPUS, "own": build_toy_corpus(root / "own", n_train=6, n_test=2)}
    kinds["mocha"] = init_corpus(MOCHA, root / "mocha" / "corpus.json", ["UI", "BN"], "UL", "LL",
                                 label_map="mocha", test_fraction=0)[0].parent
    mview = mview_from_mocha(MOCHA, root / "mview").parent
    kinds["mview"] = init_corpus(mview, upper_lip="UL", lower_lip="LL", test_fraction=0)[0].parent
    kinds["recording"] = ARCTIC / "cmu_arctic_us_aew_a0001.wav"
    folder = root / "recordings"
    folder.mkdir()
    for stem in ("cmu_arctic_us_axb_a0004", "cmu_arctic_us_axb_a0005"):
        for suffix in (".wav", ".txt"):
            (folder / f"{stem}{suffix}").symlink_to(ARCTIC / f"{stem}{suffix}")
    kinds["recordings"] = folder
    return kinds


def data_available() -> bool:
    return (MOCHA / "fsew0_001.ema").exists() and (ARCTIC / "cmu_arctic_us_aew_a0001.wav").exists()


class Errors(logging.Handler):
    """Every error the window shows (its error handler, a dialog) or logs (facetraj's loggers at
    ERROR and above, tracebacks included), and every exception raised in a slot (``raised``: the
    list of pytest-qt's ``qtbot.captureExceptions()``, so that a walk fails at the step that
    raised, not at the test's end)."""

    def __init__(self):
        super().__init__(logging.ERROR)
        self.logged: list[str] = []
        self.raised: list = []

    @property
    def items(self) -> list[str]:
        import traceback

        return self.logged + ["raised in the event loop:\n" + "".join(traceback.format_exception(*e))
                              for e in self.raised]

    def emit(self, record: logging.LogRecord) -> None:
        if record.name.startswith("facetraj"):
            text = record.getMessage()
            if record.exc_info:
                text += "\n" + logging.Formatter().formatException(record.exc_info)
            self.logged.append(f"log {record.name}: {text}")

    def shown(self, message: str) -> None:
        self.logged.append(f"shown: {message}")


@dataclass
class ScriptedDialogs:
    """The file and message dialogs as a user answers them: a folder or file to open is the one
    ``choose`` names next; a file to save gets its default name in ``out`` (numbered, never one
    written before); a question is answered Yes; an error or warning box is an error."""

    out: Path
    errors: Errors
    choose: list[Path] = field(default_factory=list)
    saved: list[Path] = field(default_factory=list)
    asked: list[str] = field(default_factory=list)

    def install(self, monkeypatch) -> ScriptedDialogs:
        mp = monkeypatch
        mp.setattr(QFileDialog, "getExistingDirectory", staticmethod(self._open))
        mp.setattr(QFileDialog, "getOpenFileName", staticmethod(lambda *a, **k: (self._open(*a), "")))
        mp.setattr(QFileDialog, "getSaveFileName", staticmethod(self._save))
        mp.setattr(QMessageBox, "critical", staticmethod(self._error))
        mp.setattr(QMessageBox, "warning", staticmethod(self._error))
        mp.setattr(QMessageBox, "information", staticmethod(lambda *a, **k: QMessageBox.StandardButton.Ok))
        mp.setattr(QMessageBox, "question", staticmethod(self._question))
        mp.setattr(QMessageBox, "exec", lambda box: self._box(box))
        mp.setattr(QDialog, "exec", lambda dialog: QDialog.DialogCode.Accepted)
        return self

    def _open(self, _parent=None, title: str = "", *_a, **_k) -> str:
        self.asked.append(title)
        return str(self.choose.pop(0)) if self.choose else ""

    def _save(self, _parent=None, title: str = "", default: str = "", *_a, **_k) -> tuple[str, str]:
        self.asked.append(title)
        name = Path(default or "export.out").name
        path = self.out / f"{len(self.saved):03d}_{name}"
        self.saved.append(path)
        return str(path), ""

    def _error(self, _parent, title, text, *_a, **_k):
        self.errors.shown(f"{title}: {text}")
        return QMessageBox.StandardButton.Ok

    def _question(self, _parent, title, text, _buttons=None, default=None, *_a, **_k):
        """A question answered by its default, else No (never a file replaced unasked)."""
        self.asked.append(f"{title}: {text}")
        return default if default is not None else QMessageBox.StandardButton.No

    def _box(self, box: QMessageBox) -> int:
        """A message box with its own buttons (unsaved label edits: Save, Discard, Cancel)
        answered Discard where it offers it (a walk never writes beside the data), else Ok."""
        self.asked.append(f"{box.windowTitle()}: {box.text()}")
        buttons = box.standardButtons()
        for answer in (QMessageBox.StandardButton.Discard, QMessageBox.StandardButton.Ok):
            if buttons & answer:
                return answer.value
        return QMessageBox.StandardButton.Cancel.value


def tier_row(win) -> int | None:
    """The row of the phones on the editable phone tier, None where it is not shown."""
    from facetraj_engine.labels.editing import PHONES

    panel = win.extension("labels").panel
    return panel.row_of(PHONES) if panel in win.timeline.shown else None


def button(root: QWidget, text: str) -> QPushButton | None:
    """The enabled, visible push button of ``root`` whose text starts with ``text``."""
    for b in root.findChildren(QPushButton):
        if b.text().replace("&", "").startswith(text) and b.isEnabled() and b.isVisibleTo(root):
            return b
    return None


class Walker:
    """One window walked by a user: the actions of :attr:`ACTIONS`, each through the widgets,
    each waiting (``qtbot``) until the window has done what it asked (a hang guard, no timing)."""

    def __init__(self, win, qtbot, kinds: dict[str, Path], dialogs: ScriptedDialogs, errors: Errors):
        self.win, self.qtbot, self.kinds, self.dialogs, self.errors = win, qtbot, kinds, dialogs, errors
        self.opened = "default"

    # ------------------------------------------------------------------ basics
    def wait(self, condition: Callable[[], bool], what: str) -> None:
        try:
            self.qtbot.waitUntil(lambda: bool(self.errors.items) or condition(), timeout=WAIT_MS)
        except Exception as exc:          # a hang: say what was awaited, and where the window is
            raise AssertionError(f"waited in vain for {what}; {self.state()}") from exc
        if self.errors.items:
            raise AssertionError(f"while waiting for {what}:\n" + "\n".join(self.errors.items))

    def state(self) -> str:
        """Where the window is, in a line (for a failure's message)."""
        w = self.win
        view, tl = w.view, w.timeline
        return (f"shown: {view.utterance.name if view else None} ({view.split if view else ''}), "
                f"corpus {w.corpus.root if w.corpus else None}, model loading {w.state.loading}, "
                f"settled {w.settled}, busy {w.busy}, panels building {tl.building} "
                f"({len(tl.shown)} shown, {len(tl.hidden)} left out), "
                f"tasks {[t.label for t in w.tasks.tasks]}, status {w.status_label.text()!r}, "
                f"window {w.width()}x{w.height()}, panels {tl.canvas.width()}x{tl.canvas.height()}")

    def settle(self) -> None:
        """Until the window's foreground work is done and its panels drawn."""
        self.wait(lambda: self.win.settled, "the window to settle")

    def menu(self, menu: str, entry: str, enabled: bool = True) -> bool:
        """Choose ``entry`` of ``menu`` as a user does (the action the menu shows, triggered);
        ``enabled``: it must be enabled (else a disabled entry is left, as a user can only).
        Whether it was chosen."""
        m = self.win.menu(menu)
        for action in m.actions():
            if action.text().replace("&", "").startswith(entry):
                assert action.isEnabled() or not enabled, f"{menu} > {entry} is disabled"
                if action.isEnabled():
                    action.trigger()
                return action.isEnabled()
        raise AssertionError(f"no entry {entry!r} in {menu}: "
                             f"{[a.text() for a in m.actions() if a.text()]}")

    def key(self, key: Qt.Key, modifier: Qt.KeyboardModifier = Qt.KeyboardModifier.NoModifier) -> None:
        """A key pressed over the 3-D view (where a click leaves the focus: the window's keys),
        the window active first (a shortcut reaches only the active window; after a dialog
        closes none may be until the window manager, here the X server, says so)."""
        self.win.activateWindow()
        self.qtbot.waitUntil(self.win.isActiveWindow, timeout=WAIT_MS)
        self.win.face.setFocus()
        self.qtbot.keyClick(QApplication.focusWidget() or self.win, key, modifier)

    def choose(self, combo, text: str) -> None:
        """Pick the entry of ``combo`` that contains ``text``, as the user's pick in its list
        does (its ``activated``, not only its current index)."""
        index = combo.findText(text, Qt.MatchFlag.MatchContains)
        assert index >= 0, (text, [combo.itemText(i) for i in range(combo.count())])
        combo.setCurrentIndex(index)
        combo.activated.emit(index)

    def click(self, widget: QWidget) -> None:
        self.qtbot.mouseClick(widget, Qt.MouseButton.LeftButton)

    # ------------------------------------------------------------------ opening data
    def open_kind(self, kind: str) -> None:
        """Open data of ``kind`` through the File menu and wait until the window shows it."""
        path = self.kinds[kind]
        self.dialogs.choose = [path]
        entry = {"recording": "Open audio for synthesis", "recordings": "Open a folder of recordings"}
        self.menu("File", entry.get(kind, "Open corpus folder"))
        self.opened = kind
        self.wait(lambda: self.shows(kind), f"the window to show {kind} ({path})")
        self.settle()

    def shows(self, kind: str) -> bool:
        """Whether the window shows the data of ``kind`` just opened: its corpus in the browser and
        one of its utterances (a recording: that recording) on screen, drawn."""
        w, path = self.win, self.kinds[kind]
        view = w.view
        if view is None or not w.settled:
            return False
        if kind == "recording":
            return view.split == "external" and view.utterance.name == path.stem
        if kind == "recordings":
            stems = sorted(p.stem for p in path.iterdir() if p.suffix == ".wav")
            return (view.split == "external" and view.utterance.name == stems[0]
                    and set(stems) <= set(w.browser.items))
        corpus = w.corpus
        return (corpus is not None and Path(corpus.root).resolve() == Path(path).resolve()
                and view.utterance.name in corpus.info.ids
                and set(corpus.info.ids) <= set(w.browser.items))

    # ------------------------------------------------------------------ actions
    def play(self) -> None:
        """Play (the transport's button) until the clock has moved, then pause (space)."""
        w = self.win
        self.key(Qt.Key.Key_Home)
        start = w.current_time()
        self.click(w.transport.play_button)
        self.wait(lambda: w.current_time() > start + 0.1 or not w.clock.playing, "playback to run")
        self.key(Qt.Key.Key_Space)
        self.wait(lambda: not w.clock.playing, "playback to pause")

    def seek(self) -> None:
        """Frame and phone steps, End and Home, and a click in the middle of the panels."""
        w = self.win
        for key, mod in ((Qt.Key.Key_Right, Qt.KeyboardModifier.NoModifier),
                         (Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier),
                         (Qt.Key.Key_Left, Qt.KeyboardModifier.NoModifier),
                         (Qt.Key.Key_End, Qt.KeyboardModifier.NoModifier)):
            self.key(key, mod)
        assert abs(w.current_time() - w.view.duration) < 0.05, (w.current_time(), w.view.duration)
        self.key(Qt.Key.Key_Home)
        assert w.current_time() == 0.0
        canvas = w.timeline.canvas
        self.wait(lambda: w.timeline.axes and not w.timeline.building, "the panels")
        self.qtbot.mouseClick(canvas, Qt.MouseButton.LeftButton, pos=QPoint(canvas.width() // 2,
                                                                           canvas.height() // 2))

    def pin(self) -> None:
        """Pin the result (Ctrl+P), change N in the settings, and see the pin beside it."""
        w = self.win
        self.key(Qt.Key.Key_P, Qt.KeyboardModifier.ControlModifier)
        n = w.settings.n
        before = w.view
        n.setValue(n.value() % 3 + 1)
        self.wait(lambda: w.view is not before and w.settled, "the new synthesis")

    def setting(self, rng: np.random.Generator) -> None:
        """One setting of the settings dock changed as a user would (N, C, the search, the
        smoothing, a closure box)."""
        w, s = self.win, self.win.settings
        choice = int(rng.integers(5))
        if choice == 0:
            s.n.setValue(int(rng.integers(1, 6)))
        elif choice == 1:
            s.c.setValue(int(rng.integers(0, s.c.maximum() + 1)))
        elif choice == 2:
            s.mode.setCurrentIndex(int(rng.integers(s.mode.count())))
        elif choice == 3:
            s.smoothing.setCurrentIndex(int(rng.integers(s.smoothing.count())))
        else:
            box = [s.closure_labels, s.rest, s.closure_detector][int(rng.integers(3))]
            if box.isEnabled():
                self.click(box)
        self.qtbot.wait(400)            # the settings' debounce, then the new synthesis
        self.settle()
        assert w.view is not None

    def edit_labels(self, rng: np.random.Generator | None = None) -> str:
        """A phone of the phones row clicked and edited as a phonetician does (renamed with F2 to
        a phone of the model, split, merged, deleted, made silence, a boundary dragged, undone,
        redone); what was done ("" where the row is not shown: no labels, or left out)."""
        import label_gui

        w = self.win
        editor = w.extension("labels")
        view = w.view
        self.settle()
        if view is None or not view.utterance.phones or tier_row(w) is None:
            return ""
        phones = [p for p in view.utterance.phones if p.end - p.start > 0.05]
        if not phones:
            return ""
        pick = int(rng.integers(len(phones))) if rng is not None else len(phones) // 2
        seg = phones[pick]
        label_gui.click(w, (seg.start + seg.end) / 2)
        if editor.selected_span() is None:
            return ""
        choice = int(rng.integers(8)) if rng is not None else 0
        if choice == 0:
            known = sorted(set(w.model.phones) - {"sil"})
            to = "m" if "m" in known else known[int(rng.integers(len(known))) if rng is not None else 0]
            label_gui.rename(w, to)
            done = f"rename to /{to}/"
        elif choice == 7:
            label_gui.drag(w, seg.end, seg.end - 0.02)
            done = "drag a boundary 20 ms"
        else:
            keys = {1: "S", 2: "M", 3: "Delete", 4: "0", 5: "Ctrl+Z", 6: "Ctrl+Shift+Z"}
            label_gui.key(w, keys[choice])
            done = f"key {keys[choice]}"
        return f"{done} at /{seg.label}/ {seg.start:.2f} s"

    def open_docks(self) -> list[str]:
        """Every Analysis view, Measure's table and each panel, through the Analysis menu; the
        marker panel of the View menu. Returns the views opened."""
        w = self.win
        analysis = w.extension("analysis")
        from facetraj_app.analysis import PANELS, VIEWS

        for text in VIEWS.values():
            self.menu("Analysis", text.rstrip("…"))
        self.menu("Analysis", "Measure")
        for key, text in PANELS.items():
            if not analysis.panel_actions[key].isChecked():
                self.menu("Analysis", f"Panel: {text}")
        self.menu("View", "Add a marker trajectory panel")
        self.wait(lambda: set(VIEWS) <= set(analysis.widgets), "every analysis view")
        self.settle()
        return list(analysis.widgets)

    def close_panels(self) -> None:
        """The panels off again (the timeline's room back for the next walk)."""
        from facetraj_app.analysis import PANELS

        analysis = self.win.extension("analysis")
        for key, text in PANELS.items():
            if analysis.panel_actions[key].isChecked():
                self.menu("Analysis", f"Panel: {text}")
        self.menu("View", "Remove the marker trajectory panels")
        self.settle()

    def run_views(self) -> None:
        """Each view's own work, small (two utterances per split, N to 2): Table 2, the N sweep,
        the error analysis; Measure across the corpus with the filter /p b m/."""
        w = self.win
        widgets = w.extension("analysis").widgets
        metrics = widgets["metrics"]
        metrics.per_split.setValue(1)
        metrics.max_n.setValue(2)
        for text in ("Compute Table 2", "Run N sweep"):
            b = button(metrics, text)
            if b is not None:
                self.click(b)
                self.wait(lambda t=text: button(metrics, t) is not None, f"metrics: {text}")
        errors = widgets["errors"]
        run = button(errors, "Run") or button(errors, "Compute")
        if run is not None:
            self.click(run)
        measure = w.extension("measure")
        table = measure.open_table()
        table.filter.setText("b p m")
        corpus_run = table.corpus
        if w.corpus is not None and button(corpus_run, "Run") is not None:
            corpus_run.count.setValue(1)
            self.click(corpus_run.run_button)
            self.wait(lambda: corpus_run.run_button.isEnabled(), "Measure across the corpus")
        self.wait(lambda: not w.tasks.busy and not w.tasks.tasks, "the views' work")

    def zoom_in(self, steps: int = 6) -> tuple[float, float]:
        """The mouse wheel turned forward over the middle of the panels, ``steps`` notches (the
        time range shown narrows around it: a video exports that range). The range shown."""
        from PyQt6.QtCore import QPointF
        from PyQt6.QtGui import QWheelEvent

        tl = self.win.timeline
        canvas = tl.canvas
        self.wait(lambda: tl.axes and not tl.building, "the panels")
        box, ratio = tl.axes[len(tl.axes) // 2].bbox, canvas.device_pixel_ratio   # inside a panel
        at = QPointF((box.x0 + box.x1) / 2 / ratio, canvas.height() - (box.y0 + box.y1) / 2 / ratio)
        for _ in range(steps):
            event = QWheelEvent(at, canvas.mapToGlobal(at), QPoint(0, 0), QPoint(0, 120),
                                Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier,
                                Qt.ScrollPhase.NoScrollPhase, False)
            QApplication.sendEvent(canvas, event)
        return self.win.timeline.xlim()

    def exports(self) -> list[Path]:
        """Every export the window offers: the File menu's and each view's button that saves a
        file (those enabled). Returns the files written."""
        w = self.win
        before = len(self.dialogs.saved)
        for entry in ("Export synthesized trajectories", "Export the panels as a figure",
                      "Save the model", "Save screenshot"):
            self.menu("File", entry)
        if w.view.original is not None:
            self.menu("File", "Export original trajectories")
        roots = [*w.extension("analysis").widgets.values()]
        table = w.extension("measure").table
        if table is not None:
            roots.append(table)
        for root in roots:
            for b in root.findChildren(QPushButton):
                text = b.text().replace("&", "")
                if b.isEnabled() and b.isVisibleTo(root) and ("…" in text or "..." in text) \
                        and any(k in text for k in ("CSV", "PNG", "Export", "SVG", "csv", "png")):
                    self.click(b)
        self.menu("File", "Export a video")
        self.wait(lambda: not w.tasks.busy and not w.tasks.tasks, "the exports")
        written = self.dialogs.saved[before:]
        missing = [p for p in written if not p.exists()]
        assert not missing, f"exports said written but absent: {missing}"
        return written

    def live(self) -> None:
        """Live on (its window opens on the model) and off."""
        live = self.win.extension("live")
        live.action.trigger()
        self.wait(lambda: live.live is not None or bool(self.errors.items), "the Live window")
        live.action.trigger()
        self.wait(lambda: live.live is None, "the Live window to close")

    def resize(self, size: tuple[int, int]) -> None:
        self.win.resize(*size)
        self.qtbot.wait(50)
        self.settle()


def assert_no_errors(errors: Errors, where: str) -> None:
    assert not errors.items, f"{where}:\n" + "\n".join(errors.items)


def walk_environment() -> dict[str, str]:
    """The environment a walk runs in (the model cache of the session)."""
    return {k: v for k, v in os.environ.items() if k.startswith("FACETRAJ")}
