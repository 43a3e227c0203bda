"""``facetraj eval``, ``sweep`` and ``similarity``: Table 2, Figure 5 and Table 1 of the paper."""

from __future__ import annotations

import argparse
import json
import logging
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING

from ..corpus_work import add_corpus_work_options, finish, jobs, skips
from ..options import POSITIVE, TOP_N, add_synth_options, integer, synth_config
from ..progress import TerminalProgress

if TYPE_CHECKING:
    from facetraj_engine.config import EvalConfig

log = logging.getLogger("facetraj")


def mode_rule(args: argparse.Namespace, model, corpus, splits) -> EvalConfig:
    """The evaluation settings of ``eval`` and ``sweep``: without ``--mode`` each utterance's mode
    follows its labels, as in ``synth`` (logged with the reason, for the first utterance)."""
    from facetraj_engine.config import EvalConfig
    from facetraj_engine.errors import FacetrajError
    from facetraj_engine.method.modes import TUNED_FIELDS, choose_mode

    from .train import log_label_census

    log_label_census(corpus)
    explicit = getattr(args, "mode", None) is not None
    keep = tuple(f for f in TUNED_FIELDS if getattr(args, f, None) is not None)
    first = next((u for sp in splits for u in getattr(corpus.info, sp)), None)
    try:
        utt = corpus.utterance(first) if first is not None else None
    except FacetrajError:       # a bad file: the evaluation reports it, or skips it
        utt = None
    if utt is not None:
        choice = choose_mode(synth_config(args), utt.phones, utt.provenance, explicit=explicit,
                             tuned=model.tuned, keep=keep)
        from facetraj_engine.io.corpus import label_source
        from facetraj_engine.io.labelfiles import LABEL_SUFFIXES

        where = label_source(corpus.data_root, first)
        log.info("%s: labels %s [%s]; %s%s", first, utt.provenance.describe(),
                 f"{where.name} beside the audio" if where.suffix.lower() in LABEL_SUFFIXES
                 else f"{where.name}'s PHONES", choice.describe(),
                 "" if explicit else " (each utterance's mode follows its labels)")
    return EvalConfig(by_labels=not explicit, keep=keep)


def log_modes(res) -> None:
    """Which modes the evaluation ran, with how many utterances each."""
    counts = Counter((s.mode, s.utterance) for s in res.scores)
    modes = Counter(mode for mode, _ in counts)
    log.info("synthesized in %s", ", ".join(f"{m} mode ({n} utterance{'s' * (n != 1)})"
                                           for m, n in modes.items()))


def baselines_result(args: argparse.Namespace, model, corpus, splits, skipped):
    """The viseme and ridge baselines fitted on the training split and scored on ``splits``
    (the utterances the evaluation skipped left out), or ``None`` with ``--no-baselines``."""
    if args.no_baselines:
        return None
    from facetraj_engine.evaluation.baselines import fit_and_score
    from facetraj_engine.evaluation.scores import EvalResult

    used = corpus.without(skipped.bad if skipped else ())
    _, scores = fit_and_score(model, used, splits, TerminalProgress("baselines"), jobs(args))
    return EvalResult(scores)


def cmd_eval(args: argparse.Namespace) -> int:
    from facetraj_engine.evaluation.scores import evaluate, format_table2
    from facetraj_engine.evaluation.sensors import format_sensor_report
    from facetraj_engine.io.corpus import load_corpus
    from facetraj_engine.method.model import Model

    model = Model.load(args.model)
    corpus = load_corpus(args.corpus)
    splits = ("train", "test") if args.split == "all" else (args.split,)
    eval_config = mode_rule(args, model, corpus, splits)
    configs = [synth_config(args)]
    if args.acoustic and configs[0].mode != "acoustic":
        configs.append(configs[0].with_(mode="acoustic"))
    skipped = skips(args)
    res = evaluate(model, corpus, splits, configs, ("triangular", "spline"), eval_config,
                   progress=TerminalProgress("eval"), workers=jobs(args), skip=skipped)
    log_modes(res)
    base = baselines_result(args, model, corpus, splits, skipped)
    if args.json:
        out = res.to_json()
        if base is not None:
            out["baselines"] = {k: v for k, v in base.to_json().items() if k != "utterances"}
        print(json.dumps(out, indent=2))
    else:
        print(format_table2(res) + "\n")
        print(format_sensor_report([res] if base is None else [res, base], splits))
    return finish(skipped)


def cmd_sweep(args: argparse.Namespace) -> int:
    from facetraj_engine.evaluation.scores import sweep_n
    from facetraj_engine.io.corpus import load_corpus
    from facetraj_engine.method.model import Model

    model = Model.load(args.model)
    corpus = load_corpus(args.corpus)
    ns = list(range(1, args.max_n + 1))
    splits = ("train", "test") if args.split == "all" else (args.split,)
    skipped = skips(args)
    res = sweep_n(model, corpus, ns, splits, mode_rule(args, model, corpus, splits),
                  progress=TerminalProgress("sweep"), workers=jobs(args), skip=skipped)
    log_modes(res)
    curve = {sp: [res.mean(sp, "triangular", n=n)["whole_face"] for n in ns] for sp in splits}
    if args.json:
        print(json.dumps({"n": ns, "whole_face": curve, "table": res.table()}, indent=2))
    else:
        print(f"{'N':>3} " + " ".join(f"{sp:>8}" for sp in splits))
        for i, n in enumerate(ns):
            print(f"{n:>3} " + " ".join(f"{curve[sp][i]:>8.4f}" for sp in splits))
    return finish(skipped)


def cmd_similarity(args: argparse.Namespace) -> int:
    from facetraj_engine.method.model import Model
    from facetraj_engine.method.similarity import format_table1, top_similar

    model = Model.load(args.model)
    s = model.similarity(args.nu)
    if args.csv:
        print("phone," + ",".join(model.phones))
        for p, row in zip(model.phones, s, strict=True):
            print(p + "," + ",".join(f"{v:.4f}" for v in row))
    else:
        print(format_table1(top_similar(s, model.phones, args.top)))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("eval", help="correlations on a corpus (Table 2) and per-sensor r and RMSE")
    p.add_argument("model", type=Path)
    p.add_argument("corpus", type=Path)
    p.add_argument("--split", choices=["train", "test", "all"], default="all")
    p.add_argument("--acoustic", action="store_true", help="add acoustic-only rows")
    p.add_argument("--json", action="store_true",
                   help="JSON output with per-utterance scores and the per-sensor tables")
    p.add_argument("--no-baselines", action="store_true",
                   help="leave out the viseme and ridge baselines (fitted on the training split)")
    add_corpus_work_options(p)
    add_synth_options(p)
    p.set_defaults(func=cmd_eval)

    p = sub.add_parser("sweep", help="correlation against N (Figure 5)")
    p.add_argument("model", type=Path)
    p.add_argument("corpus", type=Path)
    p.add_argument("--max-n", type=integer(1, 100), default=10)
    p.add_argument("--split", choices=["train", "test", "all"], default="all")
    p.add_argument("--json", action="store_true")
    add_corpus_work_options(p)
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser("similarity", help="visual phoneme similarity (Table 1)")
    p.add_argument("model", type=Path)
    p.add_argument("--nu", type=POSITIVE, help="eq 3 constant (default: the model's)")
    p.add_argument("--top", type=TOP_N, default=3)
    p.add_argument("--csv", action="store_true", help="the full K x K matrix as CSV")
    p.set_defaults(func=cmd_similarity)
