"""Where facetraj keeps what it can recompute: ``$FACETRAJ_CACHE_DIR`` or the user cache folder
(trained models, automatic phone labels). Never inside the repository or a corpus folder."""

from __future__ import annotations

import os
from pathlib import Path


def cache_dir() -> Path:
    """The cache folder (created on demand by whoever writes into it)."""
    env = os.environ.get("FACETRAJ_CACHE_DIR")
    if env:
        return Path(env)
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("facetraj"))
