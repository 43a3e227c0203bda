"""Phone labelling benchmark (``facetraj_engine.labels.alignment``): seconds of computation per second of speech
for forced alignment (two PocketSphinx passes, with and without the fit check against a free phone
loop) and for phone recognition (all-phone search, then the phone sequence re-aligned).

Inputs: sentences of the default corpus with their transcripts (and the real MOCHA-TIMIT sample
when ../shared is present), labelled without the label cache. Lower is better: 0.5 means one
second of speech is labelled in half a second.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from facetraj_engine.io.audio import read_audio
from facetraj_engine.labels.alignment import align, recognize

from .common import REPO, BenchContext, BenchRow, timed

log = logging.getLogger(__name__)

CORPUS = REPO / "data_samples"
MOCHA = REPO.parent / "shared" / "data" / "mocha_fsew0_001"
SENTENCES = ("s001", "s002", "s003", "s004", "s005")
AIMS: dict[str, float] = {}      # the issue sets no aim: measured, not judged


def _inputs(smoke: bool) -> list[tuple[str, object, int, str]]:
    out = []
    for stem in SENTENCES[:1 if smoke else None]:
        audio, rate = read_audio(CORPUS / f"{stem}.flac")
        out.append((stem, audio, rate, (CORPUS / f"{stem}.txt").read_text().strip()))
    if not smoke and (MOCHA / "fsew0_001.wav").exists():
        audio, rate = read_audio(MOCHA / "fsew0_001.wav")
        out.append(("fsew0_001", audio, rate, "This was easy for us."))
    return out


def run(ctx: BenchContext) -> list[BenchRow]:
    """Seconds per second of speech for each labelling method, summed over the inputs."""
    inputs = _inputs(ctx.smoke)
    speech_s = sum(len(a) / r for _, a, r, _ in inputs)
    methods: dict[str, Callable[[object, int, str], object]] = {
        "align": lambda a, r, t: align(a, r, t),
        "align, no fit check": lambda a, r, t: align(a, r, t, check_fit=False),
        "recognize": lambda a, r, t: recognize(a, r),
    }
    _, a, r, t = inputs[0]
    align(a, r, t, check_fit=False)          # warm-up: loads the acoustic model and dictionary
    rows = []
    for name, fn in methods.items():
        wall = cpu = 0.0
        for _, audio, rate, text in inputs:
            tm, _ = timed(lambda fn=fn, audio=audio, rate=rate, text=text: fn(audio, rate, text))
            wall, cpu = wall + tm.wall, cpu + tm.cpu
        per = wall / speech_s
        aim = AIMS.get(name)
        log.info("labels %s: %.2f s per s of speech", name, per)
        rows.append(BenchRow("labels", f"{name}, per second of speech", per, "s/s",
                             aim=f"<= {aim:g} s/s" if aim else "",
                             ok=None if ctx.smoke or aim is None else per <= aim,
                             note=f"{len(inputs)} utterances, {speech_s:.1f} s of speech; "
                                  f"{wall:.1f} s wall", cpu=cpu / speech_s))
    return rows
