"""``facetraj gui`` (and ``facetraj`` alone): the desktop app."""

from __future__ import annotations

import argparse
from pathlib import Path

from facetraj_engine.errors import FacetrajError

from ..options import SECONDS
from ..paths import default_corpus


def cmd_gui(args: argparse.Namespace) -> int:
    try:
        from facetraj_app.main import run_app
        from facetraj_app.recordings import recordings_in
    except ImportError as exc:
        raise FacetrajError(f"the app cannot start: {exc}") from exc
    recordings = recordings_in(args.corpus) if args.corpus is not None else []
    corpus = default_corpus() if recordings else args.corpus
    return run_app(corpus=corpus, screenshot=args.screenshot, utterance=args.utterance,
                   time=args.time, model=getattr(args, "model", None), recordings=recordings)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("gui", help="open the app")
    p.add_argument("corpus", nargs="?", type=Path, default=None,
                   help="a corpus folder, or a recording (.wav, .flac) or folder of recordings "
                        "without face data to synthesize with the model (--model, else the "
                        "default corpus's)")
    p.add_argument("--model", type=Path, help="a trained model (default: train and cache)")
    p.add_argument("--screenshot", metavar="OUT.png", help="render to a PNG and exit")
    p.add_argument("--utterance", help="utterance shown first")
    p.add_argument("--time", type=SECONDS, help="cursor time in seconds")
    p.set_defaults(func=cmd_gui)
