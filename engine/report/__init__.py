"""The results report (issue 7): the paper's Table 1, Table 2, Figure 5 and a Figure-4-style plot
reproduced on a corpus's train/test split, the acoustic-only mode and two baselines on the same
split, the paper's numbers beside ours and a discussion of the differences.

Pure engine: no plotting here. :func:`write_report` computes everything
(:func:`~.compute.compute_report`), calls an optional ``figures`` callable to draw the figures
(``facetraj_app.report_figures`` does it with matplotlib) and writes ``results.md`` and ``results.json``.

* :mod:`.rows`: the typed rows (one method's correlations, the N sweep, Table 1's agreement, the
  corpus and model summaries) and the functions that build them from scores;
* :mod:`.data`: :class:`ReportData` (everything in the report, and its JSON), the Figure-4
  example, the paper's headline claims beside ours (:func:`at_a_glance`);
* :mod:`.compute`: :func:`compute_report`, one function per stage;
* :mod:`.discussion`: one function per discussion paragraph;
* :mod:`.markdown`: one function per section of ``results.md``;
* :mod:`.text`: how numbers are written.

The paper's own numbers (Tables 1 and 2, Figure 4's sentence) are in :mod:`facetraj_engine.evaluation.paper`.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable
from pathlib import Path

from ..evaluation.closure_eval import CLOSURE_EVAL_FILE, read_closure_eval
from ..evaluation.label_eval import LABEL_EVAL_FILE, read_label_eval
from ..evaluation.voice_eval import VOICE_EVAL_FILE, read_voice_eval
from ..fanout import Skips
from ..io.files import atomic_write, write_json
from ..method.model import Model
from ..progress import Progress
from .compute import compute_report, figure4_data, find_utterance
from .data import Figure4Data, FigureMaker, ReportData, at_a_glance
from .discussion import discussion
from .markdown import render_markdown
from .rows import (
    ComparisonRow,
    CorpusSummary,
    GlanceRow,
    ModelSummary,
    SweepTable,
    Table1Agreement,
    summarise,
    sweep_table,
    table1_agreement,
)

log = logging.getLogger(__name__)


def write_report(corpus_dir: str | os.PathLike[str], out_dir: str | os.PathLike[str],
                 model: Model | None = None, progress: Progress | None = None,
                 ns: Iterable[int] = range(1, 11), figures: FigureMaker | None = None,
                 workers: int | None = None, skip: Skips | None = None) -> Path:
    """Compute the report on ``corpus_dir`` and write ``out_dir/results.md``, ``results.json`` and
    (through ``figures``, drawn into ``out_dir/figures/``) its figures. Returns the ``.md`` path.
    The evaluation with automatic labels is read from ``out_dir/label_eval.json`` (written by
    ``facetraj report --automatic-labels``, about half an hour) when present, and the evaluation
    with a second voice from ``out_dir/voice_eval.json`` (``facetraj report --second-voice``), and
    the closure of the lips from ``out_dir/closure_eval.json`` (``facetraj report --closure``).
    ``workers`` and ``skip``: as :func:`~.compute.compute_report`'s. Nothing is written when the
    computation fails.
    """
    out = Path(out_dir)
    data = compute_report(corpus_dir, model, progress, ns, workers=workers, skip=skip)
    out.mkdir(parents=True, exist_ok=True)
    data.label_eval = read_label_eval(out / LABEL_EVAL_FILE)
    data.voice_eval = read_voice_eval(out / VOICE_EVAL_FILE)
    data.closure_eval = read_closure_eval(out / CLOSURE_EVAL_FILE)
    if figures is not None:
        fig_dir = out / "figures"
        fig_dir.mkdir(exist_ok=True)
        made = figures(data, fig_dir)
        data.figures = {k: Path(os.path.relpath(p, out)).as_posix() for k, p in made.items()}
    md = out / "results.md"
    with atomic_write(md) as tmp:
        tmp.write_text(render_markdown(data), encoding="utf-8")
    for p in (md, write_json(out / "results.json", data.to_json())):
        p.chmod(0o644)  # atomic_write's temporary files are private
    log.info("report written to %s", md)
    return md


__all__ = ["ComparisonRow", "CorpusSummary", "Figure4Data", "FigureMaker", "GlanceRow",
           "ModelSummary", "ReportData", "SweepTable", "Table1Agreement", "at_a_glance",
           "compute_report", "discussion", "figure4_data", "find_utterance", "render_markdown",
           "summarise", "sweep_table", "table1_agreement", "write_report"]
