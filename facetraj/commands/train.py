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
    from facetraj_engine.io.corpus import load_corpus
    from facetraj_engine.io.files import check_output_path
    from facetraj_engine.method.training import train

    check_output_path(args.output, args.overwrite, probe=True)  # before training, not after
    corpus = load_corpus(args.corpus)
    log_label_census(corpus)
    skipped = skips(args)
    model = train(corpus, config=train_config(args), progress=TerminalProgress("train"),
                  workers=jobs(args), skip=skipped)
    folds = tune_folds(args, model.trained_labels, len(model.train_utterances))
    if folds:
        from facetraj_engine.evaluation.tuning import cross_validate

        tuning = cross_validate(corpus.without(skipped.bad if skipped else ()), train_config(args),
                                folds=folds,
                                progress=TerminalProgress("cross-validation"))
        model.tuned = tuning.to_json()
        log.info("robust-mode settings by %d-fold cross-validation on the training split: %s",
                 folds, tuning.settings)
    out = model.save(args.output, overwrite=args.overwrite)
    cb = model.codebook
    log.info("trained on %d utterances: %d context-phones, %d codewords, %d PCs (%.2f %% of "
             "variance), %d phones", len(model.train_utterances), cb.n_contexts, len(cb.lsf),
             model.pca.n_components, 100 * model.pca.explained_ratio.sum(), len(model.phones))
    print(out)
    return finish(skipped)


def log_label_census(corpus) -> None:
    """How the corpus's labels were made, phone by phone (the label files as training and
    evaluation read them: corrections made in the app or in Praat count as hand-checked)."""
    from facetraj_engine.io.label_census import label_census

    log.info("%s: labels of %d utterances, %s", corpus.root.name, len(corpus.info.ids),
             label_census(corpus).describe())


def tune_folds(args: argparse.Namespace, trained_labels: dict[str, int], n_train: int = 2) -> int:
    """How many folds the robust mode's settings are cross-validated on: ``--tune FOLDS``;
    ``--no-tune`` none; by default 2 when the training labels are not all hand-checked (the
    robust mode will synthesize from such labels, and its untuned settings lose to acoustic-only
    on real talkers) and there are two training utterances to fold, else none."""
    kinds = ", ".join(f"{n} {k}" for k, n in sorted(trained_labels.items()))
    if args.tune is not None:
        return args.tune
    if set(trained_labels) <= {"hand-checked"}:
        log.info("training labels: %s; the robust mode is not tuned (--tune to tune it)",
                 kinds or "hand-checked")
        return 0
    if n_train < 2:
        log.info("training labels: %s, not all hand-checked, but %d training utterance is too few "
                 "to cross-validate the robust mode's settings: its defaults are used", kinds,
                 n_train)
        return 0
    log.info("training labels: %s, not all hand-checked: cross-validating the robust mode's "
             "settings on the training split (--no-tune to skip)", kinds)
    return 2


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("train", help="train a model on a corpus folder")
    p.add_argument("corpus", type=Path)
    p.add_argument("-o", "--output", type=Path, required=True, help="model file (.npz)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    tune = p.add_mutually_exclusive_group()
    tune.add_argument("--tune", type=integer(2, 100), nargs="?", const=2, default=None,
                      metavar="FOLDS",
                      help="choose the robust mode's N, gamma range, label weight, candidates "
                           "and smoothing width by FOLDS-fold cross-validation (default 2) on the "
                           "training split, stored in the model (minutes); the default when the "
                           "training labels are not hand-checked")
    tune.add_argument("--no-tune", dest="tune", action="store_const", const=0,
                      help="do not cross-validate, even for automatic labels")
    add_corpus_work_options(p)
    add_train_options(p)
    p.set_defaults(func=cmd_train)
