"""``facetraj corpus build|init|show|align``: the default corpus, describing one's own
recordings, and labelling them by forced alignment of their transcripts."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from facetraj_engine.errors import FacetrajError

from ..corpus_work import add_corpus_work_options, finish, jobs, skips
from ..options import FRACTION, RATE, integer
from ..progress import TerminalProgress
from .align import add_label_provenance_option

log = logging.getLogger("facetraj")


def cmd_corpus_build(args: argparse.Namespace) -> int:
    try:
        from facetraj_engine.corpusgen.build import build_corpus
    except ImportError as exc:
        raise FacetrajError(f"the corpus generator is not available ({exc}); "
                            "install it with: pip install -e '.[corpus]'") from exc
    kw = {"progress": TerminalProgress("corpus")}
    if args.sentences is not None:
        kw["n_sentences"] = args.sentences
    if args.seed is not None:
        kw["seed"] = args.seed
    build_corpus(args.output, workers=jobs(args), **kw)
    print(args.output)
    return 0


def cmd_corpus_init(args: argparse.Namespace) -> int:
    from facetraj_engine.io.corpus import init_corpus, label_kinds, load_corpus

    out, info = init_corpus(args.data_dir, args.output, args.fixed, args.upper_lip,
                            args.lower_lip, args.lip_corners, args.label_map or "", args.rate,
                            args.test, args.test_fraction, args.name or "",
                            overwrite=args.overwrite,
                            label_provenance=args.label_provenance or "",
                            channel_names=args.channel_names, head_corrected=args.head_corrected)
    log.info("%d train and %d test utterances, %d markers (%d-D): %s", len(info.train),
             len(info.test), len(info.marker_names), info.dimensions, " ".join(info.marker_names))
    corpus = load_corpus(out)
    kinds = label_kinds(corpus)
    log.info("labels: %s%s", ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())),
             "" if set(kinds) <= {"hand-checked"} else
             " (train tunes the robust mode for them; synth and eval use it)")
    from .train import log_label_census

    log_label_census(corpus)
    print(out)
    return 0


def cmd_corpus_show(args: argparse.Namespace) -> int:
    from facetraj_engine.io.corpus import load_corpus

    corpus = load_corpus(args.corpus)
    info = corpus.info
    print(f"{info.name or corpus.root.name}: {len(info.train)} train, {len(info.test)} test, "
          f"{len(info.marker_names)} markers at {info.marker_rate:g} Hz ({info.dimensions}-D)")
    fixed = " ".join(info.fixed_markers) or "none"
    print(f"fixed: {fixed}{' (head-corrected data)' if info.head_corrected else ''}; "
          f"lips: {info.upper_lip} / {info.lower_lip}")
    from facetraj_engine.fanout import fan_out

    skipped = skips(args)
    for split in ("train", "test"):
        for utt_id, utt in fan_out(corpus.utterance, getattr(info, split), skip=skipped):
            print(f"{split:<5} {utt_id:<12} {utt.duration:6.2f} s {len(utt.phones):4d} phones  "
                  f"{utt.text}")
    return finish(skipped)


def cmd_corpus_align(args: argparse.Namespace) -> int:
    from facetraj_engine.io.labelling import label_folder

    from .align import extra_dictionary

    folder = args.folder
    if folder.is_file() or (folder / "corpus.json").is_file():
        from facetraj_engine.io.corpus import load_corpus

        folder = load_corpus(folder).data_root
    skipped = skips(args, "recordings")
    done = label_folder(folder, "recognized" if args.recognize else "aligned",
                        extra_dictionary(args), args.overwrite, TerminalProgress("align"),
                        workers=jobs(args), skip=skipped)
    log.info("%s", done.summary())
    print(folder)
    if skipped and not (done.written or done.kept):
        raise FacetrajError(f"{folder}: no recording could be labelled ({skipped.summary()})")
    return finish(skipped)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("corpus", help="the default corpus: build it; describe your own folder")
    csub = p.add_subparsers(dest="corpus_command", metavar="ACTION", required=True)
    b = csub.add_parser("build", help="synthesize the default corpus into a folder")
    b.add_argument("output", type=Path)
    b.add_argument("--sentences", type=integer(1, 100000), help="number of sentences")
    b.add_argument("--seed", type=int, help="random seed")
    b.add_argument("--jobs", "-j", type=integer(1, 256), metavar="N",
                   help="sentences synthesized in N processes (default: every core); the corpus "
                        "is the same bits whatever N")
    b.set_defaults(func=cmd_corpus_build)
    i = csub.add_parser("init", help="describe a folder of your own recordings as a corpus")
    i.add_argument("data_dir", type=Path,
                   help="folder with <id>.wav|flac, labels and markers (any format facetraj reads: "
                        "C3D, TSV/CSV, MOCHA, EST, Carstens .pos, NDI Wave TSV, MVIEW .mat, XRMB "
                        ".txy; an MVIEW file may hold the audio and labels itself)")
    i.add_argument("-o", "--output", type=Path,
                   help="the description (default DATA_DIR/corpus.json; elsewhere for read-only data)")
    i.add_argument("--fixed", nargs="+", metavar="MARKER",
                   help="markers that move only with the head (3, or 2 for midsagittal data); "
                        "not needed for data already head-corrected")
    i.add_argument("--head-corrected", action="store_true",
                   help="the data is already corrected for head motion (MVIEW, XRMB and AG501 "
                        "files with a head normalisation say so themselves)")
    i.add_argument("--channel-names", nargs="+", metavar="NAME",
                   help="name the files' channels: OLD=NEW pairs (NEW '-' leaves a channel out), "
                        "or one name per channel in file order (default: channel-names.txt in "
                        "the folder, else the files' own names, Ch1, Ch2, ... where they have none)")
    i.add_argument("--upper-lip", required=True, metavar="MARKER")
    i.add_argument("--lower-lip", required=True, metavar="MARKER")
    i.add_argument("--lip-corners", nargs=2, metavar=("RIGHT", "LEFT"))
    i.add_argument("--label-map", help="'mocha' or a label map file (label<TAB>arpabet)")
    add_label_provenance_option(i)
    i.add_argument("--rate", type=RATE, default=60.0, help="marker rate to resample to (60 Hz)")
    i.add_argument("--test", nargs="+", metavar="ID", help="test utterances")
    i.add_argument("--test-fraction", type=FRACTION,
                   help="the share of the recordings in the test split (default: a third, and "
                        "at least one of two or more)")
    i.add_argument("--name")
    i.add_argument("--overwrite", action="store_true", help="replace an existing description")
    i.set_defaults(func=cmd_corpus_init)
    sh = csub.add_parser("show", help="list a corpus's utterances")
    sh.add_argument("corpus", type=Path, help="corpus folder or description .json")
    add_corpus_work_options(sh, jobs=False)
    sh.set_defaults(func=cmd_corpus_show)
    a = csub.add_parser("align", help="phone labels (TextGrids) for every recording of a folder, "
                                      "aligned from its .txt transcripts")
    a.add_argument("folder", type=Path, help="folder of <id>.wav|flac and <id>.txt (or a corpus)")
    a.add_argument("--recognize", action="store_true",
                   help="recognize the phones of every utterance, ignoring transcripts")
    a.add_argument("--dict", type=Path, metavar="FILE",
                   help="extra pronunciations, CMUdict lines 'WORD  PH1 PH2 ...'")
    a.add_argument("--overwrite", action="store_true", help="replace existing TextGrids")
    add_corpus_work_options(a, "recordings")
    a.set_defaults(func=cmd_corpus_align)
