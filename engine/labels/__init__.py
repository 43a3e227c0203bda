"""Phone labels: the phone set, other alphabets, and labels made by PocketSphinx.

- ``phoneset``: ARPAbet and silence, label normalisation, mapping a label onto a model's phones;
- ``alphabets``: the phone alphabets of label files (ARPAbet, TIMIT, MOCHA-TIMIT, SAMPA, X-SAMPA,
  IPA), told apart from a file's labels and mapped onto ARPAbet;
- ``labelmap``: label maps onto ARPAbet (a user's map file, or an alphabet by name);
- ``alignment``: forced alignment of a transcript and phone recognition, with a score per phone.

Imports only the shared modules (``facetraj_engine.data``, ``facetraj_engine.errors``): reading label files and
deciding which labels an input gets is ``facetraj_engine.io`` (``labelfiles``, ``labelling``).
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "phoneset": "ARPABET SILENCE SILENCE_LABELS FALLBACK normalise_label apply_label_map map_labels",
    "alphabets": "ALPHABETS MOCHA_TO_ARPABET Alphabet detect to_arpabet",
    "labelmap": "LabelMap AlphabetMap read_label_map",
    "alignment": "align recognize pocketsphinx_version MissingWordsError UnalignableError",
    "provenance": "Labels SCORE_SCALE provenance_text parse_provenance labels_from_tiers",
})
