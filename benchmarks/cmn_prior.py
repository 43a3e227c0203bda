"""The prior of live recognition's running cepstral mean (issue 27): how many frames
PocketSphinx's initial mean counts as (``facetraj_engine.streaming.recognizer.CMN_PRIOR_FRAMES``), chosen
on recordings that are neither the training voice nor a test recording, then checked.

The choice: PocketSphinx's own test recordings (its 5.1.1 source distribution, ``test/data``:
``pip download --no-deps --no-binary :all: pocketsphinx==5.1.1``, unpack, pass the folder as
``--pocketsphinx-data``); for each count, :func:`facetraj_engine.evaluation.live_eval.prior_count_errors`
(the running mean's squared distance to each recording's whole mean, over every 5-frame block).

The check (``--check COUNT ...``), each count against the others on what the choice never saw:
the streamed recognizer's phones against offline recognition's (speech frames labelled alike) on
the default corpus's test sentences and on the real recordings beside the repository (the CMU
ARCTIC samples and the MOCHA sentence), and the lip closure of ``facetraj live --from-file`` on
the ARCTIC samples (as ``facetraj report --closure`` measures it).

``python -m benchmarks.cmn_prior --pocketsphinx-data DIR [--check 20 50]``
"""

from __future__ import annotations

import argparse
import logging
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from facetraj_engine.io.audio import read_audio
from facetraj_engine.threads import one_blas_thread

log = logging.getLogger(__name__)

#: PocketSphinx 5.1.1's test recordings of speech (``test/data``), by source; the others there
#: are not speech (noise, empty or broken files, an 8 kHz VAD test).
POCKETSPHINX_RECORDINGS = {
    "goforward": ("goforward.raw",), "numbers": ("numbers.raw",), "something": ("something.raw",),
    "tidigits": ("tidigits/dhd.2934z.raw",),
    "cards": tuple(f"cards/00{k}.wav" for k in range(1, 6)),
    "forever": ("forever/input_2_16k.wav", "forever/input_4_16k.wav"),
    "librivox": tuple(f"librivox/sense_and_sensibility_01_austen_64kb-0{k}.wav"
                      for k in (870, 880, 890, 920, 930)),
}
#: The counts tried (frames).
COUNTS = tuple(float(k) for k in range(0, 201, 10))
#: The real recordings of the check, read from ``../shared`` when present.
MOCHA_WAV = "data/mocha_fsew0_001/fsew0_001.wav"


def read_recording(path: Path) -> tuple[np.ndarray, int]:
    """A ``.wav`` or a headerless 16 kHz 16-bit ``.raw`` (PocketSphinx's test files)."""
    if path.suffix == ".raw":
        return np.frombuffer(path.read_bytes(), "<i2").astype(np.float64) / 32768.0, 16000
    return read_audio(path)


def choose_count(folder: Path, counts: Sequence[float] = COUNTS) -> dict[float, float]:
    """The error of every count on the recordings of :data:`POCKETSPHINX_RECORDINGS` in ``folder``."""
    from facetraj_engine.evaluation.live_eval import frame_cepstra, prior_count_errors

    cepstra = []
    for files in POCKETSPHINX_RECORDINGS.values():
        for f in files:
            audio, rate = read_recording(folder / f)
            cepstra.append(frame_cepstra(audio, rate))
    log.info("%d recordings, %d frames", len(cepstra), sum(len(c) for c in cepstra))
    return prior_count_errors(cepstra, counts)


def check(counts: Sequence[float]) -> list[str]:
    """Markdown rows: each count's phone agreement (corpus test sentences, real recordings) and
    ARCTIC closure of live mode."""
    from benchmarks.common import load_context
    from facetraj_engine.evaluation.closure_eval import ARCTIC_DIR, arctic_references, live_closure
    from facetraj_engine.evaluation.live_eval import phone_agreement
    from facetraj_engine.labels.alignment import recognize
    from facetraj_engine.streaming.live import LIVE_RECOGNIZER, LiveConfig
    from facetraj.paths import shared_path

    ctx = load_context()
    corpus = {u.name: (u.audio, u.sample_rate) for u in ctx.test_utts}
    refs = arctic_references(shared_path(ARCTIC_DIR))
    real = {w.name: (a, r) for w, (a, r, _) in refs.items()}
    mocha = shared_path(MOCHA_WAV)
    if mocha.exists():
        real[mocha.name] = read_audio(mocha)
    offline = {k: recognize(a, r).phones for k, (a, r) in {**corpus, **real}.items()}
    rows = []
    for count in counts:
        rec = replace(LIVE_RECOGNIZER, cmn_prior_frames=float(count))
        score = live_closure(ctx.model, refs, LiveConfig(recognizer=rec))
        rows.append(f"| {count:g} | {100 * phone_agreement(corpus, rec, offline):.1f} % | "
                    f"{100 * phone_agreement(real, rec, offline):.1f} % | "
                    f"{100 * score.within:.1f} % | {score.vowel_max:.1f} mm |")
    return ["| prior frames | phones as offline, corpus test | phones as offline, real | "
            "ARCTIC /p b m/ within 1 mm | vowel max |", "|---:|---:|---:|---:|---:|", *rows]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.cmn_prior")
    parser.add_argument("--pocketsphinx-data", type=Path,
                        help="PocketSphinx 5.1.1's source test/data folder (the choice)")
    parser.add_argument("--check", type=float, nargs="*", default=(),
                        help="prior counts to check on the corpus and the real recordings")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    log.setLevel(logging.INFO)
    with one_blas_thread():
        if args.pocketsphinx_data is not None:
            errors = choose_count(args.pocketsphinx_data)
            best = min(errors, key=errors.get)
            log.info("| prior frames | squared distance to the whole mean |\n|---:|---:|\n%s",
                     "\n".join(f"| {k:g} | {v:.1f} |" for k, v in errors.items()))
            log.info("nearest: %g frames", best)
        if args.check:
            log.info("\n".join(check(args.check)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
