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
