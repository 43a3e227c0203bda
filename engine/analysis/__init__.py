"""Analysis of a model and of its synthesis errors: the numbers of the app's analysis views, one
module per view (mirroring ``app/analysis/``):

* :mod:`.similarity` (``similarity_view``): phones ordered by hierarchical clustering of the eq 2
  distances (visemes group), the dendrogram, the similarity matrix (eq 3) as CSV;
* :mod:`.metrics` (``metrics_view``): Table 2, the per-sensor table and the N sweep (Figure 5) as
  rows and CSV, from an :class:`~facetraj_engine.evaluation.scores.EvalResult`;
* :mod:`.errors` (``errors_view``): per-frame lip error, per-phone correlation and RMS error,
  per-utterance errors, worst segments;
* :mod:`.inspector` (``inspector``): the codebook inspector, everything eqs 4-8 did at one frame;
* :mod:`.pc_modes` (``pc_modes``): principal component modes (Figure 2): displacement, standard
  deviations, which markers move;
* :mod:`.lips` (the 3-D view and the lip panels): the talker's lips at closure, where the face's
  mouth shuts and the panels draw their "closed" line;
* :mod:`.articulators` (the articulator view, Measure): the tongue curve through articulograph
  sensors, the tongue tip height, lip aperture and jaw opening at a frame;
* :mod:`.common`: the CSV writer and the quick-look corpus subset they share.

The kinematics panels' numbers are in :mod:`facetraj_engine.evaluation.kinematics`. Pure numpy/scipy; every
number
the app shows is computed here or in the other engine modules. Import from the modules, e.g.
``from facetraj_engine.analysis.similarity import cluster_phones``.
"""
