"""What the window says about how the synthesis on screen was made (no Qt): the search it used
(the one the synthesis result records, ``Synthesis.config``, never a second guess of the rule in
``facetraj_engine.method.modes.choose_mode``), why it differs from the settings, and where the phone
labels came from.

Label sources are ``Utterance.label_source`` / ``facetraj_engine.labels.alignment.Labels.source``
strings; one this module does not know reads as it is, so that a richer source shows without a
change here.
"""

from __future__ import annotations

from dataclasses import dataclass

from facetraj_engine.config import SynthConfig
from facetraj_engine.method.modes import MODES, SEARCHES, search_of

#: The searches the settings offer, by key (:func:`search_key`): the title's name of each, and one
#: line on each, shown under the selector (both from the modes' one home, ``facetraj_engine.method.modes``).
SEARCH_NAMES = {key: s.title for key, s in SEARCHES.items()}
MODE_NOTES = {key: s.note for key, s in SEARCHES.items()}


def search_key(config: SynthConfig) -> str:
    """The search of ``config`` as the settings name it: ``robust``, ``phonetic``, ``acoustic``
    (the LSF index's nearest codewords) or ``acoustic-full`` (every codeword, the paper's).

    >>> search_key(SynthConfig(mode="acoustic")), search_key(SynthConfig(mode="acoustic",
    ...                                                                acoustic_prefilter=None))
    ('acoustic', 'acoustic-full')
    """
    return search_of(config).key


def search_title(config: SynthConfig) -> str:
    """The search of ``config`` in words, with the number of codewords the index search weighs.

    >>> search_title(SynthConfig(mode="acoustic"))
    'acoustic only, indexed (K = 128)'
    """
    key = search_key(config)
    name = SEARCH_NAMES[key]
    return f"{name} (K = {config.acoustic_prefilter})" if key == "acoustic" else name


def search_short(config: SynthConfig) -> str:
    """The search of ``config`` in a word or two (a pin's part).

    >>> search_short(SynthConfig()), search_short(SynthConfig(mode="acoustic"))
    ('phonetic', 'acoustic K=128')
    >>> search_short(SynthConfig(mode="acoustic", acoustic_prefilter=None))
    'acoustic, all codewords'
    """
    key = search_key(config)
    return {"acoustic": f"acoustic K={config.acoustic_prefilter}",
            "acoustic-full": "acoustic, all codewords"}.get(key, key)


@dataclass(frozen=True)
class LabelOrigin:
    """Where an utterance's phone labels came from.

    ``source``: ``Utterance.label_source`` (``file``, ``aligned``, ``recognized``, ``none``, or
    any other the engine names); ``file``: the label file they were read from (a name);
    ``transcript``: what was aligned (``s001.txt``, or ``the sentence typed``); ``corrected``:
    the phones of automatic labels corrected by hand since.
    """

    source: str
    file: str = ""
    transcript: str = ""
    corrected: int = 0

    def text(self) -> str:
        """In words, for the title, the status bar and the phone tier.

        >>> LabelOrigin("aligned", transcript="s001.txt").text()
        'aligned from s001.txt'
        >>> LabelOrigin("file", file="s001.TextGrid").text()
        'label file s001.TextGrid'
        >>> LabelOrigin("recognized").text()
        'recognized from the speech (no text)'
        >>> LabelOrigin("aligned", file="s001.TextGrid").text()
        'aligned (label file s001.TextGrid)'
        >>> LabelOrigin("hand-corrected", file="x.TextGrid").text()
        'hand-corrected (label file x.TextGrid)'
        >>> LabelOrigin("recognized", corrected=3).text()
        'recognized from the speech (no text), 3 phones corrected by hand'
        """
        text = self._text()
        if self.corrected:
            text += f", {self.corrected} phone{'s' * (self.corrected != 1)} corrected by hand"
        return text

    def _text(self) -> str:
        src = self.source or "none"
        if src == "none":
            return "none: acoustic-only synthesis"
        if src == "file":
            return f"label file {self.file}" if self.file else "a label file"
        if src == "aligned" and self.transcript:
            return f"aligned from {self.transcript}"
        if src == "recognized" and not self.file:
            return "recognized from the speech (no text)"
        return f"{src} (label file {self.file})" if self.file else src

    def short(self) -> str:
        """In a word or two, for the phone tier's row name.

        >>> LabelOrigin("file").short(), LabelOrigin("aligned").short(), LabelOrigin("x-y").short()
        ('label file', 'aligned', 'x-y')
        """
        return {"file": "label file", "none": "none"}.get(self.source or "none", self.source)


def mode_reason(requested: SynthConfig, used: SynthConfig, reason: str) -> str:
    """The note under the search selector when the search used differs from the one the
    settings ask for ("" when it does not): the engine's ``reason``
    (:meth:`facetraj_engine.method.modes.ModeChoice.describe`, the one rule), and how to override it.

    >>> mode_reason(SynthConfig(), SynthConfig(mode="robust"), "robust mode: aligned labels")
    'robust mode: aligned labels (the settings ask for phonetic); choose a search to override'
    >>> mode_reason(SynthConfig(), SynthConfig(), "phonetic mode: hand-checked labels (the paper)")
    ''
    """
    want, got = search_key(requested), search_key(used)
    if want == got:
        return ""
    return f"{reason} (the settings ask for {want}); choose a search to override"


SMOOTHING_NAMES = {"triangular": "triangular", "spline": "spline", "none": "unsmoothed"}


def closure_text(cfg: SynthConfig) -> str:
    """The closure step's parts that are on (the settings' boxes), in words.

    >>> closure_text(SynthConfig()), closure_text(SynthConfig(closure=False))
    ('closure: /p b m/ + rest', 'closure: off')
    >>> closure_text(SynthConfig(mode="acoustic", closure_detector=True))
    'closure: /p b m/ + rest + detector'
    """
    on = [name for name, flag in (("/p b m/", cfg.closure_labels), ("rest", cfg.rest),
                                  ("detector", cfg.closure_detector),
                                  ("second opinion", cfg.closure_second_opinion)) if flag]
    return f"closure: {' + '.join(on)}" if cfg.closure and on else "closure: off"


def synthesis_parts(view) -> list[str]:
    """Every setting that changes how ``view`` (an ``UtteranceView``) was synthesized, one short
    part each, in the settings' order: the search, N, C, xi and nu where labels are searched
    (eq 4; eq 3's nu "trained" when the model's own), the smoothing, the closure step's parts,
    the labels and their source (file or transcript) -- what tells two pins apart
    (:func:`facetraj_app.pins.distinct_settings`; the model is the pin's own part)."""
    cfg, origin = view.synthesis.config, view.label_origin
    parts = [search_short(cfg)]
    if MODES[cfg.mode].needs_labels:
        nu = "trained" if cfg.nu is None else f"{cfg.nu:g}"
        parts += [f"N={cfg.n_context_phones}", f"C={cfg.context}", f"ξ={cfg.xi:g}", f"ν={nu}"]
        labels = origin.short()
        if origin.source == "file" and origin.file:
            labels = origin.file
        elif origin.transcript:
            labels = f"{labels} from {origin.transcript}"
        elif origin.file:
            labels = f"{labels} ({origin.file})"
        if origin.corrected:            # the phones corrected by hand (the label editor)
            labels += f", {origin.corrected} corrected"
    else:
        labels = "not used" if origin.source not in ("", "none") else "none"
    return [*parts, SMOOTHING_NAMES[cfg.smoothing], closure_text(cfg), f"labels: {labels}"]


def settings_text(view, short: bool = False) -> str:
    """How a view was synthesized: the smoothing, the search the synthesis used
    (``Synthesis.config``), N where labels are searched, the closure step where it is not the
    default, and where the labels
    came from; an acoustic-only search uses no labels, and says so (an acoustic-only pin read
    "labels: label file"). ``short``: every part of :func:`synthesis_parts` (a pin's record,
    from which its legend keeps what differs). ``view``: an ``UtteranceView``."""
    if short:
        return ", ".join(synthesis_parts(view))
    cfg, origin = view.synthesis.config, view.label_origin
    used = MODES[cfg.mode].needs_labels
    n = f", N={cfg.n_context_phones}" if used else ""
    unused = "" if used or origin.source in ("", "none") else " (not used by this search)"
    closure = closure_text(cfg)
    closure = "" if closure == closure_text(SynthConfig()) else f", {closure}"    # the default: unsaid
    return (f"{SMOOTHING_NAMES[cfg.smoothing]} synthesis, {search_title(cfg)}{n}{closure};  "
            f"labels: {origin.text()}{unused}")
