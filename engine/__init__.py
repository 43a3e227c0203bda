"""facetraj engine: speech-driven 3-D face point trajectory synthesis (Arslan & Talkin).

GUI-free: numpy, scipy and small format libraries only. Its folders are the pipeline's stages;
each imports only the stages listed before it (``tests/test_layering.py`` checks it):

==============  ===========================================================================
shared          ``config`` (settings), ``data`` (an utterance), ``errors``, ``fanout`` (work
                over processes), ``level`` (a signal's gain kept out), ``progress``,
                ``threads``: small modules every stage uses
``labels``      the phone set, other alphabets, PocketSphinx alignment and recognition
``io``          files in and out: audio, label and marker files, corpus folders, model files,
                exports, caches, and which labels an input gets
``method``      the paper (sections 2.1-2.3): LSF, PCA, codebook, similarity (eqs 1-3),
                eq 4, eqs 5-8, smoothing, training, the model, the modes, the pipeline
``workflow``    a recording in, a face out: its labels and mode by the rules, its synthesis
``streaming``   the method on audio blocks as they arrive (live mode)
``evaluation``  the paper's section 3 and beyond: scores, baselines, tuning, automatic labels,
                other voices, kinematics, the paper's own numbers
``analysis``    the numbers behind the app's analysis views
``report``      docs/results.md, stage by stage
``corpusgen``   building the default corpus (the ``corpus`` extra)
==============  ===========================================================================

The names a script needs are exported here (:data:`API`; ``docs/api.md`` shows them at work):
``Model``, ``train``, ``read_audio``, ``read_labels``, ``synthesize``, ``synthesize_recording``,
``evaluate``, ``write_trajectories`` and their settings. ``docs/architecture.md`` follows one
request through the stages.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable

#: facetraj's version, the one place it is written (both distributions read it at build time).
__version__ = "0.2.0"

#: The stages, lowest first: a module may import from its own stage and the ones before it.
STAGES = ("labels", "io", "method", "workflow", "streaming", "evaluation",
          ("analysis", "report", "corpusgen"))


def lazy_exports(package: str, table: dict[str, str]) -> tuple[Callable, Callable, list[str]]:
    """``__getattr__``, ``__dir__`` and ``__all__`` of a package that exports the names in
    ``table`` (``{"module": "name name ..."}``) and imports each module on first use, so that
    importing one module of a stage does not import the whole stage."""
    where = {name: module for module, names in table.items() for name in names.split()}
    names = sorted(where)

    def __getattr__(name: str):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{where[name]}"), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names))

    return __getattr__, __dir__, names


#: The public Python API: what a script imports from ``facetraj_engine`` (docs/api.md).
API = {
    "config": "SynthConfig TrainConfig EvalConfig",
    "errors": "FacetrajError InputError",
    "io.audio": "read_audio write_audio",
    "io.labelfiles": "read_labels read_label_file write_textgrid",
    "io.markerfiles": "read_markers",
    "io.corpus": "load_corpus init_corpus",
    "io.export": "write_trajectories",
    "method.model": "Model",
    "method.training": "train",
    "method.modes": "MODES choose_mode",
    "method.pipeline": "synthesize resmooth Synthesis",
    "workflow.recording": "synthesize_recording LabelRequest",
    "labels.alignment": "align recognize",
    "method.speech": "speech_mask",
    "evaluation.scores": "evaluate",
}

__getattr__, __dir__, _api_names = lazy_exports(__name__, API)
__all__ = ["STAGES", "__version__", *_api_names]
