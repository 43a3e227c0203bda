"""The report's discussion: one function per paragraph, each written from the numbers (so that
it stays true when the data change). A paragraph whose numbers are missing is left out."""

from __future__ import annotations

import itertools
from collections.abc import Callable

from ..config import SynthConfig
from ..evaluation.paper import (
    LEVELS_OFF_AT_N,
    MARKER_RATE_HZ,
    N_MARKERS,
    PAPER_TABLE2,
    TEST_MINUTES,
    TRAIN_MINUTES,
)
from .data import ReportData
from .rows import ComparisonRow, table1_agreement
from .text import fmt


def data_paragraph(data: ReportData) -> str:
    """The data are not the paper's: a synthetic corpus against one real talker."""
    c = data.corpus
    return (
        f"**The data are not the paper's.** The paper used about {TRAIN_MINUTES} minutes of training "
        f"and {TEST_MINUTES} minutes of test data from one real talker, {N_MARKERS} points tracked "
        f"optically at {MARKER_RATE_HZ} Hz. The default corpus "
        f"here ({c.n_train} training utterances, {c.train_minutes:.1f} min; {c.n_test} test "
        f"utterances, {c.test_minutes:.1f} min; {c.n_markers} markers at {c.marker_rate:g} Hz) "
        f"is synthetic: speech from the VocalTractLab articulatory synthesizer and a face rig driven "
        f"by the same articulatory tracks (jaw, lips), plus head motion, marker noise and dropouts "
        f"(`docs/corpus.md`). Its acoustics and face motion are therefore tied far more "
        f"deterministically than a real talker's, its rest posture in pauses is always the same "
        f"(the paper blames much of its error on variable silences), and its voice is a synthesizer's, "
        f"so neither the absolute correlations nor the similarity table can be expected to match.")


def train_test_paragraph(data: ReportData) -> str | None:
    """Train vs test (Table 2): the gap, the test figure against the paper's, the two lips."""
    tr, te = data.table2_row("train"), data.table2_row("test")
    if not (tr and te):
        return None
    paper_tr, paper_te = PAPER_TABLE2[("train", "triangular")], PAPER_TABLE2[("test", "triangular")]
    gap_ours = tr.whole_face - te.whole_face
    gap_paper = paper_tr[0] - paper_te[0]
    return (
        f"**Train vs test (Table 2).** Whole face, triangular: {fmt(tr.whole_face)} train and "
        f"{fmt(te.whole_face)} test here, {paper_tr[0]:.4f} and {paper_te[0]:.4f} in the paper (a gap "
        f"of {gap_ours:.2f} vs {gap_paper:.2f}). Resynthesizing a training utterance finds its own "
        f"context-phones in the codebook, so the training figure is an upper limit in both. "
        + ("Our test figure is higher than the paper's, which the deterministic synthetic "
           "articulation and fixed rest posture explain: what the codebook saw in training "
           "predicts held-out sentences well. "
           if te.whole_face > paper_te[0] + 0.02 else
           "Our test figure is below the paper's. " if te.whole_face < paper_te[0] - 0.02 else
           "Our test figure is close to the paper's. ")
        + f"Lips on test: lower {fmt(te.lower_lip)} (paper {paper_te[1]:.4f}), upper "
          f"{fmt(te.upper_lip)} (paper {paper_te[2]:.4f})"
        + ("; as in the paper, the lower lip, carried by the jaw, is predicted better than the "
           "upper lip." if te.lower_lip > te.upper_lip else
           "; unlike the paper, the upper lip is predicted at least as well as the lower lip. "
           "A likely reason is the synthetic rig: its upper lip follows one articulatory track, "
           "while its lower lip adds the jaw rotation and the lip opening, two sources the "
           "codebook must get right together.")
        + " The ± values are standard deviations over utterances: single sentences vary a lot, "
          "and short sentences with few speech frames give noisy correlations.")


def smoothing_paragraph(data: ReportData) -> str | None:
    """Triangular vs spline smoothing, and why our spline's lag decides the difference."""
    tr, te = data.table2_row("train"), data.table2_row("test")
    trs, tes = data.table2_row("train", "spline"), data.table2_row("test", "spline")
    if not (tr and te and trs and tes):
        return None
    tri_better = (te.whole_face >= tes.whole_face) and (tr.whole_face >= trs.whole_face)
    return (
        "**Triangular vs spline.** "
        + ("As in the paper, triangular smoothing scores above spline smoothing "
           f"(test whole face {fmt(te.whole_face)} vs {fmt(tes.whole_face)}). "
           if tri_better else
           "Unlike the paper, triangular smoothing does not score above spline smoothing "
           f"everywhere (test whole face {fmt(te.whole_face)} vs {fmt(tes.whole_face)}). ")
        + "The paper does not say how its spline was fitted; ours passes a cubic spline through "
          "box-averaged knots every 100 ms, which lags and flattens fast gestures (the delay the "
          "paper blames), so the size of this difference depends on that choice.")


def n_paragraph(data: ReportData) -> str | None:
    """N (Figure 5): where the held-out curve levels off, and whether the training curve falls."""
    sw = data.sweep
    if not sw.ns or sw.test_levels_off_at is None:
        return None
    trw = sw.curves["train"]["whole_face"]
    decreasing = all(b <= a + 1e-3 for a, b in itertools.pairwise(trw)) and trw[-1] < trw[0] - 0.005
    return (
        f"**N (Figure 5).** The paper's held-out curve levels off after N = {LEVELS_OFF_AT_N}. Ours "
        f"reaches within 0.005 of its best at N = {sw.test_levels_off_at} (best at N = "
        f"{sw.test_best_n}). "
        + ("As in the paper, the training curve falls as N grows: more context-phones dilute the "
           "exact training token. " if decreasing else
           f"Unlike the paper's, our training curve hardly falls ({trw[0]:.3f} at N = "
           f"{sw.ns[0]}, {trw[-1]:.3f} at N = {sw.ns[-1]}). The extra context-phones are "
           "tokens of the same phone in similar contexts, and in this synthetic corpus the face "
           "follows the phone sequence almost deterministically, so such tokens carry nearly the "
           "same face as the exact training token; diluting it costs little (the acoustic "
           "weights of eqs 5-6 also keep favouring the exact token, whose LSFs match the input). ")
        + (f"With only {data.corpus.n_test} test sentences the curve is noisy at the 0.005 level."
           if data.corpus.n_test < 30 else
           f"Our held-out curve keeps rising slowly beyond N = {LEVELS_OFF_AT_N}: the acoustic "
           "weights (eq 6) pick the best-matching codewords among the 5N candidates, so more "
           "candidates rarely hurt on this corpus, whose tokens of a phone vary little from one "
           "sentence to another."))


def _indexed_sentence(ac: ComparisonRow, ix: ComparisonRow | None) -> str:
    """The default indexed search against the whole-codebook search (empty without its row)."""
    if not ix:
        return ""
    return (
        f" The default indexed search (the {SynthConfig().acoustic_prefilter} codewords "
        f"nearest by eq 5, found in the model's LSF index) scores {fmt(ix.whole_face)} on "
        f"the same frames ({ix.whole_face - ac.whole_face:+.4f}): "
        + ("leaving out the far codewords costs nothing measurable here."
           if abs(ix.whole_face - ac.whole_face) <= 0.01 else
           "slightly better, because leaving out the far codewords removes their small "
           "pull towards the codebook's average face."
           if ix.whole_face > ac.whole_face else
           "the price of its speed (`docs/benchmarks.md`)."))


def acoustic_paragraph(data: ReportData) -> str | None:
    """Acoustic-only: the whole-codebook search against the phonetic one, then the indexed one."""
    te, ac = data.table2_row("test"), data.row("acoustic")
    if not (te and ac):
        return None
    return (
        f"**Acoustic-only.** Without labels (the whole codebook searched by eq 5) the test whole "
        f"face is {fmt(ac.whole_face)} against {fmt(te.whole_face)} with labels"
        + (": the phonetic restriction helps, as the paper expects (acoustically confusable "
           "phones such as /m/ and /n/ pick wrong faces). "
           if te.whole_face > ac.whole_face + 0.01 else
           ": the phonetic restriction makes little difference here (under 0.01), unlike the "
           "paper's expectation; the synthetic voice's spectra separate the phones, and their "
           "faces, well enough on their own. "
           if abs(te.whole_face - ac.whole_face) <= 0.01 else
           ": here the whole-codebook search is better than the restricted one, which suggests "
           "that N = 3 context-phones chosen by eq 4 often exclude the acoustically best "
           "codewords. ")
        + "The paper gives no number for this mode."
        + _indexed_sentence(ac, data.row("acoustic-indexed")))


def baselines_paragraph(data: ReportData) -> str | None:
    """The viseme lookup and the ridge regression against the paper's method."""
    te, vis, rid = data.table2_row("test"), data.row("viseme"), data.row("ridge")
    if not (te and vis and rid):
        return None
    best = max(("the paper's method", te.whole_face), ("the viseme lookup", vis.whole_face),
               ("the ridge regression", rid.whole_face), key=lambda x: x[1])
    return (
        f"**Baselines.** On the same test frames and smoothing, a viseme lookup (each frame gets "
        f"its phone's mean PC vector) scores {fmt(vis.whole_face)} and a ridge regression from "
        f"LSFs stacked over ±5 frames scores {fmt(rid.whole_face)}, against "
        f"{fmt(te.whole_face)} for the paper's method; {best[0]} is best. "
        + ("The codebook method beats both, so context-phones and acoustic weighting add "
           "something over labels alone and over a linear map. "
           if best[0] == "the paper's method" else
           "That a simpler method does as well or better is a warning against reading the "
           "absolute correlation as evidence for the codebook design on this corpus. ")
        + "The viseme lookup has no coarticulation and steps at phone boundaries (smoothed by the "
          "same 100 ms window); the ridge regression sees ±83 ms of acoustics but no labels.")


def table1_paragraph(data: ReportData) -> str:
    """Table 1: how many closest phones agree with the paper's, and why most cannot."""
    agree = table1_agreement(data.table1, data.paper_table1)
    same = [r.phone + "-" + r.neighbours[0][0] for r in data.table1
            if r.neighbours and r.phone in data.paper_table1
            and r.neighbours[0][0] == data.paper_table1[r.phone][0][0]]
    return (
        f"**Table 1.** Only {agree.same_closest} of {agree.phones_compared} phones have the "
        f"paper's closest phone ({', '.join(same) or 'none'}); on average "
        f"{fmt(agree.mean_top3_overlap, 2)} of the three neighbours agree. The visual similarity "
        "is computed from face PCs, and the synthetic face moves only with the jaw and lips: "
        "phones that differ in the tongue (invisible in both the paper's data and ours) or in "
        "cheek and lip shape details of a real talker cannot be told apart the same way, and our "
        "similarities are lower overall because the largest distance sets the scale (eq 3). "
        "The lip-driven groups that the paper highlights (b, p, m; f, v; s, z, sh, zh; ch, jh) are "
        "the ones to compare.")


def choices_paragraph(data: ReportData) -> str:
    """The choices the paper leaves open that move the numbers."""
    return (
        "**Choices the paper leaves open** also move the numbers: which coordinates make up the "
        "\"whole face\" average (here the "
        f"{data.model.moving_coordinates} head-normalised coordinates whose training standard "
        "deviation is at least 10 % of the largest; cheek, chin and nose points move little against "
        "the marker noise and pull the whole-face average down), the energy threshold of the "
        "speech/silence detector, the LSF analysis (order 18, 25 ms Hamming window, pre-emphasis "
        "0.97), and the scale of the distance before eq 3 (normalised by the largest distance; the "
        "paper does not say what its distances were measured in). See `docs/algorithm.md`.")


#: the discussion's paragraphs, in order
PARAGRAPHS: tuple[Callable[[ReportData], str | None], ...] = (
    data_paragraph, train_test_paragraph, smoothing_paragraph, n_paragraph, acoustic_paragraph,
    baselines_paragraph, table1_paragraph, choices_paragraph)


def discussion(data: ReportData) -> list[str]:
    """The discussion paragraphs, from the numbers (so that they stay true when the data change)."""
    return [p for paragraph in PARAGRAPHS if (p := paragraph(data)) is not None]


__all__ = ["PARAGRAPHS", "acoustic_paragraph", "baselines_paragraph", "choices_paragraph",
           "data_paragraph", "discussion", "n_paragraph", "smoothing_paragraph", "table1_paragraph",
           "train_test_paragraph"]
