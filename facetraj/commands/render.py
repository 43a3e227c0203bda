"""``facetraj video`` and ``facetraj report``: the headless renderers of ``app`` (a video of the
face with its sound; the results report with its figures)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from facetraj_engine.errors import FacetrajError

from ..corpus_work import add_corpus_work_options, finish, jobs, skips
from ..options import FPS, add_synth_options, integer, synth_config, video_size
from ..paths import default_corpus, shared_path
from ..progress import TerminalProgress

log = logging.getLogger("facetraj")


def cmd_video(args: argparse.Namespace) -> int:
    from facetraj_engine.method.model import Model
    from facetraj_engine.method.modes import choose_mode
    from facetraj_engine.method.pipeline import synthesize

    try:
        from facetraj_app.video import VideoSettings, render_video
    except ImportError as exc:
        raise FacetrajError(f"video export needs the app's packages: {exc}") from exc
    model = Model.load(args.model)
    original = None
    title = ""
    if args.corpus:
        from facetraj_engine.io.corpus import load_corpus

        if not args.utterance:
            raise FacetrajError("give --utterance ID with --corpus")
        utt = load_corpus(args.corpus).utterance(args.utterance)
        audio, rate, phones, n_frames = utt.audio, utt.sample_rate, utt.phones, utt.n_frames
        provenance, confidence = utt.provenance, utt.confidence
        original = model.normalise_markers(utt.markers) if utt.markers is not None else None
        title, source = utt.text or utt.name, utt.name
    elif args.audio:
        from facetraj_engine.io.audio import read_audio
        from facetraj_engine.io.labelfiles import read_label_file

        audio, rate = read_audio(args.audio)
        labels = read_label_file(args.labels, rate, len(audio) / rate) if args.labels else None
        phones = labels.phones if labels else None
        provenance, confidence = (labels.provenance, labels.trust()) if labels else (None, None)
        n_frames, source, title = None, str(args.labels or args.audio), args.audio.name
    else:
        raise FacetrajError("give an AUDIO file, or --corpus and --utterance")
    choice = choose_mode(synth_config(args), phones, provenance, explicit=args.mode is not None,
                         tuned=model.tuned)
    log.info("%s", choice.describe())
    res = synthesize(model, audio, rate, phones, choice.config, n_frames=n_frames, source=source,
                     audio_source=str(args.audio or source), confidence=confidence,
                     provenance=provenance)
    w, h = args.size
    render_video(model, res, audio, rate, args.output, original=original,
                 settings=VideoSettings(w, h, args.fps), overwrite=args.overwrite,
                 progress=TerminalProgress("video"), title=title, phones=phones)
    print(args.output)
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    from facetraj_engine.method.model import Model

    try:
        from facetraj_app.report_figures import make_report
    except ImportError as exc:
        raise FacetrajError(f"the report's figures need matplotlib: {exc}") from exc
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
        from facetraj_engine.io.corpus import load_corpus
        from facetraj_engine.method.training import train

        corpus = load_corpus(args.corpus or default_corpus())
        args.output.mkdir(parents=True, exist_ok=True)
        result = evaluate_closure(model or train(corpus), corpus, shared_path(ARCTIC_DIR),
                                  progress=TerminalProgress("closure"))
        write_closure_eval(args.output / CLOSURE_EVAL_FILE, result)
    skipped = skips(args)
    out = make_report(args.corpus, args.output, model=model, progress=TerminalProgress("report"),
                      ns=range(1, args.max_n + 1), workers=jobs(args), skip=skipped)
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
    p.add_argument("audio", type=Path, nargs="?", help="WAV or FLAC (or use --corpus)")
    p.add_argument("--labels", type=Path, help="phone labels for AUDIO")
    p.add_argument("--corpus", type=Path, help="take the utterance (and its original) from a corpus")
    p.add_argument("--utterance", help="utterance id in --corpus")
    p.add_argument("-o", "--output", type=Path, required=True, help="an .mp4 file")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    p.add_argument("--fps", type=FPS, default=30.0)
    p.add_argument("--size", type=video_size, default=(1280, 544),
                   help="WIDTHxHEIGHT (16 to 7680 pixels each)")
    add_synth_options(p)
    p.set_defaults(func=cmd_video)
