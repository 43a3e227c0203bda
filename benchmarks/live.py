"""Live mode (issue 13): latency from an audio sample entering to its face frame, speed of the
streaming path, and face updates per second of the Live window under Xvfb.

Latency is simulated on the audio clock, without sleeping: blocks of ``BLOCK_S`` arrive at their
last sample's time and queue up when the previous one is still being processed; a block's
processing starts at ``max(its arrival, the previous block's end)`` and lasts its ``feed()`` call's
measured wall time; a frame's latency is the end of the processing of the block that completes it
minus the frame's time (the algorithm's lookahead, the block wait, the queue and the compute; a
stream slower than real time shows as growing latency; the render of the frame is the live fps
row's business).

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

from engine.config import SynthConfig
from engine.streaming.synthesizer import LIVE_BATCH_FRAMES, StreamConfig, StreamingSynthesizer
from engine.threads import one_blas_thread

from .common import BenchContext, BenchRow, concatenate_input, load_context, markdown_table

BLOCK_S = 0.01                 # a typical audio callback (10 ms)
SPEED_BLOCKS_S = (0.01, 0.1, 1.0)
AIMS = {"latency": 150.0, "speed": 20.0, "fps": 30.0}
SECTION = ("<!-- live benchmarks: written by python -m benchmarks.live -->",
           "<!-- end of live benchmarks -->")


def _stream(model, audio: np.ndarray, rate: int, block_s: float, batch: int = LIVE_BATCH_FRAMES
            ) -> tuple[list[float], float, float]:
    """Per-frame latencies (s), and the total wall and CPU time of streaming ``audio`` in blocks
    (frames analysed in batches of ``batch``; live mode's by default)."""
    cfg = SynthConfig(mode="acoustic")
    stream = StreamingSynthesizer(model, StreamConfig(rate, cfg, batch))
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
    return latencies, total + time.perf_counter() - t0, time.process_time() - cpu0


def run(ctx: BenchContext) -> list[BenchRow]:
    """The live rows, on one BLAS thread as live mode runs (``app.live.run_live``,
    ``facetraj live -o``)."""
    with one_blas_thread():
        return _run(ctx)


def _run(ctx: BenchContext) -> list[BenchRow]:
    model = ctx.model
    seconds = 5.0 if ctx.smoke else 30.0
    audio, rate, _ = concatenate_input(ctx.test_utts or ctx.train_utts, seconds)
    _stream(model, audio[: rate], rate, BLOCK_S)                       # warm-up
    lat, _, _ = _stream(model, audio, rate, BLOCK_S)
    lat_ms = 1000 * np.asarray(lat)
    look = 1000 * StreamingSynthesizer(model, StreamConfig(batch_frames=LIVE_BATCH_FRAMES)).lookahead_s
    rows = []
    for name, value in (("median", np.median(lat_ms)), ("95th percentile", np.percentile(lat_ms, 95))):
        rows.append(BenchRow("live", f"latency sample -> face frame, {name}", float(value), "ms",
                             f"<= {AIMS['latency']:.0f} ms", bool(value <= AIMS["latency"]),
                             note=f"{BLOCK_S * 1000:.0f} ms blocks, {seconds:g} s of test speech; "
                                  f"includes the {look:.1f} ms lookahead (window + smoothing + "
                                  f"live mode's batch of {LIVE_BATCH_FRAMES} frames)"))
    for block_s in SPEED_BLOCKS_S:
        _, wall, cpu = _stream(model, audio, rate, block_s)
        rtf = seconds / wall
        rows.append(BenchRow("live", f"streaming speed, {block_s * 1000:g} ms blocks", rtf, "x RT",
                             f">= {AIMS['speed']:.0f}x", bool(rtf >= AIMS["speed"]),
                             note=f"{seconds:g} s of test speech as fast as possible, live mode's "
                                  f"batch of {LIVE_BATCH_FRAMES} frames",
                             cpu=seconds / max(cpu, 1e-9)))
    _, wall, cpu = _stream(model, audio, rate, BLOCK_S, batch=1)
    rows.append(BenchRow("live", f"streaming speed, {BLOCK_S * 1000:g} ms blocks, every frame at "
                         "once (no batch)", seconds / wall, "x RT",
                         note=f"{seconds:g} s of test speech as fast as possible",
                         cpu=seconds / max(cpu, 1e-9)))
    rows += _live_fps(ctx, 3.0 if ctx.smoke else 8.0)
    return rows


def _live_fps(ctx: BenchContext, seconds: float) -> list[BenchRow]:
    """Face updates per second of the Live window playing test speech in real time."""
    from app.display import has_display

    if not has_display():
        return [BenchRow("live", "Live window face updates", float("nan"), "fps",
                         note="skipped: no DISPLAY (run under xvfb-run, as make bench does)")]
    from PyQt6.QtWidgets import QApplication

    from app.live import LiveWindow

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
