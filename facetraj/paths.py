"""Where the project keeps its default corpus."""

from __future__ import annotations

import os
from pathlib import Path


def default_corpus() -> Path:
    """The default corpus: ``$FACETRAJ_CORPUS`` or the project's ``data_samples/``."""
    env = os.environ.get("FACETRAJ_CORPUS")
    if env:
        return Path(env)
    return Path(__file__).resolve().parent.parent / "data_samples"


def shared_path(relative: str) -> Path:
    """A path in the reference material beside the repository (``$FACETRAJ_SHARED`` or
    ``../shared``): read from there when present, never copied into the repository."""
    root = os.environ.get("FACETRAJ_SHARED")
    base = Path(root) if root else Path(__file__).resolve().parent.parent.parent / "shared"
    return base / relative
