"""The training and synthesis options shared by several subcommands, the range-checked option
types every subcommand uses, and the configurations (:class:`~facetraj_engine.config.TrainConfig`,
:class:`~facetraj_engine.config.SynthConfig`) built from them.

A value out of range is refused by argparse with the valid range (exit status 2), e.g.
``argument -N/--n-context-phones: expected a whole number from 1 to 1000, got '0'``.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from facetraj_engine.config import SynthConfig, TrainConfig
from facetraj_engine.method.modes import MODES

ALL = -1


def _fmt(x: float) -> str:
    return f"{x:g}"


def integer(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: a whole number in ``[lo, hi]``.

    >>> integer(1, 10)("3")
    3
    >>> integer(1, 10)("0")
    Traceback (most recent call last):
    argparse.ArgumentTypeError: expected a whole number from 1 to 10, got '0'
    """
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"expected a whole number from {lo} to {hi}, "
                                             f"got {text!r}")
        return value
    parse.__name__ = f"integer({lo}..{hi})"
    return parse


def real(lo: float, hi: float, lo_open: bool = False, hi_open: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number in the interval from ``lo`` to ``hi`` (each end open or
    closed).

    >>> real(0, 1, lo_open=True)("0.5")
    0.5
    >>> real(0, 1, lo_open=True)("nan")
    Traceback (most recent call last):
    argparse.ArgumentTypeError: expected a number in (0, 1], got 'nan'
    """
    interval = f"{'(' if lo_open else '['}{_fmt(lo)}, {_fmt(hi)}{')' if hi_open else ']'}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        ok = (math.isfinite(value) and (value > lo if lo_open else value >= lo)
              and (value < hi if hi_open else value <= hi))
        if not ok:
            raise argparse.ArgumentTypeError(f"expected a number in {interval}, got {text!r}")
        return value
    parse.__name__ = f"number{interval}"
    return parse


def count_or_all(text: str) -> int:
    """A positive count, or ``all`` (returned as :data:`ALL`).

    >>> count_or_all("all"), count_or_all("12")
    (-1, 12)
    """
    if text.strip().lower() == "all":
        return ALL
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive whole number or 'all', got {text!r}") from None
    if not 1 <= value <= MAX_COUNT:
        raise argparse.ArgumentTypeError(f"expected a whole number from 1 to {MAX_COUNT} or 'all', "
                                         f"got {text!r}")
    return value


#: Largest count any option accepts (codewords, cells, top-N ...).
MAX_COUNT = 1_000_000
PCS = integer(0, 1000)
VARIANCE = real(0, 1, lo_open=True)
LPC_ORDER = integer(2, 64)
CONTEXT = integer(0, 10)
POSITIVE = real(0, 1e6, lo_open=True)
CODEWORDS = integer(1, 100)
MAX_GAP_S = real(0, 10)
CELLS = integer(1, MAX_COUNT)
TOP_N = integer(1, MAX_COUNT)
XI = real(1, 1e6)
FPS = real(1, 240)
SECONDS = real(0, 1e6)
RATE = real(1, 100000)
FRACTION = real(0, 1, hi_open=True)


def video_size(text: str) -> tuple[int, int]:
    """An argparse type: ``WIDTHxHEIGHT`` in pixels, each from 16 to 7680.

    >>> video_size("640x480")
    (640, 480)
    """
    parts = text.lower().split("x")
    try:
        w, h = (int(v) for v in parts)
    except ValueError:
        w = h = 0
    if not (16 <= w <= 7680 and 16 <= h <= 7680):
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, each from 16 to 7680 pixels, "
                                         f"got {text!r}")
    return w, h


def add_train_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("training (paper 2.1-2.2)")
    g.add_argument("--pcs", type=PCS, help="PCs kept (default 20; 0 = as many as reach "
                                           "--variance-target)")
    g.add_argument("--variance-target", type=VARIANCE, help="variance fraction (default 0.99)")
    g.add_argument("--lpc-order", type=LPC_ORDER, help="LPC order P (default 18)")
    g.add_argument("--context", type=CONTEXT, help="phones of context C each side (default 3)")
    g.add_argument("--nu", type=POSITIVE, help="eq 3 constant (default 10)")
    g.add_argument("--codewords-per-phone", type=CODEWORDS, help="codewords per phone (default 5)")
    g.add_argument("--placement", choices=["centres", "edges"], help="codeword placement")
    g.add_argument("--distance-scale", choices=["max", "median", "none"],
                   help="normalisation of D before eq 3 (default max)")
    g.add_argument("--max-gap-s", type=MAX_GAP_S, help="longest marker gap filled (default 0.1 s)")
    g.add_argument("--index-cells", type=CELLS,
                   help="cells of the LSF index for acoustic-only synthesis (default sqrt(5L))")


def add_synth_options(p: argparse.ArgumentParser, nu: bool = True) -> None:
    g = p.add_argument_group("synthesis (paper 2.3)")
    g.add_argument("-N", "--n-context-phones", type=TOP_N, help="top-N context-phones (default 3)")
    g.add_argument("--xi", type=XI, help="eq 4 constant (default 20)")
    if nu:
        g.add_argument("--nu", type=POSITIVE, help="override eq 3's constant")
    g.add_argument("--synth-context", type=CONTEXT, help="context C used in eq 4 (default 3)")
    g.add_argument("--mode", choices=list(MODES),
                   help="; ".join(f"{m.name}: {m.help}" for m in MODES.values()) +
                        " (default: chosen by the labels, docs/labels.md)")
    g.add_argument("--no-closure", dest="closure", action="store_false", default=None,
                   help="no closure step: the lips are not closed at /p b m/ nor the face rested "
                        "in pauses (the paper's synthesis as it is)")
    add_closure_part_options(g)
    g.add_argument("--smoothing", choices=["triangular", "spline", "none"])
    g.add_argument("--acoustic-prefilter", type=count_or_all, metavar="K|all",
                   help="acoustic mode: weight the K codewords nearest to each frame (default "
                        "128); 'all' weights the whole codebook, as the paper does (slow)")
    g.add_argument("--acoustic-probe", type=count_or_all, metavar="P|all",
                   help="acoustic mode: find the K nearest in P cells of the model's LSF index "
                        "(default 8); 'all' compares every codeword (exact, slower)")


#: The closure step's parts (``SynthConfig`` fields), each with its option and what it does; the
#: defaults are those of SynthConfig (docs/algorithm.md says why each is on or off).
CLOSURE_PARTS = (
    ("closure_labels", "--no-closure-labels", False,
     "do not close the lips at the labelled /p b m/"),
    ("rest", "--no-rest", False, "do not rest the face in pauses"),
    ("closure_detector", "--closure-detector", True,
     "without phone labels, close the lips where the model's bilabial-closure detector hears a "
     "closure (off by default: on the lips measured its closures lowered the correlation)"),
    ("closure_second_opinion", "--closure-second-opinion", True,
     "beside recognized phones, close the lips also where the detector hears a closure, trusted "
     "by the voice match (off by default: on real talkers' lips it lowered the correlation)"),
)


def add_closure_part_options(g, second_opinion: bool = True) -> None:
    """The options that turn each part of the closure step on or off (``CLOSURE_PARTS``; live
    mode has no second opinion: ``second_opinion=False``)."""
    for field, flag, value, text in CLOSURE_PARTS:
        if field != "closure_second_opinion" or second_opinion:
            g.add_argument(flag, dest=field, action="store_true" if value else "store_false",
                           default=None, help=text)


def train_config(args: argparse.Namespace) -> TrainConfig:
    """The training configuration the options ask for (defaults elsewhere)."""
    kw = {}
    for name in ("lpc_order", "context", "nu", "codewords_per_phone", "placement",
                 "distance_scale", "max_gap_s", "variance_target", "index_cells"):
        val = getattr(args, name, None)
        if val is not None:
            kw[name] = val
    if args.pcs is not None:
        kw["n_components"] = None if args.pcs == 0 else args.pcs
    return TrainConfig(**kw)


def synth_config(args: argparse.Namespace) -> SynthConfig:
    """The synthesis configuration the options ask for (defaults elsewhere)."""
    kw = {}
    for name in ("n_context_phones", "xi", "nu", "mode", "smoothing", "closure",
                 *(part[0] for part in CLOSURE_PARTS)):
        val = getattr(args, name, None)
        if val is not None:
            kw[name] = val
    for name in ("acoustic_prefilter", "acoustic_probe"):       # "all" is stored as ALL -> None
        val = getattr(args, name, None)
        if val is not None:
            kw[name] = None if val == ALL else val
    if getattr(args, "synth_context", None) is not None:
        kw["context"] = args.synth_context
    return SynthConfig(**kw)
