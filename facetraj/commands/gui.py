"""``facetraj gui`` (and ``facetraj`` alone): the desktop app."""

from __future__ import annotations

import argparse
from pathlib import Path

from engine.errors import FacetrajError

from ..options import SECONDS


def cmd_gui(args: argparse.Namespace) -> int:
    try:
        from app.main import run_app
    except ImportError as exc:
        raise FacetrajError(f"the app cannot start: {exc}") from exc
    return run_app(corpus=args.corpus, screenshot=args.screenshot, utterance=args.utterance,
                   time=args.time, model=getattr(args, "model", None))


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("gui", help="open the app")
    p.add_argument("corpus", nargs="?", type=Path, default=None, help="corpus folder")
    p.add_argument("--model", type=Path, help="a trained model (default: train and cache)")
    p.add_argument("--screenshot", metavar="OUT.png", help="render to a PNG and exit")
    p.add_argument("--utterance", help="utterance shown first")
    p.add_argument("--time", type=SECONDS, help="cursor time in seconds")
    p.set_defaults(func=cmd_gui)
