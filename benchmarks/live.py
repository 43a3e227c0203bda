"""Live mode (issues 13, 27 and 40): latency from an audio sample entering to its face frame, speed
of the streaming path, acoustic-only (with the closure step: the rest in pauses) and
with phones recognized as they are spoken; the lip closure of ``facetraj live --from-file`` on
the CMU ARCTIC samples; face updates per second of the Live
window under Xvfb.

Latency is simulated on the audio clock, without sleeping: blocks of ``BLOCK_S`` arrive at their
last sample's time and queue up when the previous one is still being processed; a block's
processing starts at ``max(its arrival, the previous block's end)`` and lasts its ``feed()`` call's
measured wall time (with phones: the recognizer's and the synthesizer's, one after the other, as
``facetraj live --from-file`` runs them; in the window the recognizer has a thread of its own, but
PocketSphinx holds Python's lock while it decodes); a frame's latency is the end of the processing
of the block that completes it minus the frame's time (the algorithm's lookahead, the block wait,
the queue and the compute; a stream slower than real time shows as growing latency; the render of
the frame is the live fps row's business).

``python -m benchmarks.live [--section docs/benchmarks.md]`` runs only these and writes them as
a section of that file (``python -m benchmarks`` puts them in the main table).
"""

from __future__ import annotations

import argparse
import os
import re
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from facetraj_engine.config import SynthConfig
from facetraj_engine.streaming.live import LiveConfig, LiveStream
from facetraj_engine.threads import one_blas_thread

from .common import BenchContext, BenchRow, concatenate_input, load_context, markdown_table

BLOCK_S = 0.01                 # a typical audio callback (10 ms)
SPEED_BLOCKS_S = (0.01, 0.1, 1.0)
AIMS = {"latency": 150.0, "latency phones": 250.0, "speed": 20.0, "speed phones": 5.0,
        "fps": 30.0, "closure": 0.7, "closure acoustic": 0.5, "vowel max": 17.0, "vowels shut": 0.05}
SECTION = ("<!-- live benchmarks: written by python -m benchmarks.live -->",
           "<!-- end of live benchmarks -->")
MODES = {"acoustic-only": LiveConfig(phones=False), "phones + acoustics": LiveConfig()}


def _stream(model, audio: np.ndarray, rate: int, block_s: float, config: LiveConfig
            ) -> tuple[list[float], float, float, LiveStream]:
    """Per-frame latencies (s), the total wall and CPU time of streaming ``audio`` in blocks, and
    the stream."""
    stream = LiveStream(model, rate, config=config)
    block = max(1, int(round(block_s * rate)))
    latencies: list[float] = []
    total = 0.0
    busy_until = 0.0                                    # on the audio clock
    cpu0 = time.process_time()
    for a in range(0, len(audio), block):
        arrival = min(a + block, len(audio)) / rate
        t0 = time.perf_counter()
        frames = stream.feed(audio[a:a + block])
        dt = time.perf_counter() - t0
        total += dt
        busy_until = max(arrival, busy_until) + dt
        latencies += [busy_until - t for t in frames.times]
    t0 = time.perf_counter()
    stream.flush()
    return latencies, total + time.perf_counter() - t0, time.process_time() - cpu0, stream


def run(ctx: BenchContext) -> list[BenchRow]:
    """The live rows, on one BLAS thread as live mode runs (``facetraj_app.live.run_live``,
    ``facetraj live -o``)."""
    with one_blas_thread():
        return _run(ctx)


def _run(ctx: BenchContext) -> list[BenchRow]:
    seconds = 5.0 if ctx.smoke else 30.0
    audio, rate, _ = concatenate_input(ctx.test_utts or ctx.train_utts, seconds)
    rows = []
    for mode, config in MODES.items():
        rows += _latency_and_speed(ctx.model, audio, rate, seconds, mode, config)
    rows += closure_rows(ctx)
    rows += _live_fps(ctx, 3.0 if ctx.smoke else 8.0)
    return rows


def _latency_and_speed(model, audio: np.ndarray, rate: int, seconds: float, mode: str,
                       config: LiveConfig) -> list[BenchRow]:
    phones = config.phones
    _stream(model, audio[: rate], rate, BLOCK_S, config)                   # warm-up
    lat, _, _, stream = _stream(model, audio, rate, BLOCK_S, config)
    lat_ms = 1000 * np.asarray(lat)
    look = 1000 * stream.lookahead_s
    aim = AIMS["latency phones" if phones else "latency"]
    how = (f"recognizer settling {1000 * config.recognizer.settle_s:.0f} ms behind its front, "
           f"phones awaited {1000 * config.timing.wait_s:.0f} ms at most, frames in batches of "
           f"{config.timing.batch}, smoothing" if phones else
           "window + smoothing + live mode's batch of 5 frames; the closure detector adds none")
    rows = []
    for name, value in (("median", np.median(lat_ms)), ("95th percentile", np.percentile(lat_ms, 95))):
        rows.append(BenchRow("live", f"latency sample -> face frame, {mode}, {name}", float(value),
                             "ms", f"<= {aim:.0f} ms", bool(value <= aim),
                             note=f"{BLOCK_S * 1000:.0f} ms blocks, {seconds:g} s of test speech; "
                                  f"includes the {look:.1f} ms lookahead ({how})"
                                  + (f"; phones settled in time for "
                                     f"{100 * stream.labelled_share:.0f} % of the frames"
                                     if phones else "")))
    aim = AIMS["speed phones" if phones else "speed"]
    for block_s in SPEED_BLOCKS_S:
        _, wall, cpu, stream = _stream(model, audio, rate, block_s, config)
        rtf = seconds / wall
        rec = (f"; recognition {100 * stream.recognize_s / wall:.0f} % of it" if phones else "")
        rows.append(BenchRow("live", f"streaming speed, {mode}, {block_s * 1000:g} ms blocks", rtf,
                             "x RT", f">= {aim:.0f}x" if block_s == BLOCK_S or not phones else "",
                             bool(rtf >= aim) if block_s == BLOCK_S or not phones else None,
                             note=f"{seconds:g} s of test speech as fast as possible{rec}",
                             cpu=seconds / max(cpu, 1e-9)))
    return rows


def closure_rows(ctx: BenchContext) -> list[BenchRow]:
    """Lip closure of ``facetraj live --from-file`` on the ARCTIC samples, both modes (the
    measure of issue 25, through :func:`facetraj_engine.evaluation.closure_eval.live_closure`)."""
    from facetraj.paths import shared_path
    from facetraj_engine.evaluation.closure_eval import ARCTIC_DIR, arctic_references, live_closure

    folder = shared_path(ARCTIC_DIR)
    if not folder.is_dir() or ctx.model.closure is None:
        return [BenchRow("live", "lip closure of live --from-file (ARCTIC samples)", float("nan"),
                         "%", note=f"skipped: no {ARCTIC_DIR} beside the repository"
                         if not folder.is_dir() else "skipped: a model without closure statistics")]
    refs = arctic_references(folder)
    if ctx.smoke:
        refs = dict(list(refs.items())[:1])
    rows = []
    for mode, config in MODES.items():
        # acoustic-only, the lips close only by the detector, off by default (issue 46): asked for
        synth = None if config.phones else SynthConfig(closure_detector=True)
        score = live_closure(ctx.model, refs, config, synth=synth)
        judged = not ctx.smoke
        aim = AIMS["closure" if config.phones else "closure acoustic"]
        note = (f"{score.n} /p b m/ in {len(refs)} recordings, 10 ms blocks; median minimum "
                f"{score.median_min:.1f} mm against {score.closed:.1f} mm closed; median pause "
                f"{score.pause:.1f} mm" + ("" if config.phones else "; closures by the model's "
                                          "bilabial-closure detector (--closure-detector)"))
        rows.append(BenchRow("live", f"/p b m/ within 1 mm of closed, live --from-file, {mode}",
                             100 * score.within, "%", f">= {100 * aim:.0f} %" if judged
                             else "", bool(score.within >= aim) if judged else None,
                             note=note))
        rows.append(BenchRow("live", f"median vowel maximum, live --from-file, {mode}",
                             score.vowel_max, "mm", f">= {AIMS['vowel max']:.0f} mm" if judged
                             else "", bool(score.vowel_max >= AIMS["vowel max"]) if judged else None,
                             note="the lip aperture's largest value in each vowel, median"))
        rows.append(BenchRow("live", f"vowels shut, live --from-file, {mode}",
                             100 * score.vowels_shut, "%", f"<= {100 * AIMS['vowels shut']:.0f} %"
                             if judged else "", bool(score.vowels_shut <= AIMS["vowels shut"])
                             if judged else None,
                             note=f"vowels whose largest aperture is within 1 mm of closed; other "
                                  f"consonants shut: {100 * score.consonants_shut:.1f} %"))
    session = live_closure(ctx.model, refs, MODES["phones + acoustics"], session=True)
    rows.append(BenchRow("live", "/p b m/ within 1 mm of closed, the recordings as takes of one "
                         "Live window, phones + acoustics", 100 * session.within, "%",
                         note="the recognizer's running cepstral mean kept from take to take, as "
                              f"the window keeps it; median vowel maximum {session.vowel_max:.1f} mm"))
    return rows + comparison_rows(ctx, refs)


def comparison_rows(ctx: BenchContext, refs) -> list[BenchRow]:
    """Live mode against ``facetraj synth`` of the same recordings
    (:func:`facetraj_engine.evaluation.live_eval.compare_live_offline`)."""
    from facetraj_engine.evaluation.live_eval import compare_live_offline

    c = compare_live_offline(ctx.model, refs)
    what = f"{len(refs)} ARCTIC recordings, facetraj synth (recognizing their phones) vs live --from-file"
    return [
        BenchRow("live", "/p b m/ within 1 mm of closed, facetraj synth (offline)",
                 100 * c.offline.within, "%", note=f"{what}; live: {100 * c.live.within:.0f} %"),
        BenchRow("live", "reference /p b m/ found by the recognizer, offline / live",
                 c.found_offline, f"of {c.n}", note=f"live: {c.found_live} of {c.n}"),
        BenchRow("live", "speech frames whose recognized phone is the offline one, live", 100 *
                 c.phones_alike, "%", note="10 ms frames of the offline recognizer's phones"),
        BenchRow("live", "lip aperture, live minus offline, RMS", c.aperture_rms_mm, "mm",
                 note=f"{what}; correlation {c.aperture_corr:.3f}; median vowel maximum "
                      f"{c.offline.vowel_max:.1f} mm offline, {c.live.vowel_max:.1f} mm live"),
    ]


def _live_fps(ctx: BenchContext, seconds: float) -> list[BenchRow]:
    """Face updates per second of the Live window playing test speech in real time."""
    from facetraj_app.display import has_display

    if not has_display():
        return [BenchRow("live", "Live window face updates", float("nan"), "fps",
                         note="skipped: no DISPLAY (run under xvfb-run, as make bench does)")]
    from PyQt6.QtWidgets import QApplication

    from facetraj_app.live import LiveWindow

    app = QApplication.instance() or QApplication([])
    audio, rate, _ = concatenate_input(ctx.test_utts or ctx.train_utts, seconds)
    window = LiveWindow(ctx.model, None, (audio, rate), block_s=BLOCK_S)
    window.resize(1400, 800)
    window.show()
    window.takeFinished.connect(app.quit)
    window.start()
    app.exec()
    fps = window.fps
    window.close()
    return [BenchRow("live", "Live window face updates (Xvfb)", fps, "fps",
                     f">= {AIMS['fps']:.0f}", bool(fps >= AIMS["fps"]),
                     note=f"{seconds:g} s of test speech from a file in real time, "
                          f"{BLOCK_S * 1000:.0f} ms blocks, 1400x800 window")]


def write_section(path: Path, rows: Sequence[BenchRow]) -> None:
    """Put ``rows`` as the live section of ``path`` (replacing an earlier one)."""
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    body = "\n".join([SECTION[0], "", "## Live mode (benchmarks/live.py)", "",
                      f"Measured {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} by "
                      f"`python -m benchmarks.live`; the 2 cores were shared with other jobs "
                      f"(load average {load} at the end), so these are pessimistic: the CPU-time "
                      f"column is the speed the process would have with a core to itself; when "
                      f"the wall-clock speed is below 1x real time the blocks queue up and the "
                      f"latency grows with the length of the input.", "",
                      markdown_table(rows), "", SECTION[1]])
    text = path.read_text(encoding="utf-8") if path.exists() else ""
    pattern = re.escape(SECTION[0]) + ".*?" + re.escape(SECTION[1])
    text = (re.sub(pattern, lambda _: body, text, flags=re.S) if SECTION[0] in text
            else text.rstrip("\n") + "\n\n" + body)
    path.write_text(text.rstrip("\n") + "\n", encoding="utf-8")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.live")
    parser.add_argument("--smoke", action="store_true")
    parser.add_argument("--section", type=Path, help="write the rows as a section of this file")
    args = parser.parse_args(argv)
    rows = run(load_context(smoke=args.smoke))
    print(markdown_table(rows))
    if args.section:
        write_section(args.section, rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
