"""How close automatic phone labels are to reference labels: boundary error and phone error rate.

The paper's phonetic mode used aligner labels (section 3); these measures say how much such labels
differ from hand-checked or exact ones:

- the two phone sequences are matched by a minimum edit-distance alignment (substitution,
  insertion, deletion cost 1; silence merged and kept, since its edges are boundaries too);
- a **boundary** is the start of a reference phone (not the first) matched to a hypothesis phone
  whose predecessor is matched to the reference predecessor; its error is the difference of the
  two start times;
- the **phone error rate** is the edit distance between the non-silence phone sequences divided
  by the reference's phone count (substitutions + deletions + insertions) / N.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from .data import PhoneSegment
from .phones import SILENCE, apply_label_map

if TYPE_CHECKING:
    from .report.rows import ComparisonRow

#: A boundary "agrees" when within this many seconds (the usual 20 ms tolerance).
TOLERANCE_S = 0.020


def merged(phones: Sequence[PhoneSegment], label_map: Mapping[str, str] | None = None
           ) -> list[PhoneSegment]:
    """Labels mapped onto ARPAbet (``label_map``, e.g. MOCHA's) with adjacent silences merged.

    >>> [s.label for s in merged([PhoneSegment(0, 1, "sil"), PhoneSegment(1, 2, "breath"),
    ...                           PhoneSegment(2, 3, "@")], {"@": "ah", "breath": "sil"})]
    ['sil', 'ah']
    """
    out: list[PhoneSegment] = []
    for s in phones:
        lab = apply_label_map(s.label, label_map)
        if out and lab == SILENCE and out[-1].label == SILENCE:
            out[-1] = PhoneSegment(out[-1].start, s.end, SILENCE)
        else:
            out.append(PhoneSegment(s.start, s.end, lab))
    return out


def edit_alignment(ref: Sequence[str], hyp: Sequence[str]) -> tuple[int, list[tuple[int, int]]]:
    """Minimum edit distance of two label sequences and the matched pairs ``(i, j)``
    (equal or substituted labels), in order.

    >>> edit_alignment("abcd", "abd")
    (1, [(0, 0), (1, 1), (3, 2)])
    >>> edit_alignment("ab", "xb")[0]
    1
    """
    n, m = len(ref), len(hyp)
    d = np.zeros((n + 1, m + 1), dtype=int)
    d[:, 0] = np.arange(n + 1)
    d[0, :] = np.arange(m + 1)
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            d[i, j] = min(d[i - 1, j] + 1, d[i, j - 1] + 1,
                          d[i - 1, j - 1] + (ref[i - 1] != hyp[j - 1]))
    pairs: list[tuple[int, int]] = []
    i, j = n, m
    while i > 0 and j > 0:
        if d[i, j] == d[i - 1, j - 1] + (ref[i - 1] != hyp[j - 1]):
            pairs.append((i - 1, j - 1))
            i, j = i - 1, j - 1
        elif d[i, j] == d[i - 1, j] + 1:
            i -= 1
        else:
            j -= 1
    return int(d[n, m]), pairs[::-1]


def boundary_errors(reference: Sequence[PhoneSegment], hypothesis: Sequence[PhoneSegment]
                    ) -> np.ndarray:
    """Signed errors (hypothesis - reference, seconds) of the matched phone boundaries.

    Labels are compared as given (map and merge them first with :func:`merged`).

    >>> ref = [PhoneSegment(0, .2, "sil"), PhoneSegment(.2, .3, "b"), PhoneSegment(.3, .5, "iy")]
    >>> hyp = [PhoneSegment(0, .21, "sil"), PhoneSegment(.21, .33, "b"), PhoneSegment(.33, .5, "iy")]
    >>> boundary_errors(ref, hyp).round(3).tolist()
    [0.01, 0.03]
    """
    _, pairs = edit_alignment([s.label for s in reference], [s.label for s in hypothesis])
    errors = [hypothesis[j].start - reference[i].start
              for (pi, pj), (i, j) in pairwise(pairs)
              if i == pi + 1 and j == pj + 1]
    return np.array(errors, dtype=float)


def phone_error_rate(reference: Sequence[PhoneSegment], hypothesis: Sequence[PhoneSegment]
                     ) -> tuple[int, int]:
    """Edit distance between the non-silence phone sequences, and the reference's phone count.

    >>> ref = [PhoneSegment(0, 1, "sil"), PhoneSegment(1, 2, "b"), PhoneSegment(2, 3, "iy")]
    >>> phone_error_rate(ref, [PhoneSegment(0, 2, "p"), PhoneSegment(2, 3, "iy")])
    (1, 2)
    """
    r = [s.label for s in reference if s.label != SILENCE]
    h = [s.label for s in hypothesis if s.label != SILENCE]
    return edit_alignment(r, h)[0], len(r)


@dataclass
class LabelAccuracy:
    """Accuracy of one labelling method over a set of utterances.

    ``median_error_ms``: median absolute boundary error; ``within_20ms``: share of boundaries
    within :data:`TOLERANCE_S`; ``per``: phone error rate (edits / reference phones).
    """

    method: str
    utterances: int
    boundaries: int
    median_error_ms: float
    within_20ms: float
    per: float

    def to_json(self) -> dict:
        return dict(self.__dict__)


def summarise(method: str, pairs: Iterable[tuple[Sequence[PhoneSegment], Sequence[PhoneSegment]]],
              label_map: Mapping[str, str] | None = None) -> LabelAccuracy:
    """:class:`LabelAccuracy` of ``(reference, hypothesis)`` label pairs (``label_map`` maps the
    reference labels onto ARPAbet)."""
    errors: list[np.ndarray] = []
    edits = total = n = 0
    for ref, hyp in pairs:
        ref_m, hyp_m = merged(ref, label_map), merged(hyp)
        errors.append(boundary_errors(ref_m, hyp_m))
        e, t = phone_error_rate(ref_m, hyp_m)
        edits, total, n = edits + e, total + t, n + 1
    err = np.abs(np.concatenate(errors)) if errors else np.zeros(0)
    return LabelAccuracy(method, n, int(err.size),
                         float(np.median(err) * 1000) if err.size else float("nan"),
                         float(np.mean(err <= TOLERANCE_S + 1e-9)) if err.size else float("nan"),
                         edits / total if total else float("nan"))


# --------------------------------------------------------------------------- the report section
#: The real MOCHA-TIMIT sample read from ``../shared`` when present: (folder, utterance, sentence).
MOCHA_SAMPLE = ("data/mocha_fsew0_001", "fsew0_001", "This was easy for us.")


def accuracy_rows(corpus, mocha_dir=None, progress=None) -> list[dict]:
    """The accuracy table: alignment and recognition against the MOCHA sample's hand labels (when
    ``mocha_dir`` holds it) and against the exact labels of ``corpus``'s test split."""
    from .formats import read_audio, read_lab
    from .labelling import label_audio, label_utterance
    from .labelmap import read_label_map

    progress = progress or (lambda f, m: None)
    rows = []
    if mocha_dir is not None:
        from pathlib import Path

        stem, sentence = MOCHA_SAMPLE[1], MOCHA_SAMPLE[2]
        wav = Path(mocha_dir) / f"{stem}.wav"
        if wav.exists():
            audio, rate = read_audio(wav)
            hand = read_lab(wav.with_suffix(".lab"))
            mocha = read_label_map("mocha")
            for method in ("aligned", "recognized"):
                lab = label_audio(audio, rate, method, sentence if method == "aligned" else "")
                rows.append({"data": f"MOCHA-TIMIT {stem} (real speech, hand labels)",
                             **summarise(method, [(hand, lab.phones)], mocha).to_json()})
    ids = list(corpus.info.test)
    pairs: dict[str, list] = {"aligned": [], "recognized": []}
    fell_back = 0
    for k, utt_id in enumerate(ids):
        progress(k / max(len(ids), 1), f"labels: {utt_id}")
        utt = corpus.utterance(utt_id)
        for method in pairs:
            lab, error = label_utterance(utt, method)
            fell_back += bool(error)
            pairs[method].append((utt.phones, lab.phones))
    for method, ps in pairs.items():
        row = summarise(method, ps).to_json()
        if method == "aligned":
            row["fell_back_to_recognition"] = fell_back
        rows.append({"data": f"{corpus.root.name} test split (exact labels)", **row})
    return rows


def aligned_table2(corpus, model_exact, progress=None, train_config=None) -> list[dict]:
    """Table 2 rows with automatic labels (the paper trained and tested on aligner labels): a
    model trained on the aligned-label corpus, scored on train and test with aligned labels, and
    on the test split with recognized labels; the exact-label model on recognized test labels."""
    from .config import SynthConfig
    from .evaluation import evaluate
    from .labelling import relabelled
    from .report.rows import summarise as summarise_scores
    from .training import train

    progress = progress or (lambda f, m: None)
    aligned = relabelled(corpus, "aligned")
    recognized = relabelled(corpus, "recognized", split="test")
    progress(0.05, "training on aligned labels")
    model_aligned = train(aligned, config=train_config)
    phonetic = [SynthConfig(mode="phonetic")]
    runs = [
        ("aligned", "aligned", model_aligned, aligned, ("train", "test")),
        ("aligned", "recognized", model_aligned, recognized, ("test",)),
        ("exact", "recognized", model_exact, recognized, ("test",)),
    ]
    rows = []
    for k, (trained, tested, model, corp, splits) in enumerate(runs):
        res = evaluate(model, corp, splits, phonetic, ("triangular", "spline"),
                       progress=lambda f, m, k=k: progress(0.2 + 0.8 * (k + f) / len(runs), m))
        for r in summarise_scores(res.scores):
            rows.append({"trained_on": trained, "tested_on": tested, **r.to_json()})
    return rows


def render_section(section: dict) -> list[str]:
    """The report's markdown section on automatic labels (accuracy table, Table 2 rows)."""
    lines = ["## Automatic phone labels (forced alignment and phone recognition)", "",
             "Phonetic mode needs phone labels; the paper obtained them with an HMM aligner from the "
             "transcripts. `engine/alignment.py` does the same with PocketSphinx "
             f"{section.get('pocketsphinx', '')} (US English acoustic model, CMU dictionary): "
             "**aligned** = forced alignment of the transcript, **recognized** = phone recognition "
             "without text. Boundaries are compared after an edit-distance match of the two phone "
             "sequences (`engine/label_accuracy.py`); phone error rate = (substitutions + "
             "deletions + insertions) / reference phones.", "",
             "| Data | Labels | Utterances | Boundaries | Median abs. boundary error (ms) | "
             "Within 20 ms | Phone error rate |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for r in section["accuracy"]:
        lines.append(f"| {r['data']} | {r['method']} | {r['utterances']} | {r['boundaries']} | "
                     f"{r['median_error_ms']:.1f} | {100 * r['within_20ms']:.0f} % | "
                     f"{100 * r['per']:.1f} % |")
    fb = [r.get("fell_back_to_recognition", 0) for r in section["accuracy"]
          if r["method"] == "aligned" and "fell_back_to_recognition" in r]
    if fb and fb[0]:
        lines += ["", f"{fb[0]} test transcript(s) did not align (the aligner judged the text not to "
                      "fit the audio) and were recognized instead."]
    if section.get("table2"):
        lines += ["", "### Table 2 with automatic labels", "",
                  "Phonetic mode, N = 3. *Trained on* = the labels of the training utterances the "
                  "model was built from; *tested on* = the labels given at synthesis. Exact labels "
                  "and acoustic-only (no labels) are the Table 2 and comparison rows above.", "",
                  "| Trained on | Tested on | Split | Smoothing | Whole face | Lower lip | Upper lip "
                  "| Utterances |", "|---|---|---|---|---:|---:|---:|---:|"]
        for r in section["table2"]:
            lines.append(f"| {r['trained_on']} | {r['tested_on']} | {r['split']} | "
                         f"{r['smoothing']} | {_pm(r, 'whole_face')} | {_pm(r, 'lower_lip')} | "
                         f"{_pm(r, 'upper_lip')} | {r['n']} |")
        for r in section.get("reference", []):
            lines.append(f"| {r['trained_on']} | {r['tested_on']} | {r['split']} | "
                         f"{r['smoothing']} | {_pm(r, 'whole_face')} | {_pm(r, 'lower_lip')} | "
                         f"{_pm(r, 'upper_lip')} | {r['n']} |")
    lines.append("")
    return lines


def _pm(row: dict, m: str) -> str:
    v, sd = row.get(m), row.get(f"{m}_std")
    if v is None or not np.isfinite(v):
        return "–"
    return f"{v:.3f}" + (f" ± {sd:.3f}" if sd is not None and np.isfinite(sd) else "")


def label_section(corpus, model_exact, comparisons: Sequence[ComparisonRow] = (), mocha_dir=None,
                  progress=None) -> dict:
    """Every number of the report's automatic-label section: the accuracy table and the Table 2
    rows with automatic labels, beside the exact-label and acoustic-only test rows
    (``comparisons``, the report's rows)."""
    from .alignment import pocketsphinx_version

    progress = progress or (lambda f, m: None)
    acc = accuracy_rows(corpus, mocha_dir, lambda f, m: progress(0.3 * f, m))
    rows = aligned_table2(corpus, model_exact, lambda f, m: progress(0.3 + 0.7 * f, m))
    ref = []
    for r in comparisons:
        if r.split == "test" and r.mode in ("phonetic", "acoustic"):
            label = "exact" if r.mode == "phonetic" else "none (acoustic-only)"
            ref.append({**r.to_json(), "trained_on": "exact", "tested_on": label})
    return {"pocketsphinx": pocketsphinx_version(), "accuracy": acc, "table2": rows,
            "reference": ref}
