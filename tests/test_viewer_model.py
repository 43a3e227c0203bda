"""The viewer's Qt-free state model (app/viewer_model.py), without a display or a QApplication:
requests and their generation numbers, stale results, settings changes, the frame and phone
arithmetic of the transport, and the correlation sweep; plus the worker gate (app/workers.py)."""

from __future__ import annotations

import math
import subprocess
import sys
import threading
from dataclasses import replace
from pathlib import Path

import pytest

from facetraj_app.viewer_model import SynthRequest, ViewerModel, correlation_sweep, load_model, read_texts
from facetraj_engine.data import Provenance
from facetraj_engine.errors import FacetrajError, InputError

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture
def state(toy_corpus, toy_model) -> ViewerModel:
    st = ViewerModel()
    st.set_model(toy_corpus, toy_model, {})
    return st


def test_viewer_model_imports_no_gui_library():
    code = ("import sys, facetraj_app.viewer_model, facetraj_app.state; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('PyQt6', 'pyvista', 'pyvistaqt', "
            "'matplotlib')]; print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_utterance_asked_for_before_the_model_is_shown_first(toy_corpus, toy_model):
    st = ViewerModel()
    wanted = toy_corpus.info.train[2]
    assert st.request_utterance(wanted) is None          # no model yet: remembered
    assert st.generation == 0
    assert st.set_model(toy_corpus, toy_model, {}) == wanted
    # without it (and no text matching the default sentence): the first test utterance
    assert st.set_model(toy_corpus, toy_model, {}) == toy_corpus.info.test[0]
    st.texts = {toy_corpus.info.train[1]: "Tornadoes often destroy acres of farm land."}
    assert st.default_utterance() == toy_corpus.info.train[1]


def test_requests_name_their_split_and_unknown_ids_are_refused(state, toy_corpus):
    info = toy_corpus.info
    r1 = state.request_utterance(info.test[0])
    r2 = state.request_utterance(info.train[0])
    assert (r1.split, r2.split) == ("test", "train")
    assert (r1.generation, r2.generation) == (1, 2) and r1.new_utterance and r2.new_utterance
    assert state.request is r2
    with pytest.raises(FacetrajError, match=f"nope: no such utterance in {toy_corpus.root}"):
        state.request_utterance("nope")
    assert state.request is r2 and state.generation == 2


def test_stale_results_are_dropped(state, toy_corpus, toy_model):
    info = toy_corpus.info
    old = state.request_utterance(info.test[0])
    new = state.request_utterance(info.test[1])
    view_old, view_new = old.run(), new.run()
    assert view_old.utterance.name == info.test[0] and view_new.utterance.name == info.test[1]
    assert not state.accept(old, view_old) and state.view is None      # overtaken by ``new``
    assert state.accept(new, view_new) and state.view is view_new
    # the shown utterance is now the latest request, no longer a new one
    assert state.request.new_utterance is False and state.request.load() is view_new.utterance
    # a result computed with a model that has since been replaced is stale too
    again = state.request_utterance(info.test[2])
    state.set_model(toy_corpus, replace(toy_model), {})
    assert not state.is_current(again)
    assert state.view is None and state.request is None


def test_other_labels_of_the_utterance_shown_keep_its_place(state, toy_corpus):
    """A label source switched on a corpus utterance (the labels box): the same utterance, its
    split kept, not a new utterance (the clock and the zoom stay), marked as relabelled (its
    correlations are not the browser's) also when the settings change after; its own labels
    again: not relabelled."""
    from facetraj_app.provenance import LabelOrigin

    utt_id = toy_corpus.info.test[0]
    req = state.request_utterance(utt_id)
    view = req.run()
    assert state.accept(req, view) and not state.relabelled
    other = replace(view.utterance, phones=[], label_source="none")
    assert state.request_labels(replace(other, name="elsewhere"), LabelOrigin("none")) is None
    again = state.request_labels(other, LabelOrigin("none"))
    assert (again.split, again.new_utterance, again.relabelled) == ("test", False, True)
    relabelled = again.run()
    assert state.accept(again, relabelled) and state.relabelled
    assert relabelled.synthesis.config.mode == "acoustic" and relabelled.utterance.name == utt_id
    _, resynth = state.set_config(state.synth_config.with_(n_context_phones=1))
    assert resynth.relabelled and resynth.load() is other
    own = state.request_labels(view.utterance, LabelOrigin("file"), own=True)
    assert not own.relabelled


def test_new_settings_resynthesize_the_latest_request(state, toy_corpus):
    cfg = state.synth_config
    assert state.set_config(cfg) == (False, None)                 # unchanged: nothing to do
    changed, none = state.set_config(cfg.with_(n_context_phones=1))
    assert changed and none is None                               # nothing asked for yet
    req = state.request_utterance(toy_corpus.info.test[0])
    changed, again = state.set_config(cfg.with_(n_context_phones=2))
    assert changed and again.generation == req.generation + 1
    assert again.load is req.load and again.new_utterance      # still on its way: still new
    assert again.config.n_context_phones == 2 and not state.is_current(req)
    view = again.run()
    assert view.synthesis.config.n_context_phones == 2


def test_opened_audio_without_labels_is_synthesized_acoustic_only(state, toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    name = state.add_external(replace(utt, phones=[], markers=None))
    assert name == utt.name + "'"                   # the corpus already has that name
    # a file of that name: shown under its file name (the prime only if that is taken too)
    assert state.external_name(utt.name, ".flac") == f"{utt.name}.flac"
    assert state.external_name("fresh", ".wav") == "fresh"
    req = state.request_utterance(name)
    assert isinstance(req, SynthRequest) and req.split == "external"
    view = req.run()
    assert view.synthesis.config.mode == "acoustic" and view.original is None
    assert state.synth_config.mode == "phonetic"    # the settings themselves are unchanged


def test_aligned_labels_are_synthesized_robust_unless_the_user_chose_a_mode(state, toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    name = state.add_external(replace(utt, markers=None, label_source="aligned",
                                      provenance=Provenance("aligned")))
    assert state.request_utterance(name).run().synthesis.config.mode == "robust"
    # the user picks phonetic in the settings (away and back): eq 4 trusts the labels, as asked
    state.set_config(state.synth_config.with_(mode="acoustic"))
    state.set_config(state.synth_config.with_(mode="phonetic"))
    assert state.mode_chosen
    assert state.request_utterance(name).run().synthesis.config.mode == "phonetic"
    # the corpus's own (hand-checked) labels keep the paper's phonetic search
    fresh = ViewerModel()
    fresh.set_model(toy_corpus, state.model, {})
    assert fresh.request_utterance(utt.name).run().synthesis.config.mode == "phonetic"


def test_choosing_the_search_shown_is_explicit_and_the_title_names_the_search_used(state, toy_corpus):
    """Choosing the search the view shows (the one the labels made the engine use) is the user's
    choice from then on, with no synthesis to redo; choosing phonetic where robust is shown is
    obeyed although the settings already asked for phonetic. The title and status line say the
    search the synthesis used and where the labels came from."""
    from facetraj_app.provenance import LabelOrigin
    from facetraj_app.viewer_model import view_summary, view_title

    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    name = state.add_external(replace(utt, markers=None, label_source="aligned", text="a b c",
                                      provenance=Provenance("aligned")),
                              LabelOrigin("aligned", transcript="x.txt"))
    req = state.request_utterance(name)
    view = req.run()
    assert state.accept(req, view) and view.synthesis.config.mode == "robust"
    assert "robust, N=3" in view_title(view) and "labels: aligned from x.txt" in view_title(view)
    assert "“a b c”" in view_title(view)
    assert "labels: aligned from x.txt; robust mode: aligned labels are not hand-checked" in \
        view_summary(view)
    changed, again = state.set_config(state.synth_config, explicit=True)       # phonetic: obeyed
    assert not changed and again is not None and again.mode_chosen
    view = again.run()
    assert state.accept(again, view) and view.synthesis.config.mode == "phonetic"
    assert "phonetic (the paper), N=3" in view_title(view)
    generation = state.generation
    changed, again = state.set_config(state.synth_config, explicit=True)       # shown: nothing
    assert (changed, again, state.generation) == (False, None, generation)
    # recognized labels: not the transcript in the title; acoustic: no N, the index's K named
    state.add_external(replace(utt, markers=None, label_source="recognized", text="a b c",
                               name="r"))
    req = state.request_utterance("r")
    view = req.run()
    assert "“" not in view_title(view) and "recognized from the speech" in view_title(view)
    state.set_config(state.synth_config.with_(mode="acoustic", acoustic_prefilter=None), explicit=True)
    view = state.request.run()
    assert "acoustic only, whole codebook (the paper);  labels:" in view_title(view)


def test_provenance_doctests():
    import doctest

    import facetraj_app.provenance

    assert doctest.testmod(facetraj_app.provenance).failed == 0


def test_frame_and_phone_arithmetic(state, toy_corpus):
    req = state.request_utterance(toy_corpus.info.test[0])
    state.accept(req, req.run())
    view = state.view
    assert view.rate == pytest.approx(60.0)
    assert view.frame_at(0.51) == 31 and view.frame_at(-1.0) == 0
    assert view.frame_at(1e6) == view.n_frames - 1
    assert state.step_frames_target(0.51, 1) == pytest.approx(32 / 60)
    assert state.step_frames_target(0.0, -1) == 0.0
    phones = view.utterance.phones
    second = phones[1]
    mid = (second.start + second.end) / 2
    assert state.phone_at(mid) == second.label
    assert state.phone_at(view.duration + 1.0) == ""
    assert state.step_phone_target(mid, 1) == pytest.approx(phones[2].start)
    assert state.step_phone_target(mid, -1) == pytest.approx(second.start)
    assert state.step_phone_target(second.start, -1) == pytest.approx(phones[0].start)
    assert state.step_phone_target(phones[-1].start + 1e-3, 1) == pytest.approx(view.duration)


def test_phone_lookup_without_a_view():
    st = ViewerModel()
    assert st.phone_at(0.3) == "" and st.step_phone_target(0.3, 1) == 0.3
    assert st.correlation_ids() == [] and st.default_utterance() is None


def test_pending_time_is_used_once():
    st = ViewerModel(pending_time=1.25)
    assert st.take_pending_time(0.0) == 1.25
    assert st.take_pending_time(0.5) == 0.5


def test_correlation_sweep_reports_each_utterance(state, toy_corpus, toy_model):
    ids = state.correlation_ids()[:3]
    assert ids[0] == ("test", toy_corpus.info.test[0])

    class OneMissing:                       # the corpus, with one utterance that cannot be read
        info = toy_corpus.info

        def utterance(self, utt_id):
            if utt_id == ids[1][1]:
                raise InputError(Path(f"{utt_id}.wav"), "not a WAV file")
            return toy_corpus.utterance(utt_id)

    seen = []
    rows = list(correlation_sweep(toy_model, OneMissing(), ids, state.synth_config,
                                  lambda k, utt_id: seen.append((k, utt_id))))
    assert seen == [(k, u) for k, (_s, u) in enumerate(ids)]
    assert [r[:2] for r in rows] == seen
    assert math.isnan(rows[1][2]) and math.isnan(rows[1][3])
    for _k, _u, lower, upper in (rows[0], rows[2]):
        assert -1.0 <= lower <= 1.0 and -1.0 <= upper <= 1.0


def test_load_model_checks_the_marker_set(toy_corpus, toy_model, tmp_path):
    path = tmp_path / "m.npz"
    toy_model.save(path)
    messages = []
    model, texts = load_model(toy_corpus, path, lambda f, m="": messages.append(m), None)
    assert model.marker_names == toy_corpus.info.marker_names and messages == [f"loading {path}"]
    assert texts == read_texts(toy_corpus)


def test_gate_wakes_its_waiter_without_polling():
    from facetraj_app.workers import Gate

    gate = Gate(is_open=False)
    result: list[bool] = []
    waiting = threading.Thread(target=lambda: result.append(gate.wait_open()))
    waiting.start()
    waiting.join(0.05)
    assert waiting.is_alive() and not result            # closed: still waiting
    gate.set_open(True)
    waiting.join(5)
    assert result == [True]
    stop = threading.Event()
    gate.set_open(False)
    waiting = threading.Thread(target=lambda: result.append(gate.wait_open(stop.is_set)))
    waiting.start()
    stop.set()
    gate.wake()                                         # as cancelling a task does
    waiting.join(5)
    assert result == [True, False]
