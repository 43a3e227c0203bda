"""The synthesis modes, in one place: each mode's name, what it needs, the settings it reads, its
candidate search (paper section 2.3), and THE rule for which mode the labels allow.

A mode is a :class:`Mode`: its ``name`` (``SynthConfig.mode``), how the user knows it, whether
it needs phone labels and weighs them by their confidence, whether the model's cross-validated
settings apply, and :meth:`Mode.search`: each frame's candidate codewords and eqs 5-8 over them.
:data:`MODES` lists them in the order the command line and the app offer them; the CLI's
``--mode`` choices, :func:`choose_mode`, the app's selector (:data:`SEARCHES`) and the table in
``docs/labels.md`` (:func:`modes_table`, checked by a test) read it. Adding a mode is a class
here, in :data:`MODES`, and its tests.

The rule (:func:`choose_mode`). The paper's phonetic mode (eq 4) trusts its labels fully: right
for hand-checked labels, wrong for labels from an aligner or a recognizer, whose errors it copies
into the face. So the mode follows the labels' provenance (``facetraj_engine.labels.provenance``):

- no labels: acoustic-only (the paper's "5N replaced with the whole codebook");
- hand-checked labels: the paper's phonetic mode;
- aligned or recognized labels: the robust mode (``facetraj_engine.method.selection``), each phone's label
  counting as much as its maker trusted it, with the settings cross-validated at training
  (:func:`tuned_config`, ``facetraj train``);
- a mode the user chose explicitly is kept (acoustic-only when there are no labels at all).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

from ..config import SynthConfig
from ..data import PhoneSegment, Provenance

if TYPE_CHECKING:                   # the searches import the method (numpy, scipy) when they run
    from .search import SearchInput, SearchResult

#: Settings a tuning stores and :func:`tuned_config` applies (the SynthConfig fields it may change).
TUNED_FIELDS = ("n_context_phones", "xi", "label_weight", "context_weight", "robust_candidates",
                "gamma_max", "triangle_s", "chain_beta")


@dataclass(frozen=True)
class Search:
    """A search the app's selector offers: a mode and the settings that make it (``acoustic-full``:
    the acoustic-only mode over the whole codebook, as the paper does); its name in the selector
    (``label``, short), in the window's title (``title``), and one line on what it does."""

    key: str
    mode: str
    label: str
    title: str
    note: str
    settings: Mapping[str, Any] = field(default_factory=dict)


class Mode:
    """A synthesis mode (a subclass per mode; one instance each in :data:`MODES`)."""

    name: ClassVar[str]
    #: how the user knows it, and one line on what it does (the CLI's help, the docs)
    title: ClassVar[str]
    help: ClassVar[str]
    #: phone labels required; label confidences weigh the search; the model's tuned settings apply
    needs_labels: ClassVar[bool] = False
    weighs_labels: ClassVar[bool] = False
    tuned: ClassVar[bool] = False
    #: the SynthConfig fields the search reads beyond eqs 5-8's gamma grid
    settings: ClassVar[tuple[str, ...]] = ()
    #: the selector's entries for this mode
    searches: ClassVar[tuple[Search, ...]] = ()

    def search(self, job: SearchInput) -> SearchResult:
        raise NotImplementedError

    def describe(self, config: SynthConfig) -> str:
        """The mode as the user knows it, with the search ``config`` makes of it."""
        return self.name


class Phonetic(Mode):
    """The paper's mode (eq 4): the labels pick each phone's N context-phones, eqs 5-8 weigh their
    5N codewords; the frames of a phone the model has never seen are filled by the acoustic-only
    search (issue 38: a small model no longer refuses a whole file for one phone)."""

    name = "phonetic"
    title = "phonetic (the paper)"
    help = "the paper's eq 4, labels trusted (default for hand-checked labels)"
    needs_labels = True
    settings = ("n_context_phones", "context", "xi", "nu")
    searches = (Search("phonetic", "phonetic", "phonetic (the paper)", "phonetic (the paper)",
                       "phonetic (the paper): the labels alone pick the N context-phones searched "
                       "(eq 4); best with hand-checked labels."),)

    def search(self, job: SearchInput) -> SearchResult:
        from .search import SearchResult, acoustic_candidates, eq4, weighted
        from .synthesis import FrameWeights

        model, config = job.model, job.config
        segments, frame_seg, candidates = eq4(model, job.segs, job.times, config)
        unseen = job.unlabelled[frame_seg] if job.unlabelled is not None else None
        if unseen is None or not unseen.any():
            return SearchResult(weighted(model, job.w, lambda a, b: candidates[a:b], config),
                                segments, frame_seg)
        # a phone the model has never seen: its frames filled by the acoustic-only search
        seen_w, unseen_w, kept = job.w[~unseen], job.w[unseen], candidates[~unseen]
        fw = FrameWeights.merged(
            unseen,
            weighted(model, unseen_w, lambda a, b: acoustic_candidates(model, unseen_w[a:b], config),
                     config),
            weighted(model, seen_w, lambda a, b: kept[a:b], config))
        return SearchResult(fw, segments, frame_seg)


class Robust(Mode):
    """Eq 4's codewords and the acoustically nearest together, each label counting as much as its
    maker trusted it (``facetraj_engine.method.selection``), the weights chained over frames."""

    name = "robust"
    title = "robust"
    help = ("eq 4 and acoustic candidates weighted by label confidence (default for aligned or "
            "recognized labels)")
    needs_labels = weighs_labels = tuned = True
    settings = ("n_context_phones", "context", "xi", "nu", "robust_candidates", "label_weight",
                "label_weight_by_voice", "context_weight", "mean_normalise", "chain_beta",
                "acoustic_probe")
    searches = (Search("robust", "robust", "robust (labels weighted)", "robust",
                       "robust: eq 4's and the acoustically nearest codewords together; each label "
                       "counts as much as the aligner/recognizer trusts it (default for automatic "
                       "labels)."),)

    def search(self, job: SearchInput) -> SearchResult:
        from .chain import chain_pcs
        from .resynthesis import chained_pcs
        from .search import SearchResult, eq4, robust_weights
        from .voice_match import label_weight_scale, trust_by_voice

        model, config = job.model, job.config
        segments, frame_seg, candidates = eq4(model, job.segs, job.times, config)
        conf = trust_by_voice(job.confidence, job.voice_ratio, config.label_weight_by_voice)
        conf[job.unlabelled[frame_seg]] = 0.0
        scale = label_weight_scale(job.voice_ratio, config.label_weight_by_voice)
        fw = robust_weights(model, job.w, candidates, conf, config, scale, memo=job.memo)
        if config.chain_beta > 0 and job.memo is not None:     # only what the edit changed
            fw.pcs = chained_pcs(job.memo, fw.weights, fw.candidates, model.codebook.pcs,
                                 config.chain_beta, model.join_scale)
        elif config.chain_beta > 0:                 # the weights made consistent over time
            fw.pcs = chain_pcs(fw.weights, fw.candidates, model.codebook.pcs, config.chain_beta,
                               model.join_scale)
        return SearchResult(fw, segments, frame_seg)


class Acoustic(Mode):
    """No labels: eqs 5-8 over the codewords nearest to each frame by eq 5, found in the model's
    LSF index, or over the whole codebook as the paper does (``acoustic_prefilter=None``)."""

    name = "acoustic"
    title = "acoustic-only"
    help = "no labels: the codewords nearest to each frame by eq 5 (default without labels)"
    settings = ("acoustic_prefilter", "acoustic_probe")
    searches = (
        Search("acoustic", "acoustic", "acoustic only, indexed", "acoustic only, indexed",
               "acoustic only: no labels; the codewords nearest to each frame by eq 5, found "
               "in the model's LSF index (fast)."),
        Search("acoustic-full", "acoustic", "acoustic only, whole codebook",
               "acoustic only, whole codebook (the paper)",
               "acoustic only, whole codebook: eqs 5-8 over every codeword, as the paper (slow).",
               MappingProxyType({"acoustic_prefilter": None})),
    )

    def search(self, job: SearchInput) -> SearchResult:
        from .search import acoustic_search

        return acoustic_search(job.model, job.w, job.config)

    def describe(self, config: SynthConfig) -> str:
        return "acoustic-only (indexed)" if config.acoustic_prefilter else "acoustic-only (whole codebook)"


#: The modes, in the order the command line and the app offer them.
MODES: Mapping[str, Mode] = MappingProxyType({m.name: m for m in (Phonetic(), Robust(), Acoustic())})
#: Every search the app's selector offers, by key.
SEARCHES: Mapping[str, Search] = MappingProxyType(
    {s.key: s for key in ("robust", "phonetic", "acoustic") for s in MODES[key].searches})


def mode_of(config: SynthConfig) -> Mode:
    """The mode ``config`` names; an unknown name is refused with the ones there are."""
    try:
        return MODES[config.mode]
    except KeyError:
        raise ValueError(f"unknown mode {config.mode!r} ({', '.join(MODES)})") from None


def search_of(config: SynthConfig) -> Search:
    """The selector's search that ``config`` makes: its mode's search whose settings it holds.

    >>> search_of(SynthConfig(mode="acoustic")).key, search_of(SynthConfig(mode="acoustic",
    ...                                                                    acoustic_prefilter=None)).key
    ('acoustic', 'acoustic-full')
    """
    searches = mode_of(config).searches
    for s in reversed(searches):                 # the most specific first
        if all(getattr(config, k) == v for k, v in s.settings.items()):
            return s
    return searches[0]


def mode_name(config: SynthConfig) -> str:
    """The mode as the user knows it: ``phonetic``, ``robust``, ``acoustic-only (indexed)`` or
    ``acoustic-only (whole codebook)``, the paper's search.

    >>> mode_name(SynthConfig(mode="acoustic")), mode_name(SynthConfig(mode="acoustic",
    ...                                                               acoustic_prefilter=None))
    ('acoustic-only (indexed)', 'acoustic-only (whole codebook)')
    """
    return mode_of(config).describe(config)


def modes_table() -> str:
    """The modes as a Markdown table (``docs/labels.md`` holds it; a test checks it is current)."""
    rows = ["| mode | needs labels | weighs labels by confidence | tuned at training | what it does |",
            "|---|---|---|---|---|"]
    yes = {True: "yes", False: "no"}
    for m in MODES.values():
        rows.append(f"| `{m.name}` | {yes[m.needs_labels]} | {yes[m.weighs_labels]} | "
                    f"{yes[m.tuned]} | {m.help} |")
    return "\n".join(rows)


# --------------------------------------------------------------------------- the rule
@dataclass(frozen=True)
class ModeChoice:
    """The settings a synthesis runs with, and why its mode was chosen."""

    config: SynthConfig
    reason: str

    @property
    def mode(self) -> str:
        return self.config.mode

    def describe(self) -> str:
        """``"robust mode: aligned labels are not hand-checked"``."""
        return f"{mode_name(self.config)} mode: {self.reason}"


#: the modes the rule picks: for no labels, for hand-checked ones, for automatic ones
WITHOUT_LABELS, FOR_CHECKED_LABELS, FOR_AUTOMATIC_LABELS = "acoustic", "phonetic", "robust"


def tuned_config(config: SynthConfig, tuned: Mapping | None, keep: Sequence[str] = ()) -> SynthConfig:
    """``config`` with a model's cross-validated settings (modes that take them only; fields
    unknown to this facetraj, and the fields in ``keep`` -- set by the user -- are left alone).

    >>> tuned_config(SynthConfig(mode="robust"), {"settings": {"label_weight": 2.0}}).label_weight
    2.0
    >>> tuned_config(SynthConfig(), {"settings": {"label_weight": 2.0}}).label_weight
    16.0
    >>> tuned_config(SynthConfig(mode="robust"), {"settings": {"label_weight": 2.0}},
    ...              keep=("label_weight",)).label_weight
    16.0
    """
    if not mode_of(config).tuned or not tuned:
        return config
    kw = {k: v for k, v in dict(tuned.get("settings", {})).items()
          if k in TUNED_FIELDS and k not in keep}
    return config.with_(**kw)


def choose_mode(config: SynthConfig, phones: Sequence[PhoneSegment] | None,
                provenance: Provenance | None = None, *, explicit: bool = False,
                tuned: Mapping | None = None, keep: Sequence[str] = ()) -> ModeChoice:
    """THE rule for the synthesis mode (module docstring): ``config`` switched by the labels
    (``phones``, made as ``provenance`` says; ``None``: hand-checked) unless the user chose its
    mode (``explicit``), with the model's ``tuned`` settings in the modes that take them (except
    the fields in ``keep``, which the user set).

    >>> segs = [PhoneSegment(0.0, 0.1, "sil")]
    >>> choose_mode(SynthConfig(), None).describe()
    'acoustic-only (indexed) mode: no phone labels'
    >>> choose_mode(SynthConfig(), segs).describe()
    'phonetic mode: hand-checked labels (the paper)'
    >>> choose_mode(SynthConfig(), segs, Provenance("recognized")).describe()
    'robust mode: recognized labels are not hand-checked'
    >>> choose_mode(SynthConfig(), segs, Provenance("aligned"), explicit=True).describe()
    'phonetic mode: chosen, although the labels are aligned'
    """
    provenance = provenance or Provenance()
    mode = mode_of(config)
    if not phones:
        if not mode.needs_labels:
            return ModeChoice(config, "chosen" if explicit else "no phone labels")
        return ModeChoice(config.with_(mode=WITHOUT_LABELS), "no phone labels")
    if explicit:
        reason = "chosen" if provenance.hand_checked or mode.weighs_labels or not mode.needs_labels \
            else f"chosen, although the labels are {provenance.kind}"
        return ModeChoice(tuned_config(config, tuned, keep), reason)
    if config.mode == FOR_CHECKED_LABELS and not provenance.hand_checked:
        robust = tuned_config(config.with_(mode=FOR_AUTOMATIC_LABELS), tuned, keep)
        reason = f"{provenance.kind} labels are not hand-checked"
        if provenance.corrected:
            n = provenance.corrected
            reason += f" ({n} phone{'s' * (n != 1)} corrected by hand count{'s' * (n == 1)} as checked)"
        return ModeChoice(robust, reason + (", settings cross-validated at training" if tuned else ""))
    if config.mode == FOR_CHECKED_LABELS:
        return ModeChoice(config, "hand-checked labels (the paper)")
    return ModeChoice(tuned_config(config, tuned, keep), "chosen")
