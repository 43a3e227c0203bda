"""facetraj engine: speech-driven 3-D face point trajectory synthesis (Arslan & Talkin).

GUI-free: numpy, scipy and small format libraries only. The main entry points are
:func:`engine.training.train`, :func:`engine.pipeline.synthesize` and :mod:`engine.evaluation`.
"""

__version__ = "0.1.0"
