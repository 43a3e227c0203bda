"""The bad-input cases of phone labelling (docs/bad-input.md rows), on a real sentence of the
default corpus; used by tests/test_bad_input_doc.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from facetraj_engine.io.audio import read_audio
from facetraj_engine.labels.alignment import align, read_dictionary, recognize

SENTENCE = Path(__file__).resolve().parent.parent / "data_samples" / "s002.flac"


def alignment_cases(tmp: Path) -> dict:
    """Case name (as in docs/bad-input.md) -> a callable that makes it happen."""
    audio, rate = read_audio(SENTENCE)
    text = SENTENCE.with_suffix(".txt").read_text().strip()
    src = str(SENTENCE)

    def dict_file(content: str) -> Path:
        path = tmp / "extra.dict"
        path.write_text(content)
        return path

    return {
        "a word not in the pronouncing dictionary": lambda: align(
            audio, rate, text + " zorblax", source=src),
        "a pronunciation that is not ARPAbet": lambda: read_dictionary(dict_file("ZORB  Z Q1 R B\n")),
        "text that does not match the audio": lambda: align(
            audio, rate, "tornadoes often destroy acres of farm land", source=src),
        "silent audio given to the aligner": lambda: recognize(np.zeros(rate), rate, src),
        "audio too short to label": lambda: align(audio[: rate // 10], rate, "the boy", source=src),
        "empty text to align": lambda: align(audio, rate, "  ...  ", source=src),
        "non-English characters in the text": lambda: align(audio, rate, "the boy 男孩", source=src),
        "digits in the text": lambda: align(audio, rate, "the 2 boys", source=src),
    }
