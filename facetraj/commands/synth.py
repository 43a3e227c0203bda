"""``facetraj synth``: face point trajectories from speech files (paper 2.3), one file or a
batch (:mod:`facetraj.batch`)."""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

from ..options import add_synth_options, integer, synth_config
from .align import add_label_provenance_option, add_label_source_options, extra_dictionary

log = logging.getLogger("facetraj")


def _job(args: argparse.Namespace):
    from facetraj_engine.method.modes import TUNED_FIELDS
    from facetraj_engine.method.recording import LabelRequest

    from ..batch import SynthJob

    request = LabelRequest(labels=args.labels, text=args.text, transcript=args.transcript,
                           recognize=args.recognize, declared=args.label_provenance,
                           label_map=args.label_map, extra_dict=extra_dictionary(args))
    return SynthJob(synth_config(args), request, explicit=args.mode is not None,
                    keep=tuple(f for f in TUNED_FIELDS if getattr(args, f, None) is not None),
                    overwrite=args.overwrite, compress=args.compress)


def cmd_synth(args: argparse.Namespace) -> int:
    from ..batch import is_batch

    if is_batch(args.inputs, args.output):
        return _cmd_batch(args)
    from facetraj_engine.io.files import check_output_path
    from facetraj_engine.method.model import Model
    from facetraj_engine.method.recording import EarlyLsf

    from ..batch import choose_kernels, synthesize_file

    check_output_path(args.output, args.overwrite)       # before the work, not after
    source = Path(args.inputs[0])
    job = choose_kernels(_job(args), [source])
    early, samples = EarlyLsf.start(args.model, source, job.kernels)   # beside what follows
    model = Model.load(args.model)
    res = synthesize_file(model, source, args.output, job, samples, early).synthesis
    log.info("%d frames (%.2f s) synthesized, %s smoothing", len(res.times), res.times[-1],
             res.config.smoothing)
    print(args.output)
    return 0


def _cmd_batch(args: argparse.Namespace) -> int:
    from facetraj_engine.errors import InputError

    from .. import batch
    from ..progress import TerminalProgress

    for name in ("labels", "text", "transcript"):
        if getattr(args, name) is not None:
            raise InputError(None, f"--{name} names the labels of one recording: for a batch, put "
                                   "each recording's labels or .txt beside it (same name), or "
                                   "use --recognize")
    fmt = args.format or "c3d"
    jobs = args.jobs or batch.default_jobs()
    t0 = time.perf_counter()
    outcomes = batch.run_batch(args.model, args.inputs, args.output, fmt, _job(args), jobs,
                               TerminalProgress("synth"))
    settings = {"model": str(args.model), "format": fmt, "jobs": jobs,
                "overwrite": args.overwrite, "config": synth_config(args).to_dict()}
    summary = batch.write_summary(args.output, outcomes, settings, time.perf_counter() - t0)
    lines = batch.summary_lines(outcomes)
    print(lines[0] + f"; summary: {summary}")
    for line in lines[1:]:
        print(f"facetraj: {line}", file=sys.stderr)
    return 2 if any(o.status == "failed" for o in outcomes) else 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("synth", help="synthesize face points from speech (one file or a batch)",
                       description="One recording to one file (-o face.c3d), or many to a "
                                   "folder (-o OUTDIR): files, folders, globs or list files "
                                   "(.lst/.list/.txt, one path a line), each named after its "
                                   "input, in -j processes; existing outputs are skipped "
                                   "unless --overwrite, and a summary is written beside them "
                                   "(synth-summary.json). Exit status 2 when any input failed.")
    p.add_argument("model", type=Path)
    p.add_argument("inputs", nargs="+", metavar="INPUT",
                   help="WAV or FLAC files, folders of them, globs, or list files")
    p.add_argument("--labels", type=Path, help="phone labels: .TextGrid, .lab or .phn (default: "
                   "one beside the audio, else the sentence of a .txt beside it, aligned, else "
                   "the phones recognized; --mode acoustic: none)")
    add_label_source_options(p)
    p.add_argument("--label-map", metavar="FILE|ALPHABET",
                   help="map the labels onto ARPAbet with this label map (TSV: label<TAB>arpabet) "
                        "or alphabet (mocha, timit, sampa, x-sampa, ipa); without it a label "
                        "file's alphabet is recognised (docs/labels.md)")
    add_label_provenance_option(p)
    p.add_argument("-o", "--output", type=Path, required=True,
                   help="one input: .c3d, .tsv, .csv or .npz; several: the output folder")
    p.add_argument("--format", choices=["c3d", "tsv", "csv", "npz"],
                   help="the outputs' format in a batch (default c3d)")
    p.add_argument("-j", "--jobs", type=integer(1, 256),
                   help="worker processes in a batch (default: the cores)")
    p.add_argument("--overwrite", action="store_true", help="replace existing outputs")
    p.add_argument("--compress", action="store_true",
                   help=".npz: deflate it (17%% smaller, 40 times slower to write)")
    add_synth_options(p)
    p.set_defaults(func=cmd_synth)
