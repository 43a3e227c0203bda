"""The ``facetraj`` command.

``facetraj`` alone opens the app on the default corpus; subcommands train, synthesize, evaluate,
sweep N, print the similarity table, render videos and the report, and build or describe corpora.
Bad input gives a one-line message naming the file and the problem, and exit status 2.
"""

from __future__ import annotations

import argparse
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

#: Each subcommand's module, in the order ``facetraj --help`` lists them (a test checks it
#: against what the modules register)
COMMAND_MODULES = {"gui": gui, "train": train, "synth": synth, "align": align, "eval": evaluate,
                   "sweep": evaluate, "similarity": evaluate, "report": render, "video": render,
                   "corpus": corpus, "live": live}
#: The subcommand modules, each once, in that order.
COMMANDS = tuple(dict.fromkeys(COMMAND_MODULES.values()))


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The command's parser: every subcommand, or only the one ``argv`` names (registering
    them all took 4-5 ms of every run, issue 28); the same parse of ``argv`` either way."""
    parser = _top_parser(argparse.ArgumentParser)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    command = None if argv is None else _command_named(argv)
    for module in (COMMAND_MODULES[command],) if command else COMMANDS:
        module.register(sub)
    for subparser in subcommand_parsers(parser):
        _add_verbosity(subparser)
    return parser


def _top_parser(kind: type[argparse.ArgumentParser], **kwargs) -> argparse.ArgumentParser:
    """The options before the subcommand."""
    parser = kind(
        prog="facetraj",
        description="Speech-driven 3-D face point trajectory synthesis (Arslan & Talkin). "
                    "Without a subcommand, opens the app on the default corpus.", **kwargs)
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="log details (-vv: also the libraries' own debug messages)")
    parser.add_argument("-q", "--quiet", action="store_true", help="log only errors")
    parser.add_argument("--version", action=_Version, nargs=0, help="print the version and exit")
    parser.add_argument("--screenshot", metavar="OUT.png",
                        help="render the app window to a PNG and exit")
    parser.add_argument("--utterance", help="utterance shown first")
    parser.add_argument("--time", type=SECONDS, help="cursor time in seconds")
    return parser


class _Probe(argparse.ArgumentParser):
    """A parser whose errors are exceptions, not a message and an exit."""

    def error(self, message: str):
        raise ValueError(message)


def _command_named(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` names after the top-level options, if it is one of
    :data:`COMMAND_MODULES` and no help is asked for before it; else ``None`` (then every
    subcommand is registered, for the help and the errors that list them)."""
    argv = list(argv)
    probe = _top_parser(_Probe, add_help=False)
    probe.add_argument("command", nargs="?")
    try:
        command = probe.parse_known_args(argv)[0].command
    except ValueError:
        return None
    if command not in COMMAND_MODULES or {"-h", "--help"} & set(argv[:argv.index(command)]):
        return None
    return command


class _Version(argparse.Action):
    """``--version``: the installed package's version, looked up only when asked
    (``importlib.metadata`` costs every other command 40 ms)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from importlib.metadata import PackageNotFoundError, version

        try:
            text = version("facetraj")
        except PackageNotFoundError:
            text = "(not installed)"
        parser.exit(message=f"facetraj {text}\n")


def subcommand_parsers(parser: argparse.ArgumentParser) -> list[argparse.ArgumentParser]:
    """Every (nested) subcommand parser under ``parser``, each once, in registration order."""
    found: list[argparse.ArgumentParser] = []
    for action in parser._actions:  # argparse offers no public walk over subparsers
        if isinstance(action, argparse._SubParsersAction):
            for child in dict.fromkeys(action.choices.values()):
                found.append(child)
                found.extend(subcommand_parsers(child))
    return found


def _add_verbosity(p: argparse.ArgumentParser) -> None:
    """``-v``/``-q`` after the subcommand too; SUPPRESS keeps the value given before it."""
    p.add_argument("-v", "--verbose", action="count", default=argparse.SUPPRESS,
                   help="log details (-vv: also the libraries' own debug messages)")
    p.add_argument("-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
                   help="log only errors")


#: The packages whose messages ``-v`` shows (facetraj's own); every other logger (matplotlib's font
#: matching, PIL, numba, ...) logs warnings and errors only, unless ``-vv`` is given.
OWN_LOGGERS = ("facetraj", "engine", "app", "benchmarks")


def configure_logging(verbose: int = 0, quiet: bool = False) -> None:
    """Log to stderr: facetraj's own messages from INFO (DEBUG with ``verbose``, ERROR only with
    ``quiet``); the libraries' messages from WARNING, and all of them with ``verbose >= 2``.
    Nothing changes when the root logger has handlers already (as ``logging.basicConfig``).

    ``-v`` used to turn every logger to DEBUG: of 323 lines of a ``facetraj -v --screenshot``, 292
    were matplotlib's font matching.
    """
    if logging.getLogger().handlers:
        return          # configured already (an embedding program, a test run): as basicConfig
    own = logging.DEBUG if verbose else logging.ERROR if quiet else logging.INFO
    libraries = logging.DEBUG if verbose >= 2 else max(own, logging.WARNING)
    logging.basicConfig(level=libraries, format="%(levelname)s: %(message)s")
    for name in OWN_LOGGERS:
        logging.getLogger(name).setLevel(own)


def main(argv: Sequence[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(argv).parse_args(argv)
    configure_logging(args.verbose, args.quiet)
    if args.command is None:
        args.corpus = default_corpus()
        args.func = gui.cmd_gui
    elif args.command in ("gui", "report") and args.corpus is None:
        args.corpus = default_corpus()
    try:
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
