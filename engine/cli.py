"""The ``facetraj`` command.

``facetraj`` alone opens the app on the default corpus; subcommands train, synthesize, evaluate,
sweep N, print the similarity table and build the default corpus. Bad input gives a one-line
message naming the file and the problem, and exit status 2.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from .config import SynthConfig, TrainConfig
from .errors import FacetrajError

log = logging.getLogger("facetraj")

EXIT_BAD_INPUT = 2


def default_corpus() -> Path:
    """The default corpus: ``$FACETRAJ_CORPUS`` or the project's ``data_samples/``."""
    env = os.environ.get("FACETRAJ_CORPUS")
    if env:
        return Path(env)
    return Path(__file__).resolve().parent.parent / "data_samples"


class TerminalProgress:
    """A one-line progress bar on stderr when it is a terminal (silent otherwise)."""

    def __init__(self, label: str, stream=None):
        self.label = label
        self.stream = stream or sys.stderr
        self.live = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last = -1

    def __call__(self, fraction: float, message: str) -> None:
        pct = int(100 * fraction)
        if not self.live or pct == self._last:
            return
        self._last = pct
        bar = "#" * (pct // 4)
        self.stream.write(f"\r{self.label} [{bar:<25}] {pct:3d}% {message[:40]:<40}")
        if fraction >= 1.0:
            self.stream.write("\n")
        self.stream.flush()


# ---------------------------------------------------------------------- commands
def _train_config(args: argparse.Namespace) -> TrainConfig:
    kw = {}
    for name in ("lpc_order", "context", "nu", "codewords_per_phone", "placement",
                 "distance_scale", "max_gap_s", "variance_target", "index_cells"):
        val = getattr(args, name, None)
        if val is not None:
            kw[name] = val
    if args.pcs is not None:
        kw["n_components"] = None if args.pcs == 0 else args.pcs
    return TrainConfig(**kw)


def _synth_config(args: argparse.Namespace) -> SynthConfig:
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


def cmd_train(args: argparse.Namespace) -> int:
    from .corpus import load_corpus
    from .model import train

    corpus = load_corpus(args.corpus)
    model = train(corpus, config=_train_config(args), progress=TerminalProgress("train"))
    out = model.save(args.output, overwrite=args.overwrite)
    cb = model.codebook
    log.info("trained on %d utterances: %d context-phones, %d codewords, %d PCs (%.2f %% of "
             "variance), %d phones", len(model.train_utterances), cb.n_contexts, len(cb.lsf),
             model.pca.n_components, 100 * model.pca.explained_ratio.sum(), len(model.phones))
    print(out)
    return 0


def cmd_synth(args: argparse.Namespace) -> int:
    from .formats import read_audio, read_labels
    from .model import Model, synthesize, write_trajectories

    model = Model.load(args.model)
    audio, rate = read_audio(args.audio)
    cfg = _synth_config(args)
    phones = None
    if args.labels:
        phones = read_labels(args.labels, rate)
    elif cfg.mode == "phonetic":
        log.info("no labels given: acoustic-only synthesis")
        cfg = cfg.with_(mode="acoustic")
    label_map = _read_label_map(args.label_map) if args.label_map else None
    res = synthesize(model, audio, rate, phones, cfg, label_map=label_map,
                     source=str(args.labels or args.audio))
    out = write_trajectories(args.output, res.markers, model, res, args.overwrite)
    log.info("%d frames (%.2f s) synthesized, %s mode, %s smoothing", len(res.times),
             res.times[-1], cfg.mode, cfg.smoothing)
    print(out)
    return 0


def _read_label_map(path: str) -> dict[str, str]:
    from .labelmap import read_label_map

    return read_label_map(path)


def cmd_eval(args: argparse.Namespace) -> int:
    from .corpus import load_corpus
    from .evaluation import evaluate, format_table2
    from .model import Model

    model = Model.load(args.model)
    corpus = load_corpus(args.corpus)
    splits = ("train", "test") if args.split == "all" else (args.split,)
    configs = [_synth_config(args)]
    if args.acoustic and configs[0].mode != "acoustic":
        configs.append(configs[0].with_(mode="acoustic"))
    res = evaluate(model, corpus, splits, configs, ("triangular", "spline"),
                   progress=TerminalProgress("eval"))
    print(json.dumps(res.to_json(), indent=2) if args.json else format_table2(res))
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    from .corpus import load_corpus
    from .evaluation import sweep_n
    from .model import Model

    model = Model.load(args.model)
    corpus = load_corpus(args.corpus)
    ns = list(range(1, args.max_n + 1))
    splits = ("train", "test") if args.split == "all" else (args.split,)
    res = sweep_n(model, corpus, ns, splits, progress=TerminalProgress("sweep"))
    curve = {sp: [res.mean(sp, "triangular", n=n)["whole_face"] for n in ns] for sp in splits}
    if args.json:
        print(json.dumps({"n": ns, "whole_face": curve, "table": res.table()}, indent=2))
    else:
        print(f"{'N':>3} " + " ".join(f"{sp:>8}" for sp in splits))
        for i, n in enumerate(ns):
            print(f"{n:>3} " + " ".join(f"{curve[sp][i]:>8.4f}" for sp in splits))
    return 0


def cmd_similarity(args: argparse.Namespace) -> int:
    from .model import Model
    from .similarity import format_table1, top_similar

    model = Model.load(args.model)
    s = model.similarity(args.nu)
    if args.csv:
        print("phone," + ",".join(model.phones))
        for p, row in zip(model.phones, s, strict=True):
            print(p + "," + ",".join(f"{v:.4f}" for v in row))
    else:
        print(format_table1(top_similar(s, model.phones, args.top)))
    return 0


def cmd_corpus_build(args: argparse.Namespace) -> int:
    try:
        from .corpusgen.build import build_corpus
    except ImportError as exc:
        raise FacetrajError(f"the corpus generator is not available ({exc}); "
                            "install it with: pip install -e '.[corpus]'") from exc
    kw = {"progress": TerminalProgress("corpus")}
    if args.sentences is not None:
        kw["n_sentences"] = args.sentences
    if args.seed is not None:
        kw["seed"] = args.seed
    build_corpus(args.output, **kw)
    print(args.output)
    return 0


def cmd_corpus_init(args: argparse.Namespace) -> int:
    from .corpus import init_corpus

    out, info = init_corpus(args.data_dir, args.output, args.fixed, args.upper_lip,
                            args.lower_lip, args.lip_corners, args.label_map or "", args.rate,
                            args.test, args.test_fraction, args.name or "")
    log.info("%d train and %d test utterances, %d markers (%d-D)", len(info.train),
             len(info.test), len(info.marker_names), info.dimensions)
    print(out)
    return 0


def cmd_corpus_show(args: argparse.Namespace) -> int:
    from .corpus import load_corpus

    corpus = load_corpus(args.corpus)
    info = corpus.info
    print(f"{info.name or corpus.root.name}: {len(info.train)} train, {len(info.test)} test, "
          f"{len(info.marker_names)} markers at {info.marker_rate:g} Hz ({info.dimensions}-D)")
    print(f"fixed: {' '.join(info.fixed_markers)}; lips: {info.upper_lip} / {info.lower_lip}")
    for split in ("train", "test"):
        for utt_id in getattr(info, split):
            utt = corpus.utterance(utt_id)
            print(f"{split:<5} {utt_id:<12} {utt.duration:6.2f} s {len(utt.phones):4d} phones  "
                  f"{utt.text}")
    return 0


def cmd_video(args: argparse.Namespace) -> int:
    from .model import Model, synthesize

    try:
        from app.video import VideoSettings, render_video
    except ImportError as exc:
        raise FacetrajError(f"video export needs the app's packages: {exc}") from exc
    model = Model.load(args.model)
    cfg = _synth_config(args)
    original = None
    title = ""
    if args.corpus:
        from .corpus import load_corpus

        if not args.utterance:
            raise FacetrajError("give --utterance ID with --corpus")
        utt = load_corpus(args.corpus).utterance(args.utterance)
        audio, rate, phones, n_frames = utt.audio, utt.sample_rate, utt.phones, utt.n_frames
        original = model.normalise_markers(utt.markers) if utt.markers is not None else None
        title, source = utt.text or utt.name, utt.name
    elif args.audio:
        from .formats import read_audio, read_labels

        audio, rate = read_audio(args.audio)
        phones = read_labels(args.labels, rate) if args.labels else None
        n_frames, source, title = None, str(args.labels or args.audio), args.audio.name
    else:
        raise FacetrajError("give an AUDIO file, or --corpus and --utterance")
    if phones is None and cfg.mode == "phonetic":
        cfg = cfg.with_(mode="acoustic")
    res = synthesize(model, audio, rate, phones, cfg, n_frames=n_frames, source=source)
    w, h = (int(v) for v in args.size.lower().split("x"))
    render_video(model, res, audio, rate, args.output, original=original,
                 settings=VideoSettings(w, h, args.fps), overwrite=args.overwrite,
                 progress=TerminalProgress("video"), title=title)
    print(args.output)
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    from .model import Model

    try:
        from app.report_figures import make_report
    except ImportError as exc:
        raise FacetrajError(f"the report's figures need matplotlib: {exc}") from exc
    model = Model.load(args.model) if args.model else None
    out = make_report(args.corpus, args.output, model=model, progress=TerminalProgress("report"),
                      ns=range(1, args.max_n + 1))
    print(out)
    return 0


def cmd_gui(args: argparse.Namespace) -> int:
    try:
        from app.main import run_app
    except ImportError as exc:
        raise FacetrajError(f"the app cannot start: {exc}") from exc
    return run_app(corpus=args.corpus, screenshot=args.screenshot, utterance=args.utterance,
                   time=args.time, model=getattr(args, "model", None))


# ---------------------------------------------------------------------- parser
def _add_train_options(p: argparse.ArgumentParser) -> None:
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


def _add_synth_options(p: argparse.ArgumentParser, nu: bool = True) -> None:
    g = p.add_argument_group("synthesis (paper 2.3)")
    g.add_argument("-N", "--n-context-phones", type=int, help="top-N context-phones (default 3)")
    g.add_argument("--xi", type=float, help="eq 4 constant (default 20)")
    if nu:
        g.add_argument("--nu", type=float, help="override eq 3's constant")
    g.add_argument("--synth-context", type=int, help="context C used in eq 4 (default 3)")
    g.add_argument("--mode", choices=["phonetic", "acoustic"], help="default phonetic")
    g.add_argument("--smoothing", choices=["triangular", "spline", "none"])
    g.add_argument("--acoustic-prefilter", type=_count_or_all, metavar="K|all",
                   help="acoustic mode: weight the K codewords nearest to each frame (default "
                        "128); 'all' weights the whole codebook, as the paper does (slow)")
    g.add_argument("--acoustic-probe", type=_count_or_all, metavar="P|all",
                   help="acoustic mode: find the K nearest in P cells of the model's LSF index "
                        "(default 8); 'all' compares every codeword (exact, slower)")


ALL = -1


def _count_or_all(text: str) -> int:
    """A positive count, or ``all`` (returned as :data:`ALL`)."""
    if text.strip().lower() == "all":
        return ALL
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive whole number or 'all', got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive whole number or 'all', got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="facetraj",
        description="Speech-driven 3-D face point trajectory synthesis (Arslan & Talkin). "
                    "Without a subcommand, opens the app on the default corpus.")
    parser.add_argument("-v", "--verbose", action="store_true", help="log details")
    parser.add_argument("-q", "--quiet", action="store_true", help="log only errors")
    parser.add_argument("--screenshot", metavar="OUT.png",
                        help="render the app window to a PNG and exit")
    parser.add_argument("--utterance", help="utterance shown first")
    parser.add_argument("--time", type=float, help="cursor time in seconds")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("gui", help="open the app")
    p.add_argument("corpus", nargs="?", type=Path, default=None, help="corpus folder")
    p.add_argument("--model", type=Path, help="a trained model (default: train and cache)")
    p.add_argument("--screenshot", metavar="OUT.png", help="render to a PNG and exit")
    p.add_argument("--utterance", help="utterance shown first")
    p.add_argument("--time", type=float, help="cursor time in seconds")
    p.set_defaults(func=cmd_gui)

    p = sub.add_parser("train", help="train a model on a corpus folder")
    p.add_argument("corpus", type=Path)
    p.add_argument("-o", "--output", type=Path, required=True, help="model file (.npz)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    _add_train_options(p)
    p.set_defaults(func=cmd_train)

    p = sub.add_parser("synth", help="synthesize face points from speech")
    p.add_argument("model", type=Path)
    p.add_argument("audio", type=Path, help="WAV or FLAC")
    p.add_argument("--labels", type=Path, help="phone labels: .TextGrid, .lab or .phn")
    p.add_argument("--label-map", help="a label map (TSV: label<TAB>arpabet)")
    p.add_argument("-o", "--output", type=Path, required=True, help=".c3d, .tsv, .csv or .npz")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    _add_synth_options(p)
    p.set_defaults(func=cmd_synth)

    p = sub.add_parser("eval", help="correlations on a corpus (Table 2)")
    p.add_argument("model", type=Path)
    p.add_argument("corpus", type=Path)
    p.add_argument("--split", choices=["train", "test", "all"], default="all")
    p.add_argument("--acoustic", action="store_true", help="add acoustic-only rows")
    p.add_argument("--json", action="store_true", help="JSON output with per-utterance scores")
    _add_synth_options(p)
    p.set_defaults(func=cmd_eval)

    p = sub.add_parser("sweep", help="correlation against N (Figure 5)")
    p.add_argument("model", type=Path)
    p.add_argument("corpus", type=Path)
    p.add_argument("--max-n", type=int, default=10)
    p.add_argument("--split", choices=["train", "test", "all"], default="all")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser("similarity", help="visual phoneme similarity (Table 1)")
    p.add_argument("model", type=Path)
    p.add_argument("--nu", type=float, help="eq 3 constant (default: the model's)")
    p.add_argument("--top", type=int, default=3)
    p.add_argument("--csv", action="store_true", help="the full K x K matrix as CSV")
    p.set_defaults(func=cmd_similarity)

    p = sub.add_parser("report", help="results report: Tables 1-2, Figures 4-5, baselines")
    p.add_argument("corpus", type=Path, nargs="?", default=None, help="corpus (default data_samples)")
    p.add_argument("-o", "--output", type=Path, default=Path("docs"),
                   help="folder of results.md, results.json and figures/ (default docs)")
    p.add_argument("--model", type=Path, help="a trained model (default: train on the corpus)")
    p.add_argument("--max-n", type=int, default=10, help="the N sweep runs 1..MAX_N")
    p.set_defaults(func=cmd_report)

    p = sub.add_parser("video", help="an MP4 of the face points and lip panels with the sound")
    p.add_argument("model", type=Path)
    p.add_argument("audio", type=Path, nargs="?", help="WAV or FLAC (or use --corpus)")
    p.add_argument("--labels", type=Path, help="phone labels for AUDIO")
    p.add_argument("--corpus", type=Path, help="take the utterance (and its original) from a corpus")
    p.add_argument("--utterance", help="utterance id in --corpus")
    p.add_argument("-o", "--output", type=Path, required=True, help="an .mp4 file")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    p.add_argument("--fps", type=float, default=30.0)
    p.add_argument("--size", default="1280x544", help="WIDTHxHEIGHT")
    _add_synth_options(p)
    p.set_defaults(func=cmd_video)

    p = sub.add_parser("corpus", help="the default corpus: build it; describe your own folder")
    csub = p.add_subparsers(dest="corpus_command", metavar="ACTION", required=True)
    b = csub.add_parser("build", help="synthesize the default corpus into a folder")
    b.add_argument("output", type=Path)
    b.add_argument("--sentences", type=int, help="number of sentences")
    b.add_argument("--seed", type=int, help="random seed")
    b.set_defaults(func=cmd_corpus_build)
    i = csub.add_parser("init", help="describe a folder of your own recordings as a corpus")
    i.add_argument("data_dir", type=Path, help="folder with <id>.wav|flac, labels, markers")
    i.add_argument("-o", "--output", type=Path,
                   help="the description (default DATA_DIR/corpus.json; elsewhere for read-only data)")
    i.add_argument("--fixed", nargs="+", required=True, metavar="MARKER",
                   help="markers that move only with the head (3, or 2 for midsagittal data)")
    i.add_argument("--upper-lip", required=True, metavar="MARKER")
    i.add_argument("--lower-lip", required=True, metavar="MARKER")
    i.add_argument("--lip-corners", nargs=2, metavar=("RIGHT", "LEFT"))
    i.add_argument("--label-map", help="'mocha' or a label map file (label<TAB>arpabet)")
    i.add_argument("--rate", type=float, default=60.0, help="marker rate to resample to (60 Hz)")
    i.add_argument("--test", nargs="+", metavar="ID", help="test utterances")
    i.add_argument("--test-fraction", type=float, default=1 / 3)
    i.add_argument("--name")
    i.set_defaults(func=cmd_corpus_init)
    sh = csub.add_parser("show", help="list a corpus's utterances")
    sh.add_argument("corpus", type=Path, help="corpus folder or description .json")
    sh.set_defaults(func=cmd_corpus_show)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    level = logging.DEBUG if args.verbose else logging.ERROR if args.quiet else logging.INFO
    logging.basicConfig(level=level, format="%(levelname)s: %(message)s")
    if args.command is None:
        args.corpus = default_corpus()
        args.func = cmd_gui
    elif args.command in ("gui", "report") and args.corpus is None:
        args.corpus = default_corpus()
    try:
        return args.func(args)
    except FacetrajError as exc:
        print(f"facetraj: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except FileExistsError as exc:
        print(f"facetraj: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
