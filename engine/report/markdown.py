"""``results.md`` from the report data: one function per section, each returning its lines from
its heading to its last line; :func:`render_markdown` puts one blank line between sections."""

from __future__ import annotations

from pathlib import Path

from .. import __version__
from ..evaluation.closure_eval import format_markdown as closure_markdown
from ..evaluation.label_eval import format_markdown
from ..evaluation.paper import FIGURE4_TEXT, LEVELS_OFF_AT_N, TABLE2_N, table2_value
from ..evaluation.scores import METRICS
from ..evaluation.voice_eval import format_markdown as voice_markdown
from .data import ReportData, at_a_glance
from .discussion import discussion
from .rows import table1_agreement
from .sensors import sensors_section
from .text import fmt, mean_sd


def _figure(data: ReportData, name: str, title: str) -> list[str]:
    """The image line and a blank line when the figure was drawn, else nothing."""
    return [f"![{title}]({data.figures[name]})", ""] if name in data.figures else []


def header_section(data: ReportData) -> list[str]:
    """The title and what the numbers are."""
    c, m = data.corpus, data.model
    corpus = Path(c.root).name
    return [
        f"# Results: the paper's tables and figures on the `{corpus}` corpus",
        "",
        f"Written by `facetraj report` (facetraj {__version__}) on {data.created}. Corpus "
        f"`{corpus}/`: {c.n_train} training utterances ({c.train_minutes:.1f} min) "
        f"and {c.n_test} test utterances ({c.test_minutes:.1f} min), {c.n_markers} markers at "
        f"{c.marker_rate:g} Hz. Model: {m.n_pcs} PCs ({100 * m.variance_explained:.2f} % of "
        f"the variance), {m.n_context_phones} context-phones, {m.n_codewords} codewords, "
        f"{m.n_phones} phones. All correlations are Pearson correlations between original and "
        f"synthesized head-normalised trajectories on speech frames only (section 3), averaged over "
        f"utterances (± one standard deviation over utterances). All numbers are in "
        f"[`results.json`](results.json)." + _labels(c.labels) + _skipped(c.skipped),
    ]


def _labels(census: dict) -> str:
    """The sentence saying how the corpus's labels were made, phone by phone.

    >>> _labels({"phones": {"hand-checked": 40, "aligned": 0, "recognized": 960},
    ...          "corrected": {"a": 30, "b": 10}})
    ' Its phone labels: 1000 phones: 40 hand-checked (40 corrected by hand in 2 utterances), 960 recognized.'
    """
    if not census:
        return ""
    from ..io.label_census import LabelCensus

    return f" Its phone labels: {LabelCensus(census['phones'], {}, census.get('corrected', {})).describe()}."


def _skipped(skipped: dict[str, str]) -> str:
    """The sentence naming the utterances left out as bad (``--skip-bad``), or nothing."""
    if not skipped:
        return ""
    return (f" {len(skipped)} utterance{'s' if len(skipped) > 1 else ''} with bad files "
            f"{'were' if len(skipped) > 1 else 'was'} left out (`--skip-bad`): "
            + "; ".join(f"`{u}` ({msg})" for u, msg in skipped.items()) + ".")


def glance_section(data: ReportData) -> list[str]:
    """The paper's headline claims beside ours."""
    return [
        "## At a glance",
        "",
        "| The paper's result | Paper | Ours | Reproduced |",
        "|---|---|---|---|",
        *[f"| {g.claim} | {g.paper} | {g.ours} | "
          f"{'n/a' if g.same is None else ('yes' if g.same else 'no')} |" for g in at_a_glance(data)],
        "",
        "Numbers count as reproduced within ± 0.05. Why they differ: see the discussion at the end.",
    ]


def table2_section(data: ReportData) -> list[str]:
    """Table 2, ours beside the paper's."""
    lines = [f"## Table 2: correlation, original vs synthesized (N = {TABLE2_N})", "",
             "| Test condition | Whole face | Lower lip | Upper lip | Paper: whole | lower | upper |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in data.table2:
        p = table2_value(r.split, r.smoothing)
        lines.append(f"| {r.split.title()} ({r.smoothing}) | {mean_sd(r, 'whole_face')} | "
                     f"{mean_sd(r, 'lower_lip')} | {mean_sd(r, 'upper_lip')} | {fmt(p[0])} | "
                     f"{fmt(p[1])} | {fmt(p[2])} |")
    return lines


def figure5_section(data: ReportData) -> list[str]:
    """Figure 5 and its numbers, correlation against N."""
    sw = data.sweep
    lines = ["## Figure 5: correlation against N", "", *_figure(data, "figure5", "Figure 5"),
             "| N | " + " | ".join(str(n) for n in sw.ns) + " |",
             "|---|" + "---:|" * len(sw.ns)]
    for split in ("train", "test"):
        for metric in METRICS:
            lines.append(f"| {split} {metric.replace('_', ' ')} | "
                         + " | ".join(fmt(v, 3) for v in sw.curves[split][metric]) + " |")
    if sw.test_levels_off_at is not None:
        lines += ["", f"Triangular smoothing. The test whole-face curve comes within 0.005 of its "
                      f"best at N = {sw.test_levels_off_at} (best N = {sw.test_best_n}); the "
                      f"paper's levels off after N = {LEVELS_OFF_AT_N}."]
    return lines


def figure4_section(data: ReportData) -> list[str]:
    """The Figure-4 example and its correlations."""
    f4 = data.figure4
    if f4 is None:
        return ["## Figure 4: an example", "", "The corpus has no utterance to show."]
    said = (f"\"{f4.text}\" ({f4.utterance}, {f4.split} split)" if f4.found else
            f"The paper's sentence \"{FIGURE4_TEXT}\" is not in the corpus; {f4.utterance} "
            f"({f4.split} split, \"{f4.text}\") stands in")
    lines = ["## Figure 4: an example", "",
             f"{said}. Top: the speech signal. Middle and bottom: upper and lower lip centre "
             f"y (mm, head-normalised): original (dotted), spline (dark) and triangular (light) "
             f"synthesis, N = 3; dots along the middle mark the frames detected as speech.", "",
             *_figure(data, "figure4", "Figure 4"),
             "| Smoothing | Whole face | Lower lip | Upper lip |", "|---|---:|---:|---:|"]
    for sm, cor in f4.correlations.items():
        lines.append(f"| {sm} | {fmt(cor['whole_face'])} | {fmt(cor['lower_lip'])} | "
                     f"{fmt(cor['upper_lip'])} |")
    return lines


#: the order of the comparison table's methods
COMPARISON_ORDER = {"phonetic": 0, "acoustic": 1, "acoustic-indexed": 2, "viseme": 3, "ridge": 4}


def comparisons_section(data: ReportData) -> list[str]:
    """Every method on the same split: test before train, triangular before spline."""
    lines = ["## Comparisons on the same split", "",
             "The paper's method with labels (phonetic, N = 3), without them (acoustic-only: eq 5 "
             "over the whole codebook, as the paper; and the default indexed search), and two "
             "baselines fitted on the training split only (`engine/evaluation/baselines.py`), all scored the "
             "same way.", "", *_figure(data, "comparison", "Comparison"),
             "| Method | Split | Smoothing | Whole face | Lower lip | Upper lip | Utterances |",
             "|---|---|---|---:|---:|---:|---:|"]
    for r in sorted(data.comparisons, key=lambda r: (r.split != "test", r.smoothing != "triangular",
                                                     COMPARISON_ORDER.get(r.mode, 9))):
        lines.append(f"| {r.method} | {r.split} | {r.smoothing} | {mean_sd(r, 'whole_face')} | "
                     f"{mean_sd(r, 'lower_lip')} | {mean_sd(r, 'upper_lip')} | {r.n} |")
    return lines


def labels_section(data: ReportData) -> list[str]:
    """Automatic phone labels: their accuracy, and Table 2 with them (none without transcripts)."""
    if not data.labels:
        return []
    from .labels import render_section

    return render_section(data.labels)[:-1]


def table1_section(data: ReportData) -> list[str]:
    """Table 1, ours beside the paper's, and how many agree."""
    config = data.model.config
    agree = table1_agreement(data.table1, data.paper_table1)
    lines = ["## Table 1: the three visually most similar phones", "",
             f"Eqs 1-3 (nu = {config['nu']:g}, distances scaled by "
             f"`{config['distance_scale']}`). Of the {agree.phones_compared} phones in both "
             f"tables, {agree.same_closest} have the same closest phone as the paper; on average "
             f"{fmt(agree.mean_top3_overlap, 2)} of the three neighbours agree.", "",
             "| Phone | Closest | 2nd | 3rd | Paper: closest | 2nd | 3rd |",
             "|---|---|---|---|---|---|---|"]
    for r in data.table1:
        ours = [f"{p} {v:.2f}" for p, v in r.neighbours] + [""] * (3 - len(r.neighbours))
        paper = [f"{p} {v:.2f}" for p, v in data.paper_table1.get(r.phone, [])] or ["", "", ""]
        lines.append(f"| {r.phone} | " + " | ".join(ours + paper) + " |")
    return lines


def discussion_section(data: ReportData) -> list[str]:
    """The discussion's paragraphs, a blank line between them."""
    lines = ["## Discussion: where and why we differ from the paper", ""]
    for k, paragraph in enumerate(discussion(data)):
        lines += [paragraph] if k == 0 else ["", paragraph]
    return lines


def automatic_labels_section(data: ReportData) -> list[str]:
    """Every mode and baseline under exact, aligned and recognized labels
    (``facetraj_engine.evaluation.label_eval``),
    when an evaluation was saved beside the report; else nothing."""
    if data.label_eval is None:
        return []
    return ["## Beyond the paper: automatic labels on held-out sentences", "",
            format_markdown(data.label_eval)]


def second_voice_section(data: ReportData) -> list[str]:
    """Acoustic-only synthesis from a voice other than the training voice, with and without
    speaker normalisation (``facetraj_engine.evaluation.voice_eval``), when an evaluation was saved beside the
    report;
    else nothing."""
    if data.voice_eval is None:
        return []
    return ["## Beyond the paper: a voice other than the training voice", "",
            voice_markdown(data.voice_eval)]


def closure_section(data: ReportData) -> list[str]:
    """Lips that close, per mode and label source (``facetraj_engine.evaluation.closure_eval``), when an
    evaluation was saved beside the report; else nothing."""
    return [] if data.closure_eval is None else closure_markdown(data.closure_eval)


def reproducing_section(data: ReportData) -> list[str]:
    """The command that wrote the report, and how long each stage took."""
    return ["## Reproducing", "",
            "```sh", "facetraj report data_samples -o docs     # or: make report", "```", "",
            "Run time: " + ", ".join(f"{k.replace('_', ' ')} {v:.0f} s"
                                     for k, v in data.timings.items()) + "."]


#: the sections of ``results.md``, in order
SECTIONS = (header_section, glance_section, table2_section, figure5_section, figure4_section,
            comparisons_section, sensors_section, labels_section, table1_section, automatic_labels_section,
            second_voice_section, closure_section, discussion_section, reproducing_section)


def render_markdown(data: ReportData) -> str:
    """``results.md`` from the report data (sections with nothing to say are left out)."""
    lines: list[str] = []
    for section in SECTIONS:
        part = section(data)
        if part:
            lines += [*part, ""]
    return "\n".join(lines)


__all__ = ["COMPARISON_ORDER", "SECTIONS", "automatic_labels_section", "closure_section",
           "comparisons_section",
           "discussion_section", "figure4_section", "figure5_section", "glance_section",
           "header_section", "labels_section", "render_markdown", "reproducing_section",
           "second_voice_section", "table1_section", "table2_section"]
