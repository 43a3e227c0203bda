"""``facetraj train``: a model from a corpus folder (paper 2.1-2.2)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from ..corpus_work import add_corpus_work_options, finish, jobs, skips
from ..options import add_train_options, integer, train_config
from ..progress import TerminalProgress

log = logging.getLogger("facetraj")


def cmd_train(args: argparse.Namespace) -> int:
    from engine.io.corpus import load_corpus
    from engine.io.files import check_output_path
    from engine.method.training import train

    check_output_path(args.output, args.overwrite)  # before training, not after
    corpus = load_corpus(args.corpus)
    skipped = skips(args)
    model = train(corpus, config=train_config(args), progress=TerminalProgress("train"),
                  workers=jobs(args, 1), skip=skipped)
    if args.tune:
        from engine.evaluation.tuning import cross_validate

        tuning = cross_validate(corpus.without(skipped.bad if skipped else ()), train_config(args),
                                folds=args.tune,
                                progress=TerminalProgress("cross-validation"))
        model.tuned = tuning.to_json()
        log.info("robust-mode settings by %d-fold cross-validation on the training split: %s",
                 args.tune, tuning.settings)
    out = model.save(args.output, overwrite=args.overwrite)
    cb = model.codebook
    log.info("trained on %d utterances: %d context-phones, %d codewords, %d PCs (%.2f %% of "
             "variance), %d phones", len(model.train_utterances), cb.n_contexts, len(cb.lsf),
             model.pca.n_components, 100 * model.pca.explained_ratio.sum(), len(model.phones))
    print(out)
    return finish(skipped)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("train", help="train a model on a corpus folder")
    p.add_argument("corpus", type=Path)
    p.add_argument("-o", "--output", type=Path, required=True, help="model file (.npz)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    p.add_argument("--tune", type=integer(2, 100), nargs="?", const=2, default=0, metavar="FOLDS",
                   help="choose the robust mode's N, xi, gamma range, label and context weights "
                        "and smoothing width by FOLDS-fold cross-validation (default 2) on the "
                        "training split, stored in the model (a few minutes)")
    add_corpus_work_options(p, jobs_default="1")
    add_train_options(p)
    p.set_defaults(func=cmd_train)
