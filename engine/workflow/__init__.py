"""What a command does with a recording, above the paper's steps: its labels by the label rule
(``facetraj_engine.io.labelling``), its mode by the mode rule (``facetraj_engine.method.modes``), its
synthesis
(``facetraj_engine.method.pipeline``), in one place that ``facetraj synth`` (one file or a batch), the
evaluations and the app share (``recording``).

Imports shared modules, ``facetraj_engine.labels``, ``facetraj_engine.io`` and ``facetraj_engine.method``;
never
``facetraj_engine.streaming`` or above.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "recording": "LabelRequest RecordingSynthesis synthesize_recording",
    "model_cache": "load_or_train cached_model_path",
})
