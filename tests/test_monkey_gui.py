"""The seeded monkey test (issue 54): random sequences of the window's own actions -- data of every
kind opened from the File menu, utterances chosen in the browser, keys, play, pins, settings,
docks and panels opened and closed, phones corrected on the label editor's rows (and saved to a
temporary folder), exports to a temporary folder, resizes, Live on and off --
for a fixed time, many without waiting for the one before to finish (as an impatient user
clicks). After each action no error may have reached the error handler, a dialog or the log.

The seed is printed; a failure prints it with the actions that led there, so that
``FACETRAJ_MONKEY_SEED=<seed>`` replays the same sequence. ``make test`` runs it briefly
(``FACETRAJ_MONKEY_SECONDS``, default 45 s); ``make monkey`` runs it longer with new seeds."""

from __future__ import annotations

import logging
import os
import random
import time
from collections import Counter

import numpy as np
import pytest

pytest.importorskip("pytestqt")
if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from PyQt6.QtCore import Qt
from walk import KINDS, Errors, ScriptedDialogs, Walker, data_available, make_kinds

if not data_available():
    pytest.skip("../shared/data (MOCHA sample, ARCTIC recordings) is absent", allow_module_level=True)

pytestmark = pytest.mark.gui
SECONDS = float(os.environ.get("FACETRAJ_MONKEY_SECONDS", "45"))
SIZES = ((800, 600), (1366, 768), (1600, 1000), (1920, 1160), (1024, 700))
KEYS = ((Qt.Key.Key_Space, Qt.KeyboardModifier.NoModifier),
        (Qt.Key.Key_Right, Qt.KeyboardModifier.NoModifier),
        (Qt.Key.Key_Left, Qt.KeyboardModifier.NoModifier),
        (Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier),
        (Qt.Key.Key_Left, Qt.KeyboardModifier.ShiftModifier),
        (Qt.Key.Key_Home, Qt.KeyboardModifier.NoModifier),
        (Qt.Key.Key_End, Qt.KeyboardModifier.NoModifier),
        (Qt.Key.Key_Escape, Qt.KeyboardModifier.NoModifier),
        (Qt.Key.Key_P, Qt.KeyboardModifier.ControlModifier))


class Monkey:
    """The random actions, each a line in :attr:`done` (the sequence a failure prints)."""

    def __init__(self, walker: Walker, seed: int):
        self.w, self.seed = walker, seed
        self.rng = np.random.default_rng(seed)
        self.done: list[str] = []
        self.actions = [(3, self.open_data), (4, self.choose_utterance), (8, self.key),
                        (3, self.play), (4, self.setting), (3, self.view), (3, self.panel),
                        (2, self.close_dock), (3, self.export), (2, self.resize), (1, self.live),
                        (2, self.pins), (3, self.settle), (4, self.labels), (1, self.save_labels_as)]

    def step(self) -> None:
        weights = np.array([w for w, _ in self.actions], float)
        _, action = self.actions[int(self.rng.choice(len(self.actions), p=weights / weights.sum()))]
        action()

    def note(self, text: str) -> None:
        self.done.append(text)

    # ------------------------------------------------------------------ the actions
    def open_data(self) -> None:
        kind = KINDS[int(self.rng.integers(len(KINDS)))]
        wait = bool(self.rng.integers(2))
        self.note(f"File > open {kind}{'' if wait else ' (not waiting)'}")
        if wait:
            self.w.open_kind(kind)
        else:
            self.w.dialogs.choose = [self.w.kinds[kind]]
            entry = {"recording": "Open audio for synthesis", "recordings": "Open a folder of recordings"}
            self.w.menu("File", entry.get(kind, "Open corpus folder"))

    def choose_utterance(self) -> None:
        items = [i for i in self.w.win.browser.items.values() if not i.isHidden()]
        if items:
            item = items[int(self.rng.integers(len(items)))]
            self.note(f"browser: {item.text(0)[:30]}")
            self.w.win.browser.tree.setCurrentItem(item)

    def key(self) -> None:
        key, mod = KEYS[int(self.rng.integers(len(KEYS)))]
        self.note(f"key {key.name}{'+' + mod.name if mod.value else ''}")
        self.w.key(key, mod)

    def play(self) -> None:
        if self.w.win.view is not None:
            self.note("play, then pause")
            self.w.click(self.w.win.transport.play_button)
            self.w.qtbot.wait(int(self.rng.integers(50, 400)))
            self.w.key(Qt.Key.Key_Space)

    def setting(self) -> None:
        self.note("a setting")
        self.w.setting(self.rng)

    def view(self) -> None:
        from facetraj_app.analysis import VIEWS

        text = list(VIEWS.values())[int(self.rng.integers(len(VIEWS)))]
        entries = [text, "Measure: lip aperture per phone"]
        entry = entries[int(self.rng.integers(2))]
        self.note(f"Analysis > {entry}")
        if self.w.win.model is not None:
            self.w.menu("Analysis", entry.rstrip("…"), enabled=False)

    def panel(self) -> None:
        from facetraj_app.analysis import PANELS

        text = list(PANELS.values())[int(self.rng.integers(len(PANELS)))]
        self.note(f"Analysis > Panel: {text}")
        self.w.menu("Analysis", f"Panel: {text}", enabled=False)

    def close_dock(self) -> None:
        docks = [d for d in self.w.win.findChildren(type(self.w.win.browser_dock)) if d.isVisible()]
        if docks:
            dock = docks[int(self.rng.integers(len(docks)))]
            self.note(f"close the dock {dock.windowTitle()}")
            dock.close()

    def export(self) -> None:
        entries = ["Export synthesized trajectories", "Export the panels as a figure", "Save the model",
                   "Save screenshot", "Export a video", "Export original trajectories"]
        entry = entries[int(self.rng.integers(len(entries)))]
        w = self.w.win
        if w.view is None or w.busy or (entry.endswith("original trajectories") and w.view.original is None):
            return
        self.note(f"File > {entry}")
        self.w.menu("File", entry, enabled=False)

    def resize(self) -> None:
        size = SIZES[int(self.rng.integers(len(SIZES)))]
        self.note(f"resize to {size[0]}x{size[1]}")
        self.w.win.resize(*size)

    def live(self) -> None:
        self.note("Live on and off")
        if self.w.win.model is not None:
            self.w.live()

    def pins(self) -> None:
        entry = ["Pin this result", "Clear pins"][int(self.rng.integers(2))]
        self.note(f"View > {entry}")
        self.w.menu("View", entry, enabled=False)

    def labels(self) -> None:
        if self.w.win.model is not None:
            done = self.w.edit_labels(self.rng)
            self.note(f"labels: {done or '(no phones row)'}")

    def save_labels_as(self) -> None:
        self.note("File > Save labels as…")
        self.w.menu("File", "Save labels as", enabled=False)

    def settle(self) -> None:
        self.note("(wait until the window settles)")
        self.w.wait(lambda: self.w.win.settled or (self.w.win.view is None and not self.w.win.busy),
                    "the window to settle")


@pytest.fixture
def walker(qtbot, monkeypatch, tmp_path, trained_cache):
    from facetraj_app.main import WINDOW_SIZE, build_window

    kinds = make_kinds(tmp_path / "data")
    errors = Errors()
    logging.getLogger().addHandler(errors)
    out = tmp_path / "exports"
    out.mkdir()
    dialogs = ScriptedDialogs(out, errors).install(monkeypatch)
    win = build_window(kinds["default"], use_audio=False)
    win.set_error_handler(errors.shown)
    qtbot.addWidget(win)
    win.place_on_screen(WINDOW_SIZE)
    win.show()
    walker = Walker(win, qtbot, kinds, dialogs, errors)
    with qtbot.captureExceptions() as raised:       # a slot's exception fails the step it is in
        errors.raised = raised
        walker.wait(lambda: walker.shows("default"), "the default corpus")
        yield walker
    logging.getLogger().removeHandler(errors)
    win.extension("analysis").close()
    win.close()


def test_random_actions_never_fail(walker, capsys):
    seed = int(os.environ.get("FACETRAJ_MONKEY_SEED", random.SystemRandom().randrange(1, 10**6)))
    monkey = Monkey(walker, seed)
    with capsys.disabled():
        print(f"\nmonkey: seed {seed}, {SECONDS:g} s (FACETRAJ_MONKEY_SEED={seed} replays it)")
    end = time.monotonic() + SECONDS
    try:
        while time.monotonic() < end:
            monkey.step()
            walker.qtbot.wait(int(monkey.rng.integers(0, 120)))
            assert not walker.errors.items, "\n".join(walker.errors.items)
        monkey.settle()
        assert not walker.errors.items, "\n".join(walker.errors.items)
    except BaseException:
        sequence = "\n".join(f"  {i + 1}. {a}" for i, a in enumerate(monkey.done))
        print(f"monkey: seed {seed}; the actions (replay: FACETRAJ_MONKEY_SEED={seed}):\n{sequence}")
        raise
    kinds = Counter(a.split(":")[0].split(" (")[0].split(" to ")[0] for a in monkey.done)
    with capsys.disabled():
        print(f"monkey: {len(monkey.done)} actions, no error (seed {seed}): "
              + ", ".join(f"{k} {n}" for k, n in kinds.most_common()))
