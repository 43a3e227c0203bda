"""``facetraj live``: the face follows a microphone, or a file played through the same streaming
path (``facetraj_engine.streaming.live``: phones recognized as they are spoken, the robust mode and the
closure step; ``--acoustic-only``: the paper's acoustic search alone).

* ``facetraj live``: the app's Live mode (input device, level meter, scrolling lip panels and
  phones).
* ``facetraj live --from-file speech.wav``: the same window, fed from the file in real time.
* ``facetraj live --from-file speech.wav [--as-fast-as-possible] -o take.tsv``: no window; the
  file goes through the streaming path (in real time, or as fast as it runs) and the take is
  written in any ``synth`` output format, with the recognized phones as ``take.TextGrid`` beside
  it (their provenance and confidence in its tiers).
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

import numpy as np

from facetraj_engine.errors import FacetrajError

from ..app_modules import app_module
from ..options import add_closure_part_options, count_or_all, real, synth_config
from ..paths import default_corpus
from .align import add_label_options, label_request

log = logging.getLogger("facetraj")

def load_model(args: argparse.Namespace):
    """The model of ``--model``, or the default corpus's (trained and cached on first use)."""
    from facetraj_engine.method.model import Model

    if args.model is not None:
        return Model.load(args.model)
    from facetraj_engine.io.corpus import load_corpus
    from facetraj_engine.workflow.model_cache import load_or_train

    return load_or_train(load_corpus(args.corpus or default_corpus()))


def live_config(args: argparse.Namespace):
    """The synthesis settings of a stream (its mode follows ``--acoustic-only``:
    :func:`facetraj_engine.streaming.live.live_mode`), ``--warp`` as the speaker warp."""
    cfg = synth_config(args)
    if args.smoothing == "spline":
        raise FacetrajError("live mode smooths with the triangular window or not at all "
                            "(--smoothing triangular or none)")
    if args.warp != 1.0 and not args.acoustic_only:
        raise FacetrajError("--warp applies to the acoustic-only search: add --acoustic-only "
                            "(with phones, the robust mode weighs the voice by its running match)")
    return cfg.with_(speaker_warp=args.warp)


def write_take(args: argparse.Namespace, model, audio: np.ndarray, rate: int, cfg) -> Path:
    """Stream ``--from-file`` and write the take to ``-o`` (its phones to a TextGrid beside it).
    Its labels come by the one rule, as ``synth``'s (``--labels``, ``--text``, a label file or
    ``.txt`` beside it); without any, its phones are recognized as they are spoken."""
    from facetraj_engine.io.export import write_trajectories
    from facetraj_engine.io.label_rule import FoundLabels, resolve_labels
    from facetraj_engine.io.labelling import write_labels
    from facetraj_engine.streaming.live import LiveConfig, stream_file
    from facetraj_engine.threads import one_blas_thread

    textgrid = args.output.with_suffix(".TextGrid")
    found = FoundLabels(None, "--acoustic-only: none asked for")
    if not args.acoustic_only:
        found = resolve_labels(args.from_file, audio, rate, label_request(args, fallback=False))
    with one_blas_thread():                             # small products: threads only cost
        take = stream_file(model, audio, rate, args.block_ms / 1000.0, cfg,
                           LiveConfig(phones=not args.acoustic_only),
                           real_time=not args.as_fast_as_possible, labels=found.labels)
    if len(take.frames) == 0:
        raise FacetrajError(f"{args.from_file}: the audio is too short to synthesize")
    out = write_trajectories(args.output, take.frames.markers, model.marker_rate,
                             model.marker_names, overwrite=args.overwrite,
                             audio=None if args.no_audio else (audio, rate))
    if take.labels is not None:                         # the phones the take was made with
        write_labels(textgrid, take.labels, len(audio) / rate, overwrite=args.overwrite)
    stream = take.stream
    where = found.describe() if found.labels is not None or args.acoustic_only else \
        f"recognized as they are spoken [{found.where}]"
    log.info("%s: labels %s; %s", args.from_file.name, where, stream.choice.describe())
    log.info("%d frames streamed in %.2f s (%.1f x real time)", len(take.frames), take.wall_s,
             len(audio) / rate / max(take.wall_s, 1e-9))
    if stream.recognizer is not None:
        log.info("phones settled in time for %.0f %% of the frames", 100 * stream.labelled_share)
    if stream.phonetic is not None:
        from facetraj_engine.method.voice_match import explain_match

        kind = found.labels.provenance.kind if found.labels is not None else "recognized"
        log.info("%s", explain_match(stream.voice_ratio, stream.choice.config, kind))
    return out


def cmd_live(args: argparse.Namespace) -> int:
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.io.export import TRAJECTORY_SUFFIXES
    from facetraj_engine.io.files import check_output_path

    cfg = live_config(args)
    if args.output is not None:
        if args.from_file is None:
            raise FacetrajError("-o writes a take played from a file: add --from-file FILE "
                                "(a microphone take is saved from the Live window)")
        check_output_path(args.output, args.overwrite, TRAJECTORY_SUFFIXES, probe=True)
        if not args.acoustic_only:                       # the take's phones' TextGrid
            check_output_path(args.output.with_suffix(".TextGrid"), args.overwrite)
        audio, rate = read_audio(args.from_file, args.read_damaged_audio)
        print(write_take(args, load_model(args), audio, rate, cfg))
        return 0
    run_live = app_module("live", "the Live window (facetraj live without -o)").run_live
    return run_live(model_loader=lambda: load_model(args), config=cfg, from_file=args.from_file,
                    block_s=args.block_ms / 1000.0, fast=args.as_fast_as_possible,
                    device=args.device, screenshot=args.screenshot, quit_after=args.quit_after,
                    phones=not args.acoustic_only)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("live", help="the face follows a microphone (or a file) in real time")
    p.add_argument("--from-file", type=Path, metavar="AUDIO",
                   help="play a WAV/FLAC file through the streaming path instead of a microphone")
    p.add_argument("--as-fast-as-possible", action="store_true",
                   help="with --from-file: do not wait for the audio clock (benchmarks)")
    p.add_argument("-o", "--output", type=Path,
                   help="with --from-file: no window; write the take (.c3d, .tsv, .csv or .npz)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    p.add_argument("--no-audio", action="store_true",
                   help="-o .c3d: leave the speech out (by default the C3D's analog channel)")
    g = p.add_argument_group("labels of --from-file -o (as synth finds them; without any, the "
                             "phones are recognized as they are spoken)")
    add_label_options(g)
    p.add_argument("--model", type=Path, help="a trained model (default: the default corpus's)")
    p.add_argument("--corpus", type=Path, help="train on this corpus when no --model is given")
    p.add_argument("--device", help="input device (part of its name; default: the system's)")
    p.add_argument("--block-ms", type=real(0.0625, 10000), default=10.0,
                   help="audio block size in ms (default 10)")
    p.add_argument("--acoustic-only", action="store_true",
                   help="the paper's acoustic search without recognizing the phones (lower "
                        "latency); the face rests in pauses, and with --closure-detector the "
                        "lips close where the model's bilabial-closure detector hears a closure")
    p.add_argument("--warp", type=real(0.5, 2.0), default=1.0, metavar="ALPHA",
                   help="with --acoustic-only: speaker warp of the input LSFs "
                        "(facetraj_engine.method.speaker; "
                        "1 = none, below 1 for a shorter vocal tract than the training voice)")
    p.add_argument("--screenshot", metavar="OUT.png", help=argparse.SUPPRESS)
    p.add_argument("--quit-after", type=real(0, 1e6, lo_open=True), metavar="S",
                   help=argparse.SUPPRESS)
    g = p.add_argument_group("synthesis (paper 2.3)")
    g.add_argument("--no-closure", dest="closure", action="store_false", default=None,
                   help="no closure step: the lips are not closed (at the recognized /p b m/, or "
                        "acoustic-only where the model's detector finds a closure) nor the face "
                        "rested in pauses")
    add_closure_part_options(g, second_opinion=False)
    g.add_argument("--smoothing", choices=["triangular", "none"])
    g.add_argument("--acoustic-prefilter", type=count_or_all, metavar="K|all",
                   help="weight the K codewords nearest to each frame (default 128)")
    g.add_argument("--acoustic-probe", type=count_or_all, metavar="P|all",
                   help="find them in P cells of the model's LSF index (default 8)")
    p.set_defaults(func=cmd_live)

