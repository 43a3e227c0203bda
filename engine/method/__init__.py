"""The paper's method (Arslan & Talkin, sections 2.1-2.3), one module per step.

Training (2.1-2.2): ``markers`` (gap filling, head motion removed with the fixed markers),
``pca`` (the 3M-dim marker vector), ``lsf`` (LPC and line spectral frequencies), ``context``
(context-phones), ``codebook`` (5 codewords per phone), ``similarity`` (eqs 1-3; eq 4's search),
``lsf_index`` (the acoustic-only search's index), ``training`` (the steps in order) -> ``model``.

Synthesis (2.3): ``pipeline.synthesize``: input LSFs; the mode's search (``modes``: candidates
by eq 4 (``similarity``), by the LSF index (acoustic-only) or both (``selection``, the robust mode
beyond the paper), then eqs 5-8 (``synthesis``)); ``smoothing``; PCs back to face points.
``speaker`` warps another voice's LSFs. ``modes`` is every mode's one home, and
``modes.choose_mode`` the one rule for which mode the labels allow. Beyond the paper, after the
smoothing: ``closure`` (lips that close at /p b m/, a face that rests in pauses) and
``closure_detector`` (where the lips close without phone labels; ``closure_search``: the
acoustic search's own opinion).

Equation modules are plain array functions, each naming its equation, with doctests; where a
vectorised form replaces the formula (``synthesis.grid_weights``, ``lsf.chebyshev_real_roots``,
``similarity.top_context_phones``) it is tested against it. Imports shared modules,
``facetraj_engine.labels`` and ``facetraj_engine.io``; never ``facetraj_engine.evaluation`` or above.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "model": "Model",
    "training": "train",
    "pipeline": "synthesize Synthesis resmooth",
    "modes": "MODES Mode choose_mode ModeChoice tuned_config",
    "lsf": "lpc lsf_at poly2lsf lsf2poly",
    "pca": "PCA fit_pca",
    "codebook": "Codebook",
    "context": "context_ids",
    "similarity": "similarity_matrix top_context_phones",
    "synthesis": "FrameWeights weight_frames",
    "selection": "robust_frames",
    "smoothing": "smooth",
})
