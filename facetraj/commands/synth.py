"""``facetraj synth``: face point trajectories from a speech file (paper 2.3)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from ..options import add_synth_options, synth_config
from .align import add_label_source_options, extra_dictionary

log = logging.getLogger("facetraj")


def cmd_synth(args: argparse.Namespace) -> int:
    from engine.evaluation.tuning import TUNED_FIELDS, tuned_config
    from engine.io.audio import read_audio
    from engine.io.export import write_trajectories
    from engine.io.labelling import labels_for_audio
    from engine.labels.labelmap import read_label_map
    from engine.method.model import Model
    from engine.method.pipeline import check_length, mode_for, synthesize

    model = Model.load(args.model)
    audio, rate = read_audio(args.audio)
    cfg = synth_config(args)
    check_length(model, len(audio), rate, str(args.audio))  # before the labels are checked
    labels = None
    if cfg.mode in ("phonetic", "robust"):
        labels = labels_for_audio(args.audio, audio, rate, labels=args.labels, text=args.text,
                                  transcript=args.transcript, recognize=args.recognize,
                                  extra_dict=extra_dictionary(args),
                                  detect_alphabet=not args.label_map)
    phones = labels.phones if labels else None
    cfg = tuned_config(mode_for(cfg, phones, labels.source if labels else None,
                                explicit=args.mode == "phonetic"), model.tuned,
                       keep=[f for f in TUNED_FIELDS if getattr(args, f, None) is not None])
    confidence = labels.confidence if labels and labels.source != "file" else None
    label_map = read_label_map(args.label_map) if args.label_map and labels and \
        labels.source == "file" else None
    res = synthesize(model, audio, rate, phones, cfg, label_map=label_map,
                     source=str(args.labels or args.audio), audio_source=str(args.audio),
                     confidence=confidence)
    out = write_trajectories(args.output, res.markers, model.marker_rate, model.marker_names,
                             res.arrays(), args.overwrite)
    log.info("%d frames (%.2f s) synthesized, %s mode (labels: %s), %s smoothing", len(res.times),
             res.times[-1], cfg.mode, labels.source if labels else "none", cfg.smoothing)
    print(out)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("synth", help="synthesize face points from speech")
    p.add_argument("model", type=Path)
    p.add_argument("audio", type=Path, help="WAV or FLAC")
    p.add_argument("--labels", type=Path, help="phone labels: .TextGrid, .lab or .phn (default: "
                   "one beside the audio, else the sentence of a .txt beside it, aligned)")
    add_label_source_options(p)
    p.add_argument("--label-map", metavar="FILE|ALPHABET",
                   help="map the labels onto ARPAbet with this label map (TSV: label<TAB>arpabet) "
                        "or alphabet (mocha, timit, sampa, x-sampa, ipa); without it a label "
                        "file's alphabet is recognised (docs/labels.md)")
    p.add_argument("-o", "--output", type=Path, required=True, help=".c3d, .tsv, .csv or .npz")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    add_synth_options(p)
    p.set_defaults(func=cmd_synth)
