"""``facetraj video`` and ``facetraj report``: the headless renderers of ``app`` (a video of the
face with its sound; the results report with its figures)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from facetraj_engine.errors import FacetrajError

from ..app_modules import AppMissing, app_module
from ..corpus_work import add_corpus_work_options, finish, jobs, skips
from ..options import FPS, add_synth_options, integer, synth_config, video_size
from ..paths import default_corpus, shared_path
from ..progress import TerminalProgress
from .align import add_label_options, label_request

log = logging.getLogger("facetraj")


def cmd_video(args: argparse.Namespace) -> int:
    from facetraj_engine.io.files import check_output_path
    from facetraj_engine.method.model import Model

    video = app_module("video", "facetraj video")
    check_output_path(args.output, args.overwrite, (".mp4",), probe=True)   # before the work
    if not args.corpus and not args.audio:
        raise FacetrajError("give an AUDIO file, or --corpus and --utterance")
    model = Model.load(args.model)
    if args.corpus:
        res, audio, rate, phones, original, title = _corpus_synthesis(args, model)
    else:
        res, audio, rate, phones, original, title = _recording_synthesis(args, model)
    w, h = args.size
    video.render_video(model, res, audio, rate, args.output, original=original,
                       settings=video.VideoSettings(w, h, args.fps), overwrite=args.overwrite,
                       progress=TerminalProgress("video"), title=title, phones=phones)
    print(args.output)
    return 0


def _recording_synthesis(args: argparse.Namespace, model):
    """A recording's synthesis as ``synth`` makes it: its labels by the one rule (the options,
    else what lies beside it, else recognition), its mode by the mode rule."""
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.method.modes import TUNED_FIELDS
    from facetraj_engine.workflow.recording import synthesize_recording

    audio, rate = read_audio(args.audio, args.read_damaged_audio)
    done = synthesize_recording(model, args.audio, synth_config(args), label_request(args),
                                explicit=args.mode is not None, audio=(audio, rate),
                                keep=tuple(f for f in TUNED_FIELDS if getattr(args, f, None) is not None))
    log.info("%s", done.describe())
    phones = done.labels.phones if done.labels else None
    return done.synthesis, audio, rate, phones, None, args.audio.name


def _corpus_synthesis(args: argparse.Namespace, model):
    """A corpus utterance's synthesis (its labels those of the corpus), with its original."""
    from facetraj_engine.io.corpus import load_corpus
    from facetraj_engine.method.modes import choose_mode
    from facetraj_engine.method.pipeline import synthesize

    if not args.utterance:
        raise FacetrajError("give --utterance ID with --corpus")
    utt = load_corpus(args.corpus).utterance(args.utterance)
    choice = choose_mode(synth_config(args), utt.phones, utt.provenance,
                         explicit=args.mode is not None, tuned=model.tuned)
    log.info("%s: labels %s; %s", utt.name, utt.provenance.describe(), choice.describe())
    res = synthesize(model, utt.audio, utt.sample_rate, utt.phones, choice.config,
                     n_frames=utt.n_frames, source=utt.name, confidence=utt.confidence,
                     provenance=utt.provenance)
    original = model.normalise_markers(utt.markers) if utt.markers is not None else None
    return res, utt.audio, utt.sample_rate, utt.phones, original, utt.text or utt.name


def cmd_report(args: argparse.Namespace) -> int:
    from facetraj_engine.method.model import Model
    from facetraj_engine.report import write_report

    try:
        figures = app_module("report_figures", "the report's figures").make_figures
    except AppMissing as exc:
        log.warning("%s; results.md is written without its figures", exc)
        figures = None
    model = Model.load(args.model) if args.model else None
    if args.automatic_labels:
        from facetraj_engine.evaluation.label_eval import LABEL_EVAL_FILE, evaluate_labels, write_label_eval
        from facetraj_engine.io.corpus import load_corpus

        args.output.mkdir(parents=True, exist_ok=True)
        result = evaluate_labels(load_corpus(args.corpus or default_corpus()),
                                 progress=TerminalProgress("automatic labels"))
        write_label_eval(args.output / LABEL_EVAL_FILE, result)
    if args.second_voice:
        from facetraj_engine.evaluation.voice_eval import VOICE_EVAL_FILE, evaluate_voices, write_voice_eval
        from facetraj_engine.io.corpus import load_corpus

        args.output.mkdir(parents=True, exist_ok=True)
        voices = evaluate_voices(load_corpus(args.corpus or default_corpus()), model=model,
                                 progress=TerminalProgress("second voice"))
        write_voice_eval(args.output / VOICE_EVAL_FILE, voices)
    if args.closure:
        from facetraj_engine.evaluation.closure_eval import (
            ARCTIC_DIR,
            CLOSURE_EVAL_FILE,
            evaluate_closure,
            write_closure_eval,
        )
        from facetraj_engine.evaluation.closure_parts import MOCHA_DIR
        from facetraj_engine.io.corpus import load_corpus
        from facetraj_engine.method.training import train

        corpus = load_corpus(args.corpus or default_corpus())
        args.output.mkdir(parents=True, exist_ok=True)
        result = evaluate_closure(model or train(corpus), corpus, shared_path(ARCTIC_DIR),
                                  progress=TerminalProgress("closure"),
                                  mocha=shared_path(MOCHA_DIR), workers=jobs(args))
        write_closure_eval(args.output / CLOSURE_EVAL_FILE, result)
    skipped = skips(args)
    out = write_report(args.corpus, args.output, model=model, progress=TerminalProgress("report"),
                       ns=range(1, args.max_n + 1), figures=figures, workers=jobs(args), skip=skipped)
    print(out)
    return finish(skipped)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("report", help="results report: Tables 1-2, Figures 4-5, baselines")
    p.add_argument("corpus", type=Path, nargs="?", default=None, help="corpus (default data_samples)")
    p.add_argument("-o", "--output", type=Path, default=Path("docs"),
                   help="folder of results.md, results.json and figures/ (default docs)")
    p.add_argument("--model", type=Path, help="a trained model (default: train on the corpus)")
    p.add_argument("--max-n", type=integer(1, 100), default=10, help="the N sweep runs 1..MAX_N")
    p.add_argument("--automatic-labels", action="store_true",
                   help="also evaluate every mode with aligned and recognized labels (trains and "
                        "cross-validates three models: about half an hour), saved as "
                        "label_eval.json beside results.md and reported from it")
    p.add_argument("--second-voice", action="store_true",
                   help="also evaluate acoustic-only synthesis from a second voice made from the "
                        "test sentences (shorter vocal tract, higher pitch), with and without "
                        "speaker normalisation (about 8 minutes), saved as voice_eval.json beside "
                        "results.md and reported from it")
    p.add_argument("--closure", action="store_true",
                   help="also measure how the lips close at /p b m/ in every mode, on the held-out "
                        "sentences and on real voices (../shared/data/arctic_samples when present; "
                        "a few minutes), saved as closure_eval.json beside results.md")
    add_corpus_work_options(p)
    p.set_defaults(func=cmd_report)

    p = sub.add_parser("video", help="an MP4 of the face points and lip panels with the sound")
    p.add_argument("model", type=Path)
    p.add_argument("audio", type=Path, nargs="?", help="WAV or FLAC (or use --corpus); its labels "
                   "as synth finds them")
    add_label_options(p)
    p.add_argument("--corpus", type=Path, help="take the utterance (and its original) from a corpus")
    p.add_argument("--utterance", help="utterance id in --corpus")
    p.add_argument("-o", "--output", type=Path, required=True, help="an .mp4 file")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    p.add_argument("--fps", type=FPS, default=30.0)
    p.add_argument("--size", type=video_size, default=(1280, 544),
                   help="WIDTHxHEIGHT (16 to 7680 pixels each)")
    add_synth_options(p)
    p.set_defaults(func=cmd_video)
