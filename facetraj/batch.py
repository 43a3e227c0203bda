"""``facetraj synth MODEL INPUTS... -o OUTDIR``: many recordings, one model (issue 28).

Every input goes through :func:`synthesize_file`, the one path of ``facetraj synth`` for a
recording (its labels and mode by the same rules as one file,
:func:`facetraj_engine.workflow.recording.synthesize_recording`), in ``jobs`` worker processes that each
hold the model (loaded once; forked workers share the parent's copy: :func:`facetraj_engine.fanout.fan_out`,
whose worker that dies fails the input it was on, and only that one). An input whose output
exists is skipped unless ``overwrite`` (outputs are written whole or not at all, so an interrupted
run resumes where it stopped); an input that fails is reported with its one-line reason and the
others go on. The summary (done / skipped / failed, with each reason) is printed, and written as
JSON beside the outputs (:data:`SUMMARY_NAME`).
"""

from __future__ import annotations

import glob
import logging
import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from facetraj_engine.errors import FacetrajError, InputError

log = logging.getLogger("facetraj")

#: the machine-readable summary, written in the output folder
SUMMARY_NAME = "synth-summary.json"
#: input files read as lists of inputs (one path a line, relative to the list's folder)
LIST_SUFFIXES = (".lst", ".list", ".txt")
FORMATS = ("c3d", "tsv", "csv", "npz")
_GLOB_CHARS = frozenset("*?[")


@dataclass(frozen=True)
class SynthJob:
    """What every input of a run shares: the synthesis settings and how outputs are written
    (``request``: :class:`~facetraj_engine.workflow.recording.LabelRequest`; ``explicit``, ``keep``,
    ``allow_damaged``: as :func:`~facetraj_engine.workflow.recording.synthesize_recording` takes
    them; ``c3d_audio``: a C3D output carries the speech as its analog channel)."""

    config: Any
    request: Any
    explicit: bool = False
    keep: tuple[str, ...] = ()
    overwrite: bool = False
    compress: bool = False
    allow_damaged: bool = False
    c3d_audio: bool = True


@dataclass
class Outcome:
    """One input's result: ``status`` done, skipped or failed, and why (``reason``)."""

    input: str
    output: str
    status: str
    reason: str = ""
    seconds: float = 0.0
    audio_s: float = 0.0
    details: dict[str, Any] = field(default_factory=dict)


# --------------------------------------------------------------------------- inputs and outputs
def is_batch(inputs: Sequence[str], output: Path) -> bool:
    """Whether the command line asks for a batch: several inputs, a folder, a glob or a list
    file, or an output that is a folder (exists as one, or has no suffix; a trajectory file's
    suffix makes it one file's output, refused there if a folder is in the way)."""
    if len(inputs) != 1:
        return True
    one = inputs[0]
    named_file = output.suffix.lower().lstrip(".") in (*FORMATS, "txt")
    return (_is_dir(Path(one)) or (bool(_GLOB_CHARS & set(one)) and not Path(one).exists()) or
            Path(one).suffix.lower() in LIST_SUFFIXES or not output.suffix or
            (not named_file and _is_dir(output)))


def _is_dir(path: Path) -> bool:
    """``path.is_dir()``, False where the system cannot tell (a name too long): the command then
    reports the path's problem as it does for one file."""
    try:
        return path.is_dir()
    except OSError:
        return False


def collect_inputs(specs: Iterable[str]) -> list[Path]:
    """The recordings named by ``specs``, in order, each once: files, folders (their
    ``.wav``/``.flac`` files, sorted), globs (``**`` for sub-folders; audio files only) and list
    files (:data:`LIST_SUFFIXES`: one input a line, ``#`` comments)."""
    from facetraj_engine.io.audio import AUDIO_SUFFIXES

    found: list[Path] = []
    for spec in specs:
        path = Path(spec)
        if path.is_dir():
            found += sorted(p for p in path.iterdir()
                            if p.is_file() and p.suffix.lower() in AUDIO_SUFFIXES)
        elif _GLOB_CHARS & set(spec) and not path.exists():
            matches = [Path(p) for p in sorted(glob.glob(spec, recursive=True))]
            audio = [p for p in matches if p.is_file() and p.suffix.lower() in AUDIO_SUFFIXES]
            if not audio:
                raise InputError(spec, "no .wav or .flac file matches")
            found += audio
        elif path.suffix.lower() in LIST_SUFFIXES:
            found += collect_inputs(_list_file(path))
        else:
            found.append(path)                   # a missing or bad file fails as that input
    return list(dict.fromkeys(found))


def _list_file(path: Path) -> list[str]:
    from facetraj_engine.io.files import read_text

    lines = (ln.split("#", 1)[0].strip() for ln in read_text(path, "list of inputs").splitlines())
    return [str(path.parent / ln) for ln in lines if ln]


def output_paths(inputs: Sequence[Path], outdir: Path, fmt: str) -> list[Path]:
    """Each input's output: ``OUTDIR/<its name>.<fmt>``; two inputs of one name are refused
    (their outputs would overwrite each other)."""
    outs = [outdir / f"{p.stem}.{fmt}" for p in inputs]
    seen: dict[Path, Path] = {}
    for src, out in zip(inputs, outs, strict=True):
        if out in seen:
            raise InputError(out, f"two inputs would both be written here: {seen[out]} and {src} "
                                  "(give them different names, or run them separately)")
        seen[out] = src
    return outs


# --------------------------------------------------------------------------- one input
def synthesize_file(model: Any, audio: Path, output: Path, job: SynthJob, say: bool = True,
                    progress: Callable[[float, str], None] | None = None) -> Any:
    """One recording to one trajectory file, as ``facetraj synth`` does for every input;
    returns the :class:`~facetraj_engine.workflow.recording.RecordingSynthesis` (logged unless
    ``say`` is off: a batch's parent logs each input's lines above its progress bar)."""
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.io.export import write_trajectories
    from facetraj_engine.workflow.recording import synthesize_recording

    sound = read_audio(audio, job.allow_damaged)
    done = synthesize_recording(model, audio, job.config, job.request, explicit=job.explicit,
                                keep=list(job.keep), audio=sound, progress=progress)
    if say:
        log.info("%s", done.describe())
    res = done.synthesis
    write_trajectories(output, res.markers, model.marker_rate, model.marker_names, res.arrays(),
                       job.overwrite, compress=job.compress,
                       audio=sound if job.c3d_audio else None)
    if output.suffix.lower() == ".c3d" and say:
        log.info("%s: %s", output.name, c3d_contents(job.c3d_audio))
    return done


def c3d_contents(audio: bool) -> str:
    """What a C3D output holds beside its points, and why (for the log)."""
    axes = "axes declared (POINT:X_SCREEN +X, Y_SCREEN +Y: upright in a viewer that honours them)"
    if not audio:
        return f"{axes}; no speech (--no-audio)"
    return (f"{axes}; the speech as analog channel SPEECH (by default: where motion-capture "
            "software keeps a recording's sound in sync with its points; --no-audio leaves it out)")


#: a worker's model and job (set before the workers fork: they inherit them)
_WORKER: dict[str, Any] = {}


def _worker_run(pair: tuple[Path, Path]) -> Outcome:
    """One input in a worker: every error comes back as its one-line reason (plain text, so
    that it crosses the process boundary whatever it holds)."""
    src, out = pair
    t0 = time.perf_counter()
    try:
        done = synthesize_file(_WORKER["model"], src, out, _WORKER["job"], say=False)
    except FacetrajError as exc:
        return Outcome(str(src), str(out), "failed", str(exc), time.perf_counter() - t0)
    except OSError as exc:
        from facetraj_engine.io.files import write_problem

        where = exc.filename or src
        return Outcome(str(src), str(out), "failed", f"{where}: {write_problem(exc)}",
                       time.perf_counter() - t0)
    except Exception as exc:                                # a bug: this input, not the batch
        log.debug("%s failed", src, exc_info=True)
        return Outcome(str(src), str(out), "failed",
                       f"{src}: unexpected error ({type(exc).__name__}: {exc})",
                       time.perf_counter() - t0)
    res = done.synthesis
    details = {"labels": done.found.describe(), "mode": done.choice.config.mode,
               "why": done.choice.describe(), "line": done.describe(),
               "voice_match": done.voice_match if math.isfinite(done.voice_match) else None,
               "frames": len(res.times)}
    return Outcome(str(src), str(out), "done", "", time.perf_counter() - t0,
                   float(res.times[-1]), details)


def import_synthesis() -> None:
    """Import what every input's synthesis imports (the audio reader, the label readers, the
    writers): paid once before a batch's workers fork, not in each worker (and the benchmarks'
    start-up)."""
    import soundfile  # noqa: F401

    import facetraj_engine.io.export
    import facetraj_engine.io.labelling
    import facetraj_engine.io.textgrid
    import facetraj_engine.workflow.recording  # noqa: F401


# --------------------------------------------------------------------------- the run
def run_batch(model_path: Path, specs: Sequence[str], outdir: Path, fmt: str, job: SynthJob,
              jobs: int, progress: Callable[[float, str], None] | None = None
              ) -> list[Outcome]:
    """Synthesize every input of ``specs`` into ``outdir`` (made when missing) with ``jobs``
    worker processes; the outcomes in input order. The model is loaded (and checked) here once
    before any worker starts."""
    from facetraj_engine.fanout import Skips, fan_out
    from facetraj_engine.method.model import Model

    inputs = collect_inputs(specs)
    if not inputs:
        raise InputError(None, f"no .wav or .flac input in {' '.join(specs)}")
    outs = output_paths(inputs, outdir, fmt)
    model = Model.load(model_path)
    outdir.mkdir(parents=True, exist_ok=True)
    outcomes: dict[Path, Outcome] = {}
    todo = []
    for src, out in zip(inputs, outs, strict=True):
        if out.exists() and not job.overwrite:
            outcomes[src] = Outcome(str(src), str(out), "skipped", "the output exists "
                                    "(--overwrite replaces it)")
        else:
            todo.append((src, out))
    workers = max(1, min(jobs, len(todo)))
    log.info("%d inputs: %d to synthesize in %d process%s, %d skipped (output exists)",
             len(inputs), len(todo), workers, "es" * (workers > 1), len(outcomes))
    if workers > 1:
        import_synthesis()
    _WORKER.update(model=model, job=job)          # read by _worker_run, here or in a forked worker
    t0 = time.perf_counter()
    died = Skips("inputs", verb="failed")         # a worker that died: its input failed
    for _, outcome in fan_out(_worker_run, todo, workers, skip=died, progress=progress,
                              describe=lambda pair: str(pair[0]), ordered=False):
        outcomes[Path(outcome.input)] = outcome
        if outcome.status == "failed":
            log.info("%s", outcome.reason)          # and in the summary at the end
        elif "line" in outcome.details:             # here, above the bar: not from a worker
            log.info("%s", outcome.details["line"])
    for src, out in todo:
        if (src, out) in died.bad:
            outcomes[src] = Outcome(str(src), str(out), "failed", died.bad[(src, out)])
    log.info("%d inputs in %.1f s", len(todo), time.perf_counter() - t0)
    return [outcomes[p] for p in inputs]


def write_summary(outdir: Path, outcomes: Sequence[Outcome], settings: dict[str, Any],
                  seconds: float) -> Path:
    """The JSON summary beside the outputs: counts, settings and every input's outcome."""
    from facetraj_engine.io.files import write_json

    counts = {s: sum(o.status == s for o in outcomes) for s in ("done", "skipped", "failed")}
    return write_json(outdir / SUMMARY_NAME, {
        "format": "facetraj-synth-summary", "version": 1, **counts, "seconds": round(seconds, 3),
        "settings": settings, "inputs": [asdict(o) for o in outcomes]})


def summary_lines(outcomes: Sequence[Outcome]) -> list[str]:
    """The summary for the terminal: the counts, then each failed input's reason."""
    counts = {s: sum(o.status == s for o in outcomes) for s in ("done", "skipped", "failed")}
    lines = [f"{counts['done']} done, {counts['skipped']} skipped (output exists), "
             f"{counts['failed']} failed"]
    lines += [f"failed: {o.reason}" for o in outcomes if o.status == "failed"]
    return lines


def default_jobs() -> int:
    """Worker processes by default: the cores this process may use."""
    from facetraj_engine.threads import usable_cores

    return usable_cores()

