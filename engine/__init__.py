"""facetraj engine: speech-driven 3-D face point trajectory synthesis (Arslan & Talkin).

GUI-free: numpy, scipy and small format libraries only. Its folders are the pipeline's stages;
each imports only the stages listed before it (``tests/test_layering.py`` checks it):

==============  ===========================================================================
shared          ``config`` (settings), ``data`` (an utterance), ``errors``, ``fanout`` (work
                over processes), ``progress``, ``threads``: small modules every stage uses
``labels``      the phone set, other alphabets, PocketSphinx alignment and recognition
``io``          files in and out: audio, label and marker files, corpus folders, model files,
                exports, caches, and which labels an input gets
``method``      the paper (sections 2.1-2.3): LSF, PCA, codebook, similarity (eqs 1-3),
                eq 4, eqs 5-8, smoothing, training, the model, the synthesis pipeline
``streaming``   the method on audio blocks as they arrive (live mode)
``evaluation``  the paper's section 3 and beyond: scores, baselines, tuning, automatic labels,
                other voices, kinematics, the paper's own numbers
``analysis``    the numbers behind the app's analysis views
``report``      docs/results.md, stage by stage
``corpusgen``   building the default corpus (the ``corpus`` extra)
==============  ===========================================================================

The entry points: :func:`facetraj_engine.method.train`, :func:`facetraj_engine.method.synthesize` and
:func:`facetraj_engine.evaluation.evaluate`. ``docs/architecture.md`` follows one request through them.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
import warnings
from collections.abc import Callable

__version__ = "0.1.0"

#: The stages, lowest first: a module may import from its own stage and the ones before it.
STAGES = ("labels", "io", "method", "streaming", "evaluation", ("analysis", "report", "corpusgen"))


def lazy_exports(package: str, table: dict[str, str]) -> tuple[Callable, Callable, list[str]]:
    """``__getattr__``, ``__dir__`` and ``__all__`` of a stage package that exports the names in
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


# --------------------------------------------------------------------------- old module paths
#: Module paths of version 0.1 before the stages, and where their names are now. Importing one
#: still works, with a DeprecationWarning, until the next release.
MOVED: dict[str, tuple[str, ...]] = {
    "facetraj_engine.formats": ("facetraj_engine.io.files", "facetraj_engine.io.audio", "facetraj_engine.io.labelfiles",
                       "facetraj_engine.io.markerfiles"),
    "engine.phones": ("facetraj_engine.labels.phoneset", "facetraj_engine.method.context"),
    "engine.labelmap": ("facetraj_engine.labels.labelmap", "facetraj_engine.io.labelfiles"),
    **{f"engine.{old}": (f"engine.{new}",) for old, new in {
        "alignment": "labels.alignment", "c3d_check": "io.c3d_check", "corpus": "io.corpus",
        "model_file": "io.model_file", "cachedir": "io.cachedir", "hash_memo": "io.hash_memo",
        "labelling": "io.labelling", "export": "io.export", "lsf": "method.lsf",
        "lsf_index": "method.lsf_index", "markers": "method.markers", "pca": "method.pca",
        "codebook": "method.codebook", "similarity": "method.similarity",
        "synthesis": "method.synthesis", "selection": "method.selection",
        "smoothing": "method.smoothing", "speaker": "method.speaker",
        "training": "method.training", "model": "method.model", "pipeline": "method.pipeline",
        "baselines": "evaluation.baselines", "tuning": "evaluation.tuning",
        "label_accuracy": "evaluation.label_accuracy", "label_eval": "evaluation.label_eval",
        "voice_eval": "evaluation.voice_eval", "voice": "evaluation.second_voice",
        "kinematics": "evaluation.kinematics", "paper": "evaluation.paper",
    }.items()},
}


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports an old module path (:data:`MOVED`) as a module that forwards every attribute to
    the modules that now hold its names."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in MOVED:
            return None
        return importlib.machinery.ModuleSpec(fullname, self)

    def create_module(self, spec):
        targets = MOVED[spec.name]
        warnings.warn(f"{spec.name} is deprecated: its names are now in {', '.join(targets)}",
                      DeprecationWarning, stacklevel=2)
        modules = [importlib.import_module(t) for t in targets]
        module = types.ModuleType(spec.name, f"Deprecated: see {', '.join(targets)}.")

        def forward(name: str):
            for m in modules:
                if hasattr(m, name):
                    return getattr(m, name)
            raise AttributeError(f"module {spec.name!r} has no attribute {name!r}")

        module.__getattr__ = forward
        return module

    def exec_module(self, module) -> None:
        return None


if not any(isinstance(f, _MovedModules) for f in sys.meta_path):
    sys.meta_path.append(_MovedModules())
