"""Evaluation: the paper's section 3 and what we measure beyond it.

- ``scores``: speech-only frames (energy, 112 ms median filter), the correlations of Table 2,
  the N sweep of Figure 5;
- ``sensors``: per sensor coordinate, r and RMSE in mm, as articulatory-inversion papers
  tabulate them; ``correlation``: the Pearson correlation both use;
- ``baselines``: a viseme lookup and a ridge regression, scored the same way;
- ``tuning``: the robust mode's settings cross-validated on the training split;
- ``label_accuracy``, ``label_eval``: automatic labels, their accuracy and every mode with them;
- ``second_voice``, ``voice_eval``: a second voice, and acoustic-only synthesis from it;
- ``kinematics``: lip kinematics and gesture landmarks;
- ``paper``: the paper's own numbers (Tables 1-2, Figure 4's sentence).

Imports ``facetraj_engine.method``, ``facetraj_engine.streaming`` and below; ``facetraj_engine.analysis`` and
``facetraj_engine.report`` build on it.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "scores": "METRICS EvalConfig speech_mask pearson "
              "moving_coordinates trajectory_correlations ConditionScores UtteranceScore EvalResult "
              "evaluate_utterance default_workers evaluate table2 sweep_n format_table2",
    "sensors": "CoordinateScore SensorTable sensor_scores pooled format_sensor_report",
    "baselines": "fit_baselines evaluate_baselines fit_and_score",
    "tuning": "cross_validate",
    "label_eval": "evaluate_labels",
    "voice_eval": "evaluate_voices",
    "second_voice": "second_voice",
    "kinematics": "lip_measures",
    "paper": "PAPER_TABLE2 paper_table1",
})
