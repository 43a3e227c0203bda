"""What the main window shows, without Qt: the viewer's state and its request/stale-result logic.

:class:`ViewerModel` holds the corpus, the model, the synthesis settings, the utterances opened
from files, the current :class:`~facetraj_app.state.UtteranceView` and the latest synthesis request. Every
new request (another utterance, other settings) gets a higher generation number; a result that
arrives for an older generation, or for a model that has since been replaced, is stale and is
dropped (:meth:`ViewerModel.accept`). The slow parts (:func:`load_model`, :meth:`SynthRequest.run`,
:func:`correlation_sweep`) are plain functions meant for a worker thread; the window
(``app/main_window.py``) runs them with its task runner and lays the results out. Nothing here
imports Qt, so the logic is tested without a display (tests/test_viewer_model.py), in the way
napari's ``ViewerModel`` sits under its Qt viewer.
"""

from __future__ import annotations

import logging
import math
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from facetraj_engine.analysis.apertures import label_at
from facetraj_engine.config import SynthConfig
from facetraj_engine.data import Utterance
from facetraj_engine.errors import FacetrajError
from facetraj_engine.evaluation.paper import FIGURE4_TEXT
from facetraj_engine.evaluation.scores import evaluate_utterance
from facetraj_engine.io.corpus import Corpus, held_transcript, label_source
from facetraj_engine.io.labelfiles import LABEL_SUFFIXES
from facetraj_engine.method.model import Model
from facetraj_engine.method.modes import choose_mode
from facetraj_engine.method.resynthesis import SynthesisMemo
from facetraj_engine.progress import Progress

from .phases import mark
from .pins import PinBoard
from .provenance import LabelOrigin, search_key, settings_text
from .state import UtteranceView, build_view

log = logging.getLogger(__name__)

#: the sentence shown first: the held-out example of the paper's Figure 4
DEFAULT_SENTENCE = FIGURE4_TEXT


def normalise_text(text: str) -> str:
    """Lower case, letters and single spaces only (for matching sentences).

    >>> normalise_text("Tornadoes often destroy, acres!")
    'tornadoes often destroy acres'
    """
    return " ".join(re.sub(r"[^a-z' ]+", " ", text.lower()).split())


@dataclass(frozen=True, eq=False)
class SynthRequest:
    """One synthesis asked for: which utterance (loaded by ``load``), with which model and settings.

    ``new_utterance`` is True when the utterance is not the one shown (the clock rewinds and the
    zoom resets when it arrives); ``generation`` orders the requests.
    """

    load: Callable[[], Utterance]
    split: str
    new_utterance: bool
    model: Model
    config: SynthConfig
    generation: int
    mode_chosen: bool = False
    origin: LabelOrigin | None = None      # the label file or transcript, when known
    relabelled: bool = False               # other labels than the utterance's own (labels box)
    memo: SynthesisMemo | None = None      # the recording's last synthesis (another label set)

    def run(self, progress: Progress | None = None) -> UtteranceView:
        """Load and synthesize (slow: run in a worker). Without phone labels the synthesis is
        acoustic-only, and with labels not hand-checked robust unless the user chose the mode
        (:func:`facetraj_engine.method.modes.choose_mode`)."""
        utt = self.load()
        mark(f"utterance {utt.name} read")
        if progress is not None:
            progress(0.3, f"synthesizing {utt.name}")
        choice = choose_mode(self.config, utt.phones, utt.provenance, explicit=self.mode_chosen,
                             tuned=self.model.tuned)
        return build_view(self.model, utt, self.split, choice.config, choice.describe(),
                          self.origin, self.memo)


@dataclass
class ViewerModel:
    """The viewer's state: corpus, model, settings, the current view and the latest request."""

    synth_config: SynthConfig = field(default_factory=SynthConfig)
    corpus: Corpus | None = None
    model: Model | None = None
    texts: dict[str, str] = field(default_factory=dict)
    external: dict[str, Utterance] = field(default_factory=dict)
    external_origin: dict[str, LabelOrigin] = field(default_factory=dict)
    view: UtteranceView | None = None
    pending_utterance: str | None = None     # asked for before the model was ready
    pending_time: float | None = None        # where the first utterance starts
    show_default: bool = True                # the next model shows a corpus utterance first
    #                                          (not: recordings opened with it; once)
    request: SynthRequest | None = None      # the latest utterance asked for
    generation: int = 0
    mode_chosen: bool = False                # the user picked a search mode in the settings
    pins: PinBoard = field(default_factory=PinBoard)   # results kept to compare (app/pins.py)
    model_load: int = 0                      # the latest model asked for (a corpus opened)
    loading: bool = False                    # whether that model is on its way
    memo: SynthesisMemo = field(default_factory=SynthesisMemo)  # the recording on screen's

    # ------------------------------------------------------------------ corpus and model
    def begin_model_load(self) -> int:
        """A corpus was opened: its model is on its way. Returns its number; a model that
        arrives for an older number (a corpus opened before the last one) is stale
        (:meth:`is_latest_load`)."""
        self.model_load += 1
        self.loading = True
        return self.model_load

    def is_latest_load(self, number: int) -> bool:
        return number == self.model_load

    def end_model_load(self, number: int) -> None:
        """The model ``number`` failed to load: the one in use stays (if it is the latest)."""
        if self.is_latest_load(number):
            self.loading = False

    @property
    def ready(self) -> bool:
        """Whether a model is in use and no other is on its way (a recording opened now is
        synthesized with the model the user sees)."""
        return self.model is not None and not self.loading

    def set_model(self, corpus: Corpus, model: Model, texts: dict[str, str]) -> str | None:
        """Use a newly loaded corpus and model: forget the view, the request and the utterances
        opened from files. Returns the utterance to show first (the one asked for, or the default)."""
        self.corpus, self.model, self.texts = corpus, model, texts
        self.loading = False
        self.pins.set_model(Path(corpus.root).name, model.marker_names)   # pins are kept
        self.external.clear()
        self.external_origin.clear()
        self.view = None
        self.request = None
        first = self.pending_utterance or (self.default_utterance() if self.show_default else None)
        self.pending_utterance, self.show_default = None, True
        return first

    def default_utterance(self) -> str | None:
        """The test sentence "Tornadoes often destroy acres of farm land" (paper Figure 4), else
        the first test utterance."""
        if self.corpus is None:
            return None
        info = self.corpus.info
        want = normalise_text(DEFAULT_SENTENCE)
        for utt_id in [*info.test, *info.train]:
            if normalise_text(self.texts.get(utt_id, "")) == want:
                return utt_id
        return (info.test or info.train or [None])[0]

    def external_name(self, stem: str, suffix: str = "") -> str:
        """The name a recording opened from a file is shown under: its ``stem``, or where a
        corpus utterance has that name the file's name (``s002.flac`` beside the corpus's
        ``s002``; a prime added only if that is taken too)."""
        ids = set(self.corpus.info.ids) if self.corpus else set()
        name = stem if stem not in ids else f"{stem}{suffix}"
        while name in ids:
            name += "'"
        return name

    def add_external(self, utt: Utterance, origin: LabelOrigin | None = None) -> str:
        """Keep an utterance opened from files (and where its labels came from) under a name no
        corpus utterance has (:meth:`external_name`); return it."""
        name = self.external_name(utt.name)
        if utt.markers is None and self.model is not None:     # opened while another model
            utt = replace(utt, marker_names=list(self.model.marker_names),   # was in use
                          marker_rate=self.model.marker_rate)
        self.external[name] = replace(utt, name=name)
        self.external_origin[name] = origin or LabelOrigin(utt.label_source)
        return name

    # ------------------------------------------------------------------ requests
    def request_utterance(self, utt_id: str) -> SynthRequest | None:
        """A request for utterance ``utt_id`` (None while no model: it is shown once one is).

        Raises :class:`FacetrajError` for an id that is neither in the corpus nor opened."""
        if self.model is None:
            self.pending_utterance = utt_id
            return None
        if utt_id in self.external:
            utt = self.external[utt_id]
            return self._new_request(lambda: utt, "external", True, self.external_origin.get(utt_id))
        if self.corpus is None:
            return None
        corpus, info = self.corpus, self.corpus.info
        if utt_id not in info.ids:
            raise FacetrajError(f"{utt_id}: no such utterance in {corpus.root}")
        split = "test" if utt_id in info.test else "train"
        try:
            source = label_source(corpus.data_root, utt_id)
        except FacetrajError:           # reading the utterance reports it
            origin = None
        else:             # a label file, or a marker file's own (MVIEW's PHONES)
            held = source.suffix.lower() not in LABEL_SUFFIXES
            origin = LabelOrigin("file", file=f"{source.name}{' (PHONES)' if held else ''}")
        return self._new_request(lambda: corpus.utterance(utt_id), split, True, origin)

    def request_labels(self, utt: Utterance, origin: LabelOrigin,
                       own: bool = False) -> SynthRequest | None:
        """A request for the utterance on screen with other labels (``utt``: the same audio and
        markers, the labels of another source; ``own``: its own again; ``app/label_sources.py``):
        not a new utterance (the clock and the zoom stay), its split kept; an opened recording
        keeps them."""
        if self.model is None or self.view is None or utt.name != self.view.utterance.name:
            return None
        if utt.name in self.external:
            self.external[utt.name] = utt
            self.external_origin[utt.name] = origin
        return self._new_request(lambda: utt, self.view.split, False, origin,
                                 relabelled=not own and self.view.split != "external")

    def set_config(self, config: SynthConfig, explicit: bool = False) -> tuple[bool, SynthRequest | None]:
        """Use new settings: (whether they changed, the re-synthesis of the latest request).
        ``explicit``: the user chose the search (``config.mode``): the labels' rule must not switch
        it (``choose_mode(explicit=True)``), and the utterance is synthesized again when the search
        shown differs, even with unchanged settings (choosing "phonetic" while the robust search
        chosen for aligned labels was shown did nothing)."""
        changed = config != self.synth_config
        shown = self.view.synthesis.config if self.view is not None else None
        if explicit:
            self.mode_chosen = True
            if shown is not None and search_key(shown) == search_key(config) and (
                    shown.with_(mode=config.mode) == config.with_(mode=shown.mode)):
                self.synth_config = config      # the view shows it already: nothing to redo
                return changed, None
            if not changed and shown is None:
                return False, None
        elif not changed:
            return False, None
        else:
            self.mode_chosen |= config.mode != self.synth_config.mode
        self.synth_config = config
        req = self.request
        if req is None:
            return changed, None
        # the utterance asked for last (it may still be on its way)
        return changed, self._new_request(req.load, req.split, req.new_utterance, req.origin,
                                          req.relabelled)

    def _new_request(self, load: Callable[[], Utterance], split: str, new_utterance: bool,
                     origin: LabelOrigin | None = None, relabelled: bool = False) -> SynthRequest:
        """The next request; another utterance gets a memo of its own (the last one's work is
        of no use to it), the utterance shown keeps its memo (a label edit, other settings)."""
        assert self.model is not None
        self.generation += 1
        if new_utterance:
            self.memo = SynthesisMemo()
        self.request = SynthRequest(load, split, new_utterance, self.model, self.synth_config,
                                    self.generation, self.mode_chosen, origin, relabelled, self.memo)
        return self.request

    @property
    def relabelled(self) -> bool:
        """Whether the corpus utterance shown has other labels than its own (labels box): its
        correlations are not the browser's."""
        return self.request is not None and self.request.relabelled

    def is_current(self, request: SynthRequest) -> bool:
        """Whether ``request`` is still the latest (no newer request, the same model)."""
        return request.generation == self.generation and request.model is self.model

    def accept(self, request: SynthRequest, view: UtteranceView) -> bool:
        """Make ``view`` (the result of ``request``) current; False (and nothing changes) when the
        result is stale. The shown utterance becomes the latest request (no longer new)."""
        if not self.is_current(request):
            return False
        self.view = view
        utt = view.utterance
        self.request = replace(request, load=lambda: utt, split=view.split, new_utterance=False)
        return True

    def take_pending_time(self, default: float) -> float:
        """The start time asked for on the command line (once), else ``default``."""
        if self.pending_time is None:
            return default
        t, self.pending_time = float(self.pending_time), None
        return t

    # ------------------------------------------------------------------ time and frames
    def phone_at(self, t: float) -> str:
        """The phone label at ``t`` seconds ("" outside the labels or without a view)."""
        return "" if self.view is None else label_at(self.view.utterance.phones, t)

    def step_frames_target(self, t: float, n: int) -> float:
        """The time of the frame ``n`` frames after the one at ``t`` (clipped to the view)."""
        v = self.view
        return t if v is None else v.frame_at(t, n) / v.rate

    def step_phone_target(self, t: float, direction: int) -> float:
        """The start of the next (``direction > 0``) or previous phone from ``t``."""
        v = self.view
        if v is None:
            return t
        starts = [s.start for s in v.utterance.phones] or [0.0]
        if direction > 0:
            later = [s for s in starts if s > t + 1e-6]
            return later[0] if later else v.duration
        earlier = [s for s in starts if s < t - 1e-3]
        return earlier[-1] if earlier else 0.0

    def correlation_ids(self) -> list[tuple[str, str]]:
        """(split, id) of every corpus utterance, test first (the browser's score columns)."""
        if self.corpus is None:
            return []
        info = self.corpus.info
        return [(s, u) for s in ("test", "train") for u in getattr(info, s)]


def view_heading(view: UtteranceView, separator: str = " — ") -> str:
    """What is shown: the utterance, its split and, after ``separator``, its sentence (not for
    recognized labels: the sentence is not what they say)."""
    utt = view.utterance
    text = f"{separator}“{utt.text}”" if utt.text and view.label_origin.source != "recognized" else ""
    return f"{utt.name} ({view.split}){text}"


def view_title(view: UtteranceView) -> str:
    """The title over the panels: :func:`view_heading`, then how the synthesis was made
    (:func:`settings_text`), in 2-D for midsagittal data (x = 0 for every marker)."""
    dims = "2-D" if np.nanmax(np.abs(view.shown[..., 0]), initial=0.0) < 1e-9 else "3-D"
    return f"{view_heading(view)}    ·    {dims}: {settings_text(view)}"


def view_summary(view: UtteranceView) -> str:
    """The status line of a new view: frames, rate, speech frames, the labels' origin, the mode
    and why, and the voice match."""
    text = (f"{view.utterance.name}: {view.n_frames} frames at {view.rate:g} Hz, "
            f"{int(view.speech.sum())} speech frames; labels: {view.label_origin.text()}")
    text = f"{text}; {view.mode_reason}" if view.mode_reason else text
    return f"{text}; voice match {view.voice_match:.2f}" if math.isfinite(view.voice_match) else text


def voice_match_tip(view: UtteranceView) -> str:
    """The status line's tooltip: what the voice match means and what it changed in this
    synthesis (:func:`facetraj_engine.method.voice_match.explain_match`), empty without one."""
    from facetraj_engine.method.voice_match import explain_match

    res = view.synthesis
    if not math.isfinite(res.voice_ratio):
        return ""
    kind = view.utterance.provenance.kind if view.utterance.phones else None
    return explain_match(res.voice_ratio, res.config, kind).replace("; here: ", ".\nIn this "
                                                                    "synthesis: ", 1)


def read_texts(corpus: Corpus) -> dict[str, str]:
    """The orthographic text of each utterance: its ``<id>.txt`` file, else the sentence its
    marker file holds (MVIEW's SENTENCE)."""
    texts = {}
    for utt_id in corpus.info.ids:
        p = corpus.data_root / f"{utt_id}.txt"
        if p.exists():
            texts[utt_id] = p.read_text(encoding="utf-8", errors="replace").strip()
        else:
            held = held_transcript(corpus.data_root, utt_id)
            if held:
                texts[utt_id] = held
    return texts


def load_model(corpus: Corpus, model_path: Path | None, progress: Progress,
               load_or_train: Callable[..., Model]) -> tuple[Model, dict[str, str]]:
    """The model for ``corpus`` (from ``model_path``, else ``load_or_train``: the cache or
    training) and the utterance texts (slow: run in a worker)."""
    texts = read_texts(corpus)
    if model_path is not None:
        progress(0.5, f"loading {model_path}")
        model = Model.load(model_path)
    else:
        model = load_or_train(corpus, progress=progress)
    if model.marker_names != corpus.info.marker_names:
        raise FacetrajError(f"{model_path or corpus.root}: the model's marker set differs from the "
                            "corpus")
    return model, texts


def correlation_sweep(model: Model, corpus: Corpus, ids: list[tuple[str, str]], config: SynthConfig,
                      before: Callable[[int, str], None] = lambda k, utt_id: None,
                      ) -> Iterator[tuple[int, str, float, float]]:
    """Lip correlations of each ``(split, id)`` under ``config`` with its own smoothing:
    ``(index, id, lower lip r, upper lip r)``, NaN for an utterance that cannot be read (logged).
    ``before(index, id)`` is called before each utterance (the window reports progress there and
    waits while sound plays)."""
    for k, (split, utt_id) in enumerate(ids):
        before(k, utt_id)
        try:
            utt = corpus.utterance(utt_id)
            score = evaluate_utterance(model, utt, split, config, (config.smoothing,))[0]
            yield k, utt_id, score.lower_lip, score.upper_lip
        except FacetrajError as exc:
            log.warning("%s", exc)
            yield k, utt_id, math.nan, math.nan
