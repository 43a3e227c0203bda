"""Training benchmark (paper sections 2.1-2.2): wall time and peak memory of
:func:`facetraj_engine.method.training.train`, split into LSF extraction, marker normalisation + PCA, and the
rest of
the codebook.

The split is measured inside one ``train()`` call by wrapping the engine's own functions as
``facetraj_engine.method.training`` calls them (``analysed_lsf``: ``lsf_at`` with the model's
settings; ``fill_gaps``, ``reference_pose``, ``remove_head_motion``; ``pca_of``, the PCA of the
merged moments); the codebook time is the remainder (context-phones, codeword times, PC
interpolation, eqs 1-2). Peak memory is measured in a second call under ``tracemalloc`` (numpy
reports its buffers to it), so that tracing does not slow the timed run.
"""

from __future__ import annotations

import logging
import time
import tracemalloc
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from unittest import mock

import facetraj_engine.method.training as engine_training
from facetraj_engine.method.training import train

from .common import BenchContext, BenchRow, peak_rss_mib

log = logging.getLogger(__name__)

#: the engine functions timed, grouped by stage
STAGES: dict[str, tuple[str, ...]] = {
    "lsf": ("analysed_lsf",),
    "normalisation": ("fill_gaps", "reference_pose", "remove_head_motion"),
    "pca": ("pca_of",),
}

TRAIN_AIM_S = 30.0


@contextmanager
def timed_engine_functions() -> Iterator[dict[str, float]]:
    """Wrap the functions of :data:`STAGES` in ``facetraj_engine.method.training``; yield seconds spent per
    function."""
    spent: dict[str, float] = defaultdict(float)

    def wrap(name: str, fn: Callable) -> Callable:
        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                spent[name] += time.perf_counter() - t0
        return timed

    names = [n for group in STAGES.values() for n in group]
    patches = [mock.patch.object(engine_training, n, wrap(n, getattr(engine_training, n))) for n in names]
    for p in patches:
        p.start()
    try:
        yield spent
    finally:
        for p in reversed(patches):
            p.stop()


def run(ctx: BenchContext) -> list[BenchRow]:
    """Time training on the context's training utterances; return the table rows."""
    utts, setup = ctx.train_utts, ctx.setup
    audio_s = ctx.train_audio_s
    size = f"{len(utts)} utterances, {audio_s / 60:.1f} min"
    train(utts[:2], setup)  # warm-up: imports, BLAS and FFT plans
    with timed_engine_functions() as spent:
        c0, t0 = time.process_time(), time.perf_counter()
        model = train(utts, setup)
        total = time.perf_counter() - t0
        total_cpu = time.process_time() - c0
    lsf = sum(spent[n] for n in STAGES["lsf"])
    norm = sum(spent[n] for n in STAGES["normalisation"])
    pca = sum(spent[n] for n in STAGES["pca"])
    rest = max(total - lsf - norm - pca, 0.0)
    if ctx._model is None:
        ctx._model = model
    tracemalloc.start()
    try:
        train(utts, setup)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    n_cw = model.codebook.lsf.shape[0]
    log.info("train: %.2f s total (lsf %.2f, normalisation %.2f, pca %.2f, rest %.2f)", total, lsf,
             norm, pca, rest)
    return [
        BenchRow("train", "corpus loading (I/O, not in train())", ctx.load_s, "s", note=size),
        BenchRow("train", "LSF extraction (lsf_at)", lsf, "s",
                 note=f"{n_cw} codeword LSF vectors"),
        BenchRow("train", "marker normalisation (fill_gaps, reference_pose, remove_head_motion)",
                 norm, "s"),
        BenchRow("train", "PCA (pca_of)", pca, "s",
                 note=f"{model.pca.n_components} PCs of {model.n_markers * 3} coordinates"),
        BenchRow("train", "codebook: contexts, PC codewords, eqs 1-2 (rest of train())", rest, "s",
                 note=f"{model.codebook.n_contexts} context-phones"),
        BenchRow("train", "train() total", total, "s", aim=f"<= {TRAIN_AIM_S:.0f} s",
                 ok=total <= TRAIN_AIM_S if not ctx.smoke else None, note=size, cpu=total_cpu),
        BenchRow("train", "train() peak traced memory (tracemalloc)", peak / 1024**2, "MiB"),
        BenchRow("train", "process peak RSS so far (getrusage)", peak_rss_mib(), "MiB",
                 note="includes the loaded corpus"),
    ]
