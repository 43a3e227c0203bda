"""What the analysis modules share: CSV tables written atomically, and a corpus cut down to its
first few utterances for a quick look."""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Iterable, Sequence
from dataclasses import replace
from pathlib import Path

from ..io.corpus import Corpus
from ..io.files import atomic_write


def write_csv(path: str | os.PathLike[str], header: Sequence[str], rows: Iterable[Sequence],
              overwrite: bool = True) -> Path:
    """Write ``header`` and ``rows`` as CSV (floats to 6 significant digits), atomically."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for r in rows:
        w.writerow([f"{x:.6g}" if isinstance(x, float) else x for x in r])
    path = Path(path)
    with atomic_write(path, overwrite) as tmp:
        tmp.write_text(buf.getvalue(), encoding="utf-8")
    return path


def subset_corpus(corpus: Corpus, per_split: int | None) -> Corpus:
    """The same corpus with only the first ``per_split`` utterances of each split (all when
    ``None`` or 0): a quick look at Table 2 or the N sweep before the full run."""
    if not per_split:
        return corpus
    info = replace(corpus.info, train=list(corpus.info.train[:per_split]),
                   test=list(corpus.info.test[:per_split]))
    return Corpus(corpus.root, info)


__all__ = ["subset_corpus", "write_csv"]
