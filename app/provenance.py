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

#: The searches the settings offer, by key (:func:`search_key`): the title's name of each.
SEARCH_NAMES = {
    "robust": "robust",
    "phonetic": "phonetic (the paper)",
    "acoustic": "acoustic only, indexed",
    "acoustic-full": "acoustic only, whole codebook (the paper)",
}

#: One line per search, shown under the selector.
MODE_NOTES = {
    "robust": "robust: eq 4's and the acoustically nearest codewords together; each label counts "
              "as much as the aligner/recognizer trusts it (default for automatic labels).",
    "phonetic": "phonetic (the paper): the labels alone pick the N context-phones searched "
                "(eq 4); best with hand-checked labels.",
    "acoustic": "acoustic only: no labels; the codewords nearest to each frame by eq 5, found "
                "in the model's LSF index (fast).",
    "acoustic-full": "acoustic only, whole codebook: eqs 5-8 over every codeword, as the paper "
                     "(slow).",
}


def search_key(config: SynthConfig) -> str:
    """The search of ``config`` as the settings name it: ``robust``, ``phonetic``, ``acoustic``
    (the LSF index's nearest codewords) or ``acoustic-full`` (every codeword, the paper's).

    >>> search_key(SynthConfig(mode="acoustic")), search_key(SynthConfig(mode="acoustic",
    ...                                                                acoustic_prefilter=None))
    ('acoustic', 'acoustic-full')
    """
    if config.mode == "acoustic" and config.acoustic_prefilter is None:
        return "acoustic-full"
    return config.mode


def search_title(config: SynthConfig) -> str:
    """The search of ``config`` in words, with the number of codewords the index search weighs.

    >>> search_title(SynthConfig(mode="acoustic"))
    'acoustic only, indexed (K = 128)'
    """
    key = search_key(config)
    name = SEARCH_NAMES.get(key, key)
    return f"{name} (K = {config.acoustic_prefilter})" if key == "acoustic" else name


@dataclass(frozen=True)
class LabelOrigin:
    """Where an utterance's phone labels came from.

    ``source``: ``Utterance.label_source`` (``file``, ``aligned``, ``recognized``, ``none``, or
    any other the engine names); ``file``: the label file they were read from (a name);
    ``transcript``: what was aligned (``s001.txt``, or ``the sentence typed``).
    """

    source: str
    file: str = ""
    transcript: str = ""

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
        """
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
