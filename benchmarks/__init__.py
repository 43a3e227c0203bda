"""Benchmarks of facetraj (issue 7): training time and memory, synthesis real-time factor, codebook
scaling and the acoustic prefilter, and (when its module exists) app playback.

Run ``python -m benchmarks`` (all sizes) or ``python -m benchmarks --smoke`` (a tiny size for CI).
These are not tests: they print a table and write ``docs/benchmarks.md``.
"""
