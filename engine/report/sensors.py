"""The report's per-sensor section: r and RMSE (mm) of every sensor coordinate for each method
(the paper's with and without labels, the indexed search, the two baselines) on the held-out
split, triangular smoothing, as articulatory-inversion papers tabulate them
(:mod:`facetraj_engine.evaluation.sensors`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..evaluation.scores import EvalResult, UtteranceScore
from ..method.model import Model
from .data import ReportData
from .text import fmt

#: a table with more coordinates than this shows the ones that move most (all are in the JSON)
MAX_ROWS = 30
SHOWN_ROWS = 15


def sensor_section(model: Model, paper_modes: EvalResult, indexed: EvalResult,
                   baseline_scores: Sequence[UtteranceScore], split: str,
                   smoothing: str = "triangular") -> dict:
    """The section's numbers: per method its per-sensor table on ``split``; per coordinate its
    training standard deviation (mm), by which a long table is cut."""
    base = EvalResult(list(baseline_scores))
    n = next((s.n_context_phones for s in paper_modes.scores if s.mode == "phonetic"), 3)
    methods = [("phonetic (N = 3)", paper_modes.sensor_table(split, smoothing, "phonetic", n)),
               ("acoustic-only", paper_modes.sensor_table(split, smoothing, "acoustic")),
               ("acoustic-only, indexed", indexed.sensor_table(split, smoothing, "acoustic")),
               ("viseme lookup", base.sensor_table(split, smoothing, "viseme")),
               ("ridge regression", base.sensor_table(split, smoothing, "ridge"))]
    std = np.asarray(model.coord_std, dtype=np.float64).reshape(model.n_markers, 3)
    names = list(model.marker_names)
    return {"split": split, "smoothing": smoothing,
            "methods": [{"method": name, **t.to_json()} for name, t in methods if t.rows],
            "sd_mm": {r.key: float(std[names.index(r.sensor), "xyz".index(r.axis)])
                      for _, t in methods for r in t.rows}}


def sensors_section(data: ReportData) -> list[str]:
    """Markdown: a row per coordinate (the ones that move most when there are many), each
    method's r and RMSE, and the articulators' mean."""
    sec = data.sensors
    if not sec or not sec["methods"]:
        return []
    methods = sec["methods"]
    rows = {f"{c['sensor']} {c['axis']}": c["role"] for c in methods[0]["coordinates"]}
    keys = list(rows)
    cut = len(keys) > MAX_ROWS
    if cut:
        keys = sorted(keys, key=lambda k: -sec["sd_mm"][k])[:SHOWN_ROWS]
    cells = {m["method"]: {f"{c['sensor']} {c['axis']}": c for c in m["coordinates"]} for m in methods}
    lines = ["## Per sensor", "",
             f"r and RMSE (mm) of each sensor coordinate, original against synthesized, on the "
             f"speech frames of the {sec['split']} split ({sec['smoothing']} smoothing), as "
             f"articulatory-inversion papers tabulate them (`engine/evaluation/sensors.py`; axes: "
             f"x right, y up, z forward). r is averaged over utterances as in Table 2, the RMSE "
             f"pooled over their frames; the articulators' mean leaves out reference sensors."
             + (f" The {SHOWN_ROWS} coordinates that move most of {len(rows)} (all in "
                f"`results.json`, `sensors`)." if cut else ""), "",
             "| Coordinate | Role | " + " | ".join(f"{m['method']}: r / RMSE" for m in methods) + " |",
             "|---|---|" + "---:|" * len(methods)]
    for key in keys:
        row = [_cell(cells[m["method"]].get(key, {})) for m in methods]
        lines.append(f"| {key} | {rows[key]} | " + " | ".join(row) + " |")
    lines.append("| articulators (mean) | | " + " | ".join(
        _cell({"r": m["articulators_mean"]["r"], "rmse_mm": m["articulators_mean"]["rmse_mm"]})
        for m in methods) + " |")
    return lines


def _cell(c: dict) -> str:
    return f"{fmt(c.get('r'), 3)} / {fmt(c.get('rmse_mm'), 2)}"


__all__ = ["sensor_section", "sensors_section"]
