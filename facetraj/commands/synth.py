"""``facetraj synth``: face point trajectories from a speech file (paper 2.3)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from ..options import add_synth_options, synth_config
from .align import add_label_provenance_option, add_label_source_options, extra_dictionary

log = logging.getLogger("facetraj")


def cmd_synth(args: argparse.Namespace) -> int:
    from engine.io.export import write_trajectories
    from engine.io.files import check_output_path
    from engine.method.model import Model
    from engine.method.modes import TUNED_FIELDS
    from engine.method.recording import LabelRequest, synthesize_recording

    check_output_path(args.output, args.overwrite)       # before the work, not after
    model = Model.load(args.model)
    request = LabelRequest(labels=args.labels, text=args.text, transcript=args.transcript,
                           recognize=args.recognize, declared=args.label_provenance,
                           label_map=args.label_map, extra_dict=extra_dictionary(args))
    done = synthesize_recording(model, args.audio, synth_config(args), request,
                                explicit=args.mode is not None,
                                keep=[f for f in TUNED_FIELDS if getattr(args, f, None) is not None])
    log.info("%s", done.describe())
    res = done.synthesis
    out = write_trajectories(args.output, res.markers, model.marker_rate, model.marker_names,
                             res.arrays(), args.overwrite)
    log.info("%d frames (%.2f s) synthesized, %s smoothing", len(res.times), res.times[-1],
             res.config.smoothing)
    print(out)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("synth", help="synthesize face points from speech")
    p.add_argument("model", type=Path)
    p.add_argument("audio", type=Path, help="WAV or FLAC")
    p.add_argument("--labels", type=Path, help="phone labels: .TextGrid, .lab or .phn (default: "
                   "one beside the audio, else the sentence of a .txt beside it, aligned, else "
                   "the phones recognized; --mode acoustic: none)")
    add_label_source_options(p)
    p.add_argument("--label-map", metavar="FILE|ALPHABET",
                   help="map the labels onto ARPAbet with this label map (TSV: label<TAB>arpabet) "
                        "or alphabet (mocha, timit, sampa, x-sampa, ipa); without it a label "
                        "file's alphabet is recognised (docs/labels.md)")
    add_label_provenance_option(p)
    p.add_argument("-o", "--output", type=Path, required=True, help=".c3d, .tsv, .csv or .npz")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    add_synth_options(p)
    p.set_defaults(func=cmd_synth)
