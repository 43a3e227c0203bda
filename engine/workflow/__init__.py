"""What a command does with a recording, above the paper's steps: its labels by the label rule
(``engine.io.labelling``), its mode by the mode rule (``engine.method.modes``), its synthesis
(``engine.method.pipeline``), in one place that ``facetraj synth`` (one file or a batch), the
evaluations and the app share (``recording``).

Imports shared modules, ``engine.labels``, ``engine.io`` and ``engine.method``; never
``engine.streaming`` or above.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "recording": "LabelRequest RecordingSynthesis synthesize_recording",
})
