"""Measure's words and Compare's pins without a display (app/measure_model.py, app/pins.py,
app/panel_layout.py): the readout at the /b/ of "boy" against the engine's numbers, the table's
filter, the pins kept, shown and let go, and the panels' heights on a short timeline."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from facetraj_app.measure_model import Measure
from facetraj_app.panel_layout import fit_heights
from facetraj_app.pins import MAX_PINS, PIN_COLORS, PinBoard, aperture_difference
from facetraj_app.state import build_view
from facetraj_engine.analysis.apertures import aperture, readout_at
from facetraj_engine.config import SynthConfig


@pytest.fixture(scope="module")
def views(default_model, default_corpus):
    utt = default_corpus.utterance("s002")
    return (build_view(default_model, utt, "train", SynthConfig()),
            build_view(default_model, utt, "train", SynthConfig(n_context_phones=1)))


def test_the_readout_at_the_b_of_boy(default_model, views):
    n3, n1 = views
    pins = PinBoard(model_name="data_samples", marker_names=tuple(default_model.marker_names))
    pin = pins.pin(n3)
    assert pins.shown(n3) == [] and pins.shown(n1) == [pin]        # not with itself
    m = Measure()
    m.set_view(n1, default_model.upper_lip, default_model.lower_lip, pins.shown(n1))
    b = next(p for p in n1.utterance.phones if p.label == "b")
    t = 0.5 * (b.start + b.end)
    text = m.readout_text(t)
    r = readout_at(t, n1.times, n1.shown, default_model.upper_lip, default_model.lower_lip,
                   n1.original, n1.utterance.phones, n1.utterance.words)
    p = readout_at(t, n3.times, n3.shown, default_model.upper_lip, default_model.lower_lip)
    assert text.startswith(f"{t:.3f} s  /b/ in “boy”")
    assert f"aperture {r.aperture:.1f} mm" in text
    assert f"original {r.original_aperture:.1f} mm (synthesized − original {r.difference:+.1f} mm)" in text
    assert f"pin 1 /b/ {p.aperture:.1f} mm (this − pin 1 {r.aperture - p.aperture:+.1f} mm)" in text
    rows = m.rows("b, /oy/")
    assert {row.phone for row in rows} == {"b", "oy"} and rows == sorted(rows, key=lambda x: x.start)
    assert m.rows("") == m.rows() and len(m.rows()) > len(rows)
    labels = m.frame_labels()
    assert labels["phone"][n1.frame_at(t)] == "b" and labels["word"][n1.frame_at(t)] == "boy"
    diff = aperture_difference(n1, pin, default_model.upper_lip, default_model.lower_lip)
    np.testing.assert_allclose(diff, aperture(n1.shown, default_model.upper_lip, default_model.lower_lip)
                               - aperture(n3.shown, default_model.upper_lip, default_model.lower_lip))


def test_pins_keep_three_in_distinct_colours_and_name_their_settings(default_model, views):
    n3, n1 = views
    pins = PinBoard(model_name="data_samples", marker_names=tuple(default_model.marker_names))
    assert pins.pin(n3) is pins.pin(n3) and len(pins) == 1         # the same result: pinned once
    kept = [pins.pins[0], *(pins.pin(v) for v in (n1, replace(n3), replace(n1)))]   # 4 results
    assert len(pins) == MAX_PINS and kept[0] not in pins.pins      # the oldest went
    assert sorted(p.color for p in pins.pins) == sorted(PIN_COLORS)
    assert kept[3].color == kept[0].color                          # its colour reused
    assert "N=1" in kept[1].legend("data_samples") and "model " not in kept[1].legend("data_samples")
    assert kept[1].legend("my_corpus").endswith("; model data_samples")
    pins.set_model("other", ["A", "B"])                            # another marker set: not shown
    assert pins.shown(n1) == []
    pins.clear()
    assert len(pins) == 0


def test_a_short_timeline_leaves_out_the_spectrogram_first():
    # waveform, spectrogram, phones, upper lip, lower lip, aperture (the window's priorities)
    heights, least, priority = [0.8, 1.3, 0.8, 1.2, 1.2, 0.9], [24, 40, 30, 72, 72, 48], \
        [20, 10, 90, 100, 100, 50]
    tall = fit_heights(heights, least, priority, 700)
    assert None not in tall and all(h >= m for h, m in zip(tall, least, strict=True))
    short = fit_heights(heights, least, priority, 300)
    assert short[1] is None and short[0] is not None                # the spectrogram first
    shorter = fit_heights(heights, least, priority, 260)
    assert shorter[0] is None and shorter[1] is None
    assert all(h >= m for h, m in zip(shorter, least, strict=True) if h is not None)
    assert sum(h for h in shorter if h is not None) + 6 * 3 <= 260


def test_the_table_has_a_column_per_pin_and_the_csv_too(default_model, views, tmp_path):
    """Each pin's least aperture over the row's segment (the engine's minimum_within of its own
    aperture track) beside the result on screen's, and this minus it; the CSV's columns
    ``min_pin1_mm`` and ``min_this_minus_pin1_mm`` hold the same numbers; the recipes name how
    each result was made (an acoustic-only result's labels are "not used")."""
    import csv

    from facetraj_app.provenance import settings_text
    from facetraj_engine.analysis.apertures import phone_apertures

    n3, n1 = views
    up, lo = default_model.upper_lip, default_model.lower_lip
    pins = PinBoard(model_name="data_samples", marker_names=tuple(default_model.marker_names))
    pin = pins.pin(n3)
    m = Measure()
    m.set_view(n1, up, lo, pins.shown(n1))
    rows = m.rows("b")
    minima = m.pin_minima(rows)
    pin_ap = aperture(n3.shown, up, lo)
    for r, (value,) in zip(rows, minima, strict=True):
        inside = (n3.times >= r.start) & (n3.times < r.end)
        assert value == pytest.approx(float(pin_ap[inside].min()))
    assert m.pin_columns() == ["min: pin 1", "min: this − pin 1"]
    back = list(csv.DictReader(m.write_csv(tmp_path / "b.csv", "b").open()))
    assert [float(b["min_pin1_mm"]) for b in back] == pytest.approx([v[0] for v in minima], abs=1e-4)
    assert [float(b["min_this_minus_pin1_mm"]) for b in back] == pytest.approx(
        [r.min_synthesized - v[0] for r, v in zip(rows, minima, strict=True)], abs=1e-4)
    assert len(rows) == len([p for p in phone_apertures(n1.times, n1.shown, up, lo, n1.utterance.phones)
                             if p.phone == "b"])
    recipes = m.recipes()
    assert [(r.name, r.labels, r.config) for r in recipes] == [
        ("this", "file", n1.synthesis.config), ("pin 1", "file", n3.synthesis.config)]
    assert recipes[1].settings == pin.settings
    acoustic = replace(n1, synthesis=replace(n1.synthesis, config=n1.synthesis.config.with_(mode="acoustic")))
    assert settings_text(acoustic, short=True).endswith("labels: not used")
    assert "labels: label file" not in settings_text(acoustic, short=True)


def test_the_readout_has_units_and_no_negative_zero(default_model, views):
    from facetraj_app.measure_model import mm
    from facetraj_app.pins import distinct_settings

    _n3, n1 = views
    m = Measure()
    m.set_view(n1, default_model.upper_lip, default_model.lower_lip, [])
    text = m.readout_text(0.5)
    r = m.readout(0.5)
    assert f"upper lip y {r.upper_y:.1f} mm, lower lip y {r.lower_y:.1f} mm" in text
    assert mm(-0.04, signed=True) == "0.0 mm" and mm(-0.06, signed=True) == "-0.1 mm"
    assert distinct_settings(["robust, N=3, triangular; labels: aligned",
                              "robust, N=1, triangular; labels: aligned"]) == ["N=3", "N=1"]


def test_every_setting_that_changes_the_synthesis_tells_two_pins_apart(default_model, views):
    """Issue 54, defect 5: pins at N=2, C=3 and N=2, C=2 both read "N=2"; a result with the
    detector on read as the plain acoustic-only one. Each setting of the synthesis, the labels'
    source and the model tell a pin apart from the result on screen and from the other pins."""
    from facetraj_app.provenance import LabelOrigin, settings_text

    _n3, n1 = views
    base = n1.synthesis.config.with_(n_context_phones=2, context=3)

    def made(view=n1, **changes):
        return replace(view, synthesis=replace(view.synthesis, config=base.with_(**changes)))

    screen = made()
    variants = {"C=2": made(context=2), "N=1": made(n_context_phones=1), "ξ=12": made(xi=12.0),
                "ν=4": made(nu=4.0), "spline": made(smoothing="spline"),
                "closure: rest": made(closure_labels=False), "closure: off": made(closure=False),
                "closure: /p b m/": made(rest=False),
                "labels: aligned from s002.txt": replace(
                    screen, utterance=replace(screen.utterance, label_source="aligned"),
                    origin=LabelOrigin("aligned", transcript="s002.txt"))}
    for differs, view in variants.items():
        pins = PinBoard(model_name="data_samples", marker_names=tuple(default_model.marker_names))
        pin = pins.pin(view)
        assert pins.describe(screen, [pin]) == [differs], differs
    acoustic = made(mode="acoustic")
    detector = made(mode="acoustic", closure_detector=True)
    pins = PinBoard(model_name="data_samples")
    pin = pins.pin(detector)
    assert pins.describe(acoustic, [pin]) == ["closure: /p b m/ + rest + detector"]
    assert "detector" in settings_text(detector) and "detector" not in settings_text(acoustic)
    pins.set_model("my_corpus", [])              # the same settings, another model
    assert pins.describe(detector, [pin]) == ["model data_samples"]
    # two pins and the screen: each pin says what sets it apart
    pins = PinBoard(model_name="data_samples")
    both = [pins.pin(made(context=2)), pins.pin(made(context=1))]
    assert pins.describe(screen, both) == ["C=2", "C=1"]
