"""The order test (issue 54): one window opens every kind of data the app takes, each after each
of the others -- every ordered pair of the default corpus, a face corpus of the user's own (C3D),
the MOCHA-TIMIT sample (2-D EMA), an MVIEW articulograph corpus (3-D EMA, another sensor count),
a single recording and a folder of recordings -- through the File menu, and on each plays, seeks,
pins, corrects a phone (left unsaved: the next opening asks, and the edit is discarded), opens
every dock and panel, runs the views' work and every export. No error reaches the
error handler, a dialog or the log, and the window shows the data just opened.

The 30 ordered pairs are walked as one circuit (each pair once: an Eulerian circuit of the
complete directed graph on the six kinds), in one window, on small data."""

from __future__ import annotations

import itertools
import logging
import os
import time

import pytest

pytest.importorskip("pytestqt")
if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from walk import KINDS, Errors, ScriptedDialogs, Walker, assert_no_errors, data_available, make_kinds

if not data_available():
    pytest.skip("../shared/data (MOCHA sample, ARCTIC recordings) is absent", allow_module_level=True)

pytestmark = pytest.mark.gui


def every_ordered_pair(kinds: tuple[str, ...]) -> list[str]:
    """A walk through ``kinds`` that takes every ordered pair of two different kinds once, from
    and back to the first (Hierholzer's algorithm on the complete directed graph).

    >>> walk = every_ordered_pair(("a", "b", "c"))
    >>> walk[0] == walk[-1] == "a", len(walk), sorted(itertools.pairwise(walk)) == sorted(
    ...     (x, y) for x in "abc" for y in "abc" if x != y)
    (True, 7, True)
    """
    out_edges = {k: [j for j in reversed(kinds) if j != k] for k in kinds}
    stack, circuit = [kinds[0]], []
    while stack:
        node = stack[-1]
        if out_edges[node]:
            stack.append(out_edges[node].pop())
        else:
            circuit.append(stack.pop())
    return circuit[::-1]


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


def test_every_kind_of_data_after_every_other(walker, capsys):
    walk = every_ordered_pair(KINDS)
    assert len(walk) == 31 and len(set(itertools.pairwise(walk))) == 30
    visited = []
    clock = time.perf_counter()
    spent: dict[str, float] = {}

    def timed(action):
        t0 = time.perf_counter()
        out = action()
        spent[action.__name__] = spent.get(action.__name__, 0.0) + time.perf_counter() - t0
        return out

    for step, kind in enumerate(walk):
        if step:
            t0 = time.perf_counter()
            walker.open_kind(kind)
            spent["open"] = spent.get("open", 0.0) + time.perf_counter() - t0
        where = f"step {step}: {' -> '.join(walk[max(0, step - 1):step + 1])}"
        assert_no_errors(walker.errors, f"{where}, opening")
        for action in (walker.play, walker.seek, walker.pin, walker.edit_labels, walker.open_docks,
                       walker.run_views):
            timed(action)
        lo, hi = walker.zoom_in()                    # the panels (and a video) over 0.8 s
        assert hi - lo < 0.3 * walker.win.view.duration + 0.05, (lo, hi)
        written = timed(walker.exports)
        timed(walker.close_panels)
        assert_no_errors(walker.errors, where)
        assert walker.shows(kind), where
        visited.append((kind, len(written)))
        with capsys.disabled():
            print(f"\n{where}: {len(written)} files written, {time.perf_counter() - clock:.0f} s", end="")
    with capsys.disabled():
        print("\norder test: " + ", ".join(f"{k} ({n} files)" for k, n in visited))
        print("time per action: " + ", ".join(f"{k} {v:.0f} s" for k, v in spent.items()))
