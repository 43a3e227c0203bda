"""The report's section on automatic phone labels: their accuracy against hand and exact labels
(:mod:`facetraj_engine.evaluation.label_accuracy`) and Table 2 with aligned and recognized labels."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..evaluation.label_accuracy import summarise
from .rows import ComparisonRow

#: The real MOCHA-TIMIT sample read from ``../shared`` when present: (folder, utterance, sentence).
MOCHA_SAMPLE = ("data/mocha_fsew0_001", "fsew0_001", "This was easy for us.")


def accuracy_rows(corpus, mocha_dir=None, progress=None) -> list[dict]:
    """The accuracy table: alignment and recognition against the MOCHA sample's hand labels (when
    ``mocha_dir`` holds it) and against the exact labels of ``corpus``'s test split."""
    from ..io.audio import read_audio
    from ..io.labelfiles import read_lab
    from ..io.labelling import label_audio, label_utterance
    from ..labels.labelmap import read_label_map

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
    from ..config import SynthConfig
    from ..evaluation.scores import evaluate
    from ..io.labelling import relabelled
    from ..method.training import train
    from .rows import summarise as summarise_scores

    progress = progress or (lambda f, m: None)
    aligned = relabelled(corpus, "aligned")
    recognized = relabelled(corpus, "recognized", split="test")
    progress(0.05, "training on aligned labels")
    model_aligned = train(aligned, config=train_config)
    phonetic = [SynthConfig(mode="phonetic", closure=False)]
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
             "transcripts. `engine/labels/alignment.py` does the same with PocketSphinx "
             f"{section.get('pocketsphinx', '')} (US English acoustic model, CMU dictionary): "
             "**aligned** = forced alignment of the transcript, **recognized** = phone recognition "
             "without text. Boundaries are compared after an edit-distance match of the two phone "
             "sequences (`engine/evaluation/label_accuracy.py`); phone error rate = (substitutions + "
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
    from ..labels.alignment import pocketsphinx_version

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
