"""The paper's method (Arslan & Talkin, sections 2.1-2.3), one module per step.

Training (2.1-2.2): ``markers`` (gap filling, head motion removed with the fixed markers),
``pca`` (the 3M-dim marker vector), ``lsf`` (LPC and line spectral frequencies), ``context``
(context-phones), ``codebook`` (5 codewords per phone), ``similarity`` (eqs 1-3; eq 4's search),
``lsf_index`` (the acoustic-only search's index), ``training`` (the steps in order) -> ``model``.

Synthesis (2.3): ``pipeline.synthesize``: input LSFs; candidates by eq 4 (``similarity``), by
the LSF index (acoustic-only) or both (``selection``, the robust mode beyond the paper); eqs 5-8
(``synthesis``); ``smoothing``; PCs back to face points. ``speaker`` warps another voice's LSFs.
``modes.choose_mode`` is the one rule for which mode the labels allow.

Equation modules are plain array functions, each naming its equation, with doctests; fast
kernels (``compiled_lsf``, ``compiled_search``, ``compiled_weights``; ``kernels`` chooses them,
``aot`` builds them at install, ``prebuilt`` loads those) are tested against the reference
formula. Imports shared modules, ``facetraj_engine.labels`` and ``facetraj_engine.io``; never
``facetraj_engine.evaluation`` or above.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "model": "Model",
    "training": "train",
    "pipeline": "synthesize Synthesis resmooth",
    "modes": "choose_mode ModeChoice tuned_config",
    "lsf": "lpc lsf_at poly2lsf lsf2poly",
    "pca": "PCA fit_pca",
    "codebook": "Codebook",
    "context": "context_ids",
    "similarity": "similarity_matrix top_context_phones",
    "synthesis": "FrameWeights weight_frames",
    "selection": "robust_frames",
    "smoothing": "smooth",
})
