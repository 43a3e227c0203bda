"""The options and the end of the commands that work through a whole corpus (``eval``,
``sweep``, ``train``, ``corpus align``, ``report``, and ``corpus show``): ``--jobs`` and
``--skip-bad``, the summary of what was skipped, and the exit status.

Without ``--skip-bad`` the first bad file stops the command with its one-line error (exit status
2), with any number of jobs. With it, each utterance (or recording) with a bad file is left out,
the command finishes on the others and ends with ``k of n utterances skipped: <file>: <problem>``
and exit status 3: its result (a table, a model, TextGrids, a report) does not cover every input.
"""

from __future__ import annotations

import argparse
import logging
import sys

from .options import integer

log = logging.getLogger("facetraj")

#: exit status of a command that finished but left bad files out (``--skip-bad``)
EXIT_INCOMPLETE = 3


def add_corpus_work_options(p: argparse.ArgumentParser, noun: str = "utterances",
                            jobs: bool = True) -> None:
    """``--jobs/-j N`` (unless ``jobs`` is off) and ``--skip-bad`` (``noun``: what the command
    works through)."""
    if jobs:
        p.add_argument("--jobs", "-j", type=integer(1, 256), metavar="N",
                       help=f"{noun} processed in N processes (default: every core)")
    p.add_argument("--skip-bad", action="store_true",
                   help=f"leave out {noun} whose files are bad and go on: the command ends with "
                        f"a summary ('2 of 280 {noun} skipped: FILE: PROBLEM') and exit status 3, "
                        f"as its result is incomplete (without it, the first bad file stops the "
                        f"command: exit status 2)")


def jobs(args: argparse.Namespace, default: int | None = None) -> int:
    """The processes asked for: ``--jobs``, else ``default``, else every usable core."""
    from facetraj_engine.threads import usable_cores

    return args.jobs or default or usable_cores()


def skips(args: argparse.Namespace, noun: str = "utterances"):
    """An :class:`facetraj_engine.fanout.Skips` to collect skipped items when ``--skip-bad`` was given,
    else ``None`` (a bad file stops the command)."""
    if not getattr(args, "skip_bad", False):
        return None
    from facetraj_engine.fanout import Skips

    return Skips(noun)


def finish(skipped) -> int:
    """The end of a corpus-wide command: one line per kind of file warning with its count, the
    summary of what was skipped (printed even with ``-q``), and the exit status (0, or
    :data:`EXIT_INCOMPLETE` when something was skipped)."""
    from facetraj_engine.errors import file_warning_summary

    for line in file_warning_summary():
        log.warning("%s", line)
    if not skipped:
        return 0
    print(f"facetraj: {skipped.summary()}", file=sys.stderr)
    return EXIT_INCOMPLETE
