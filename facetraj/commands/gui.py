"""``facetraj gui`` (and ``facetraj`` alone): the desktop app."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..app_modules import app_module
from ..options import SECONDS
from ..paths import default_corpus


def cmd_gui(args: argparse.Namespace) -> int:
    main = app_module("main", "facetraj gui")      # the app first: without it, nothing else matters
    if args.screenshot:
        from facetraj_engine.io.files import check_output_path

        check_output_path(args.screenshot, formats=(".png",), probe=True)   # before the window
    if args.corpus is None:
        args.corpus = default_corpus()
    recordings = app_module("recordings", "facetraj gui").recordings_in(args.corpus)
    corpus = default_corpus() if recordings else args.corpus
    utterance = args.utterance
    if recordings and utterance is not None:        # a recording of the folder, shown first
        recordings = first_recording(recordings, utterance, args.corpus)
        utterance = None
    return main.run_app(corpus=corpus, screenshot=args.screenshot, utterance=utterance,
                        time=args.time, model=getattr(args, "model", None), recordings=recordings)


def first_recording(recordings: list[Path], name: str, where: Path) -> list[Path]:
    """``recordings`` with the one named ``name`` (its file name, with or without the suffix)
    first; a name none has is refused, listing some that are there."""
    from facetraj_engine.errors import InputError

    chosen = [p for p in recordings if name in (p.stem, p.name)]
    if not chosen:
        names = ", ".join(p.stem for p in recordings[:8]) + (", ..." if len(recordings) > 8 else "")
        raise InputError(where, f"no recording named {name!r} here (recordings: {names})")
    return chosen[:1] + [p for p in recordings if p != chosen[0]]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("gui", help="open the app")
    p.add_argument("corpus", nargs="?", type=Path, default=None,
                   help="a corpus folder, or a recording (.wav, .flac) or folder of recordings "
                        "without face data to synthesize with the model (--model, else the "
                        "default corpus's)")
    p.add_argument("--model", type=Path, help="a trained model (default: train and cache)")
    p.add_argument("--screenshot", metavar="OUT.png", help="render to a PNG and exit")
    p.add_argument("--utterance", help="utterance shown first (of a folder of recordings: the "
                                       "recording's name)")
    p.add_argument("--time", type=SECONDS, help="cursor time in seconds")
    p.set_defaults(func=cmd_gui)
