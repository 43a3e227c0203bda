"""The ``facetraj`` command.

``facetraj`` alone opens the app on the default corpus; subcommands train, synthesize, evaluate,
sweep N, print the similarity table, render videos and the report, and build or describe corpora.
Bad input gives a one-line message naming the file and the problem, and exit status 2.
"""

from __future__ import annotations

import argparse
import gc
import logging
import sys
from collections.abc import Sequence

from facetraj_engine.errors import FacetrajError
from facetraj_engine.io.files import write_problem

from .commands import align, corpus, evaluate, gui, live, render, synth, train
from .options import SECONDS
from .paths import default_corpus

log = logging.getLogger("facetraj")

EXIT_BAD_INPUT = 2

#: The subcommand modules, in the order ``facetraj --help`` lists what they register.
COMMANDS = (gui, train, synth, align, evaluate, render, corpus, live)


class SubcommandParser(argparse.ArgumentParser):
    """A subcommand's parser: ``-v``/``-q`` after the subcommand too (``SUPPRESS`` keeps the value
    given before it). Nested subcommands (``corpus init``) are made of this class as well."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.add_argument("-v", "--verbose", action="count", default=argparse.SUPPRESS,
                          help="log details (-vv: also the libraries' own debug messages)")
        self.add_argument("-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
                          help="log only errors")


def build_parser() -> argparse.ArgumentParser:
    """The command's parser, every subcommand registered."""
    parser = argparse.ArgumentParser(
        prog="facetraj",
        description="Speech-driven 3-D face point trajectory synthesis (Arslan & Talkin). "
                    "Without a subcommand, opens the app on the default corpus.")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="log details (-vv: also the libraries' own debug messages)")
    parser.add_argument("-q", "--quiet", action="store_true", help="log only errors")
    parser.add_argument("--version", action=_Version, nargs=0, help="print the version and exit")
    parser.add_argument("--screenshot", metavar="OUT.png",
                        help="render the app window to a PNG and exit")
    parser.add_argument("--utterance", help="utterance shown first")
    parser.add_argument("--time", type=SECONDS, help="cursor time in seconds")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=SubcommandParser)
    for module in COMMANDS:
        module.register(sub)
    return parser


class _Version(argparse.Action):
    """``--version``: facetraj's version (the engine's, written in one place), and whether the
    app is installed."""

    def __call__(self, parser, namespace, values, option_string=None):
        from facetraj_engine import __version__

        from .app_modules import APP_DISTRIBUTION, app_installed

        app = "" if app_installed() else f" (engine only: pip install {APP_DISTRIBUTION} for the app)"
        parser.exit(message=f"facetraj {__version__}{app}\n")


#: The packages whose messages ``-v`` shows (facetraj's own); every other logger (matplotlib's font
#: matching, PIL, ...) logs warnings and errors only, unless ``-vv`` is given.
OWN_LOGGERS = ("facetraj", "facetraj_engine", "facetraj_app", "benchmarks")


def configure_logging(verbose: int = 0, quiet: bool = False) -> None:
    """Log to stderr: facetraj's own messages from INFO (DEBUG with ``verbose``, ERROR only with
    ``quiet``); the libraries' messages from WARNING, and all of them with ``verbose >= 2``.
    Nothing changes when the root logger has handlers already (as ``logging.basicConfig``).

    ``-v`` used to turn every logger to DEBUG: of 323 lines of a ``facetraj -v --screenshot``, 292
    were matplotlib's font matching.
    """
    if logging.getLogger().handlers:
        return          # configured already (an embedding program, a test run): as basicConfig
    from .progress import LogAboveBar

    own = logging.DEBUG if verbose else logging.ERROR if quiet else logging.INFO
    libraries = logging.DEBUG if verbose >= 2 else max(own, logging.WARNING)
    handler = LogAboveBar()                 # lines above a progress bar, not through it
    handler.setFormatter(logging.Formatter("%(levelname)s: %(message)s"))
    logging.basicConfig(level=libraries, handlers=[handler])
    for name in OWN_LOGGERS:
        logging.getLogger(name).setLevel(own)


def main(argv: Sequence[str] | None = None) -> int:
    """The command with ``argv`` (``None``: this program's arguments, as the console command and
    ``python -m facetraj`` run it); its exit status. As the program, it then freezes what is
    left for the garbage collector (``gc.freeze``): the interpreter's teardown, which otherwise
    walks every object of the modules and the run again while it exits, is left with what it
    frees by their counts (issue 48)."""
    code = run(sys.argv[1:] if argv is None else list(argv))
    if argv is None:
        gc.freeze()
    return code


def run(argv: Sequence[str]) -> int:
    """The command with ``argv``; its exit status (bad input: 2, a one-line message)."""
    args = build_parser().parse_args(argv)
    configure_logging(args.verbose, args.quiet)
    if args.command is None:                    # the app on the default corpus
        args.corpus, args.func = None, gui.cmd_gui
    try:
        if args.command == "report" and args.corpus is None:
            args.corpus = default_corpus()
        return args.func(args)
    except FacetrajError as exc:
        print(f"facetraj: error: {exc}", file=sys.stderr)
        if hasattr(exc, "item") and hasattr(args, "skip_bad"):
            print("facetraj: (--skip-bad leaves out what has bad files and goes on)",
                  file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:  # a file the commands did not check themselves: still one line
        where = exc.filename or exc.filename2
        problem = write_problem(exc) if exc.strerror else str(exc)
        print(f"facetraj: error: {where + ': ' if where else ''}{problem}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
