"""The trained-model cache: ``$FACETRAJ_CACHE_DIR`` or the user cache directory, one ``.npz`` per
(corpus contents, training settings)."""

from __future__ import annotations

import hashlib
import json
import logging
from pathlib import Path

from facetraj_engine.config import TrainConfig
from facetraj_engine.errors import InputError, ModelFileError
from facetraj_engine.io.cachedir import cache_dir
from facetraj_engine.io.corpus import Corpus
from facetraj_engine.io.model_file import is_compressed
from facetraj_engine.method.model import Model
from facetraj_engine.progress import Progress

log = logging.getLogger(__name__)

__all__ = ["cache_dir", "cached_model_path", "load_or_train", "model_key"]


def model_key(fingerprint: str, config: TrainConfig) -> str:
    """A short hash of the corpus fingerprint and the training settings."""
    blob = json.dumps({"corpus": fingerprint, "train": config.to_dict()}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


def cached_model_path(corpus: Corpus, config: TrainConfig | None = None) -> Path:
    """The cache file of ``corpus`` trained with ``config`` (hashes every corpus file)."""
    config = config or TrainConfig()
    return cache_dir() / f"model-{model_key(corpus.fingerprint(), config)}.npz"


def _store_uncompressed(model: Model, path: Path) -> None:
    """A cached model written compressed by an older facetraj is written again as
    :meth:`Model.save` writes it now (uncompressed: later starts skip inflating it)."""
    if not is_compressed(path):
        return
    try:
        model.save(path)
        log.info("cached model %s stored uncompressed", path)
    except (OSError, InputError) as exc:
        log.info("cached model %s left compressed (%s)", path, exc)


def load_or_train(corpus: Corpus, config: TrainConfig | None = None,
                  progress: Progress | None = None) -> Model:
    """The cached model of ``corpus``, training and caching it on the first call."""
    config = config or TrainConfig()
    progress = progress or (lambda f, m: None)
    progress(0.0, "hashing the corpus")
    path = cached_model_path(corpus, config)
    if path.exists():
        try:
            progress(0.5, f"loading cached model {path.name}")
            model = Model.load(path)
            log.info("loaded cached model %s", path)
            _store_uncompressed(model, path)
            progress(1.0, "model loaded")
            return model
        except ModelFileError as exc:
            log.warning("ignoring unreadable cached model: %s", exc)
    from facetraj_engine.method.training import train

    log.info("training the model on %s (first run; cached in %s)", corpus.root, path.parent)
    model = train(corpus, config=config, progress=lambda f, m: progress(0.02 + 0.96 * f, f"training: {m}"))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        model.save(path)
    except OSError as exc:
        log.warning("could not cache the model in %s: %s", path, exc)
    progress(1.0, "model trained")
    return model
