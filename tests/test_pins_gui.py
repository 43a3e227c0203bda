"""Compare's pins in the window: a pin pushed out by a new one (at most ``MAX_PINS`` kept) is no
longer drawn, in the lip panels, the difference panel or the legend row, without waiting for
the next result."""

from __future__ import annotations

import os

import pytest

pytest.importorskip("pytestqt")
pytest.importorskip("pyvistaqt")

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

from screens import opened_window, resynthesize

pytestmark = pytest.mark.gui

WAIT_MS = 240_000


@pytest.fixture
def win(qtbot, trained_cache):
    yield from opened_window(qtbot, "s002", WAIT_MS)


def drawn_pin_lines(w, colors: set[str]) -> list:
    """The lines of the lip and difference panels drawn in one of ``colors``."""
    tl = w.timeline
    tl.canvas.finish()
    titles = ("upper lip y", "lower lip y", w.extension("compare").panel.title)
    return [line for p in tl.shown if p.title in titles for line in tl.axes_of(p).lines
            if line.get_color() in colors]


def test_a_pin_pushed_out_is_no_longer_drawn(win, qtbot):
    """Pin three results (N = 3, 1, 2), synthesize a fourth (N = 4) and pin it too: the oldest
    pin goes, and the panels at once draw only the two pins left (the fourth is the result on
    screen) and the legend row no longer names the first."""
    from facetraj_app.pins import MAX_PINS

    w = win
    compare = w.extension("compare")
    for n in (1, 2, 4):
        compare.pin()
        resynthesize(w, qtbot, lambda n=n: w.set_synth_config(w.synth_config.with_(n_context_phones=n)),
                     WAIT_MS)
    assert MAX_PINS == 3 and len(w.pins) == 3
    first, *kept = w.pins.pins
    assert w.pins.shown(w.view) == [first, *kept]
    assert any(e.label.startswith(f"{first.name}: ") for e in w.timeline.legend)
    compare.pin()                                   # the fourth: the first goes
    assert first not in w.pins.pins and w.pins.shown(w.view) == kept
    qtbot.waitUntil(lambda: w.settled, timeout=WAIT_MS)
    labels = [e.label for e in w.timeline.legend]
    assert not any(label.startswith(f"{first.name}: ") for label in labels), labels
    assert all(any(label.startswith(f"{p.name}: ") for label in labels) for p in kept), labels
    colors = {p.color for p in kept}
    lines = drawn_pin_lines(w, {first.color} | colors)
    assert {line.get_color() for line in lines} == colors       # the first's colour: gone
    assert len(lines) == 3 * len(kept)          # upper, lower lip and difference: each pin once
    assert w.face.pins == kept
