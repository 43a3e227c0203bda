"""Where facetraj finds its default corpus and the reference material beside the repository."""

from __future__ import annotations

import os
from importlib.util import find_spec
from pathlib import Path

from facetraj_engine.errors import FacetrajError

#: the checkout this module sits in (its ``data_samples/`` and ``../shared``), when it is one
CHECKOUT = Path(__file__).resolve().parent.parent


def default_corpus() -> Path:
    """The default corpus: ``$FACETRAJ_CORPUS``, else the checkout's ``data_samples/``, else the
    copy the app distribution carries (``facetraj_app/corpus``, read where pip put it); without
    either, one line saying where it comes from."""
    env = os.environ.get("FACETRAJ_CORPUS")
    if env:
        return Path(env)
    checkout = CHECKOUT / "data_samples"
    if (checkout / "corpus.json").is_file():
        return checkout
    spec = find_spec("facetraj_app")
    if spec is not None and spec.submodule_search_locations:
        for folder in spec.submodule_search_locations:
            packaged = Path(folder) / "corpus"
            if (packaged / "corpus.json").is_file():
                return packaged
    raise FacetrajError("no default corpus here: it comes with the app (pip install facetraj); "
                        "or give a corpus folder (docs/data-format.md)")


def shared_path(relative: str) -> Path:
    """A path in the reference material beside the repository (``$FACETRAJ_SHARED`` or
    ``../shared``): read from there when present, never copied into the repository."""
    root = os.environ.get("FACETRAJ_SHARED")
    base = Path(root) if root else CHECKOUT.parent / "shared"
    return base / relative
