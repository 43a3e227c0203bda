"""The training and synthesis options shared by several subcommands, and the configurations
(:class:`~engine.config.TrainConfig`, :class:`~engine.config.SynthConfig`) built from them."""

from __future__ import annotations

import argparse

from engine.config import SynthConfig, TrainConfig

ALL = -1


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
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive whole number or 'all', got {text!r}")
    return value


def add_train_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("training (paper 2.1-2.2)")
    g.add_argument("--pcs", type=int, help="PCs kept (default 20; 0 = as many as reach "
                                           "--variance-target)")
    g.add_argument("--variance-target", type=float, help="variance fraction (default 0.99)")
    g.add_argument("--lpc-order", type=int, help="LPC order P (default 18)")
    g.add_argument("--context", type=int, help="phones of context C each side (default 3)")
    g.add_argument("--nu", type=float, help="eq 3 constant (default 10)")
    g.add_argument("--codewords-per-phone", type=int, help="codewords per phone (default 5)")
    g.add_argument("--placement", choices=["centres", "edges"], help="codeword placement")
    g.add_argument("--distance-scale", choices=["max", "median", "none"],
                   help="normalisation of D before eq 3 (default max)")
    g.add_argument("--max-gap-s", type=float, help="longest marker gap filled (default 0.1 s)")
    g.add_argument("--index-cells", type=int,
                   help="cells of the LSF index for acoustic-only synthesis (default sqrt(5L))")


def add_synth_options(p: argparse.ArgumentParser, nu: bool = True) -> None:
    g = p.add_argument_group("synthesis (paper 2.3)")
    g.add_argument("-N", "--n-context-phones", type=int, help="top-N context-phones (default 3)")
    g.add_argument("--xi", type=float, help="eq 4 constant (default 20)")
    if nu:
        g.add_argument("--nu", type=float, help="override eq 3's constant")
    g.add_argument("--synth-context", type=int, help="context C used in eq 4 (default 3)")
    g.add_argument("--mode", choices=["phonetic", "acoustic", "robust"],
                   help="phonetic: the paper's eq 4, labels trusted (default for label files); "
                        "robust: eq 4 and acoustic candidates weighted by label confidence "
                        "(default for aligned or recognized labels); acoustic: no labels")
    g.add_argument("--smoothing", choices=["triangular", "spline", "none"])
    g.add_argument("--acoustic-prefilter", type=count_or_all, metavar="K|all",
                   help="acoustic mode: weight the K codewords nearest to each frame (default "
                        "128); 'all' weights the whole codebook, as the paper does (slow)")
    g.add_argument("--acoustic-probe", type=count_or_all, metavar="P|all",
                   help="acoustic mode: find the K nearest in P cells of the model's LSF index "
                        "(default 8); 'all' compares every codeword (exact, slower)")


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
    for name in ("n_context_phones", "xi", "nu", "mode", "smoothing"):
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
