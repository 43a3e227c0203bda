"""``facetraj eval``, ``sweep`` and ``similarity``: Table 2, Figure 5 and Table 1 of the paper."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..corpus_work import add_corpus_work_options, finish, jobs, skips
from ..options import POSITIVE, TOP_N, add_synth_options, integer, synth_config
from ..progress import TerminalProgress


def cmd_eval(args: argparse.Namespace) -> int:
    from engine.evaluation.scores import evaluate, format_table2
    from engine.io.corpus import load_corpus
    from engine.method.model import Model

    model = Model.load(args.model)
    corpus = load_corpus(args.corpus)
    splits = ("train", "test") if args.split == "all" else (args.split,)
    configs = [synth_config(args)]
    if args.acoustic and configs[0].mode != "acoustic":
        configs.append(configs[0].with_(mode="acoustic"))
    skipped = skips(args)
    res = evaluate(model, corpus, splits, configs, ("triangular", "spline"),
                   progress=TerminalProgress("eval"), workers=jobs(args), skip=skipped)
    print(json.dumps(res.to_json(), indent=2) if args.json else format_table2(res))
    return finish(skipped)


def cmd_sweep(args: argparse.Namespace) -> int:
    from engine.evaluation.scores import sweep_n
    from engine.io.corpus import load_corpus
    from engine.method.model import Model

    model = Model.load(args.model)
    corpus = load_corpus(args.corpus)
    ns = list(range(1, args.max_n + 1))
    splits = ("train", "test") if args.split == "all" else (args.split,)
    skipped = skips(args)
    res = sweep_n(model, corpus, ns, splits, progress=TerminalProgress("sweep"),
                  workers=jobs(args), skip=skipped)
    curve = {sp: [res.mean(sp, "triangular", n=n)["whole_face"] for n in ns] for sp in splits}
    if args.json:
        print(json.dumps({"n": ns, "whole_face": curve, "table": res.table()}, indent=2))
    else:
        print(f"{'N':>3} " + " ".join(f"{sp:>8}" for sp in splits))
        for i, n in enumerate(ns):
            print(f"{n:>3} " + " ".join(f"{curve[sp][i]:>8.4f}" for sp in splits))
    return finish(skipped)


def cmd_similarity(args: argparse.Namespace) -> int:
    from engine.method.model import Model
    from engine.method.similarity import format_table1, top_similar

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
    p = sub.add_parser("eval", help="correlations on a corpus (Table 2)")
    p.add_argument("model", type=Path)
    p.add_argument("corpus", type=Path)
    p.add_argument("--split", choices=["train", "test", "all"], default="all")
    p.add_argument("--acoustic", action="store_true", help="add acoustic-only rows")
    p.add_argument("--json", action="store_true", help="JSON output with per-utterance scores")
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
