"""Saving corrected labels (facetraj_engine.io.labelling.write_labels): never over an existing
file unless asked, and a save killed or failing half-way leaves the previous file whole."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from facetraj_engine.data import PhoneSegment as S
from facetraj_engine.data import Provenance
from facetraj_engine.errors import OutputError, OutputExistsError
from facetraj_engine.io.labelfiles import read_label_file
from facetraj_engine.io.labelling import write_labels
from facetraj_engine.labels.editing import PHONES, LabelDocument
from facetraj_engine.labels.provenance import Labels


def recognized(n: int = 400) -> Labels:
    """``n`` phones over ``n / 10`` s (a long file: the write takes a while)."""
    phones = [S(k / 10, (k + 1) / 10, "n" if k % 2 else "ah") for k in range(n)]
    return Labels(phones, [], "recognized", scores=np.full(n, -5.0),
                  provenance=Provenance("recognized", "PocketSphinx 5.1.1"))


def corrected(labels: Labels) -> Labels:
    d = LabelDocument(labels, labels.phones[-1].end, 60.0)
    d.select(PHONES, 1)
    d.rename("m")
    return d.labels_now()


def test_an_existing_file_is_kept_unless_overwrite_is_asked(tmp_path):
    path = tmp_path / "rec.TextGrid"
    write_labels(path, recognized(), 40.0)
    before = path.read_bytes()
    with pytest.raises(OutputExistsError, match="already exists"):
        write_labels(path, corrected(recognized()), 40.0)
    assert path.read_bytes() == before
    write_labels(path, corrected(recognized()), 40.0, overwrite=True)
    back = read_label_file(path, 16000, 40.0)
    assert back.phones[1].label == "m" and back.provenance.corrected == 1


def test_a_save_that_fails_half_way_leaves_the_old_file_whole(tmp_path, monkeypatch):
    from praatio import textgrid

    path = tmp_path / "rec.TextGrid"
    write_labels(path, recognized(), 40.0)
    before = path.read_bytes()

    def half_then_fail(self, fn, *args, **kwargs):
        with open(fn, "wb") as out:
            out.write(before[: len(before) // 2])
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(textgrid.Textgrid, "save", half_then_fail)
    with pytest.raises(OutputError, match="no space left on the device"):
        write_labels(path, corrected(recognized()), 40.0, overwrite=True)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec.TextGrid"]     # no part left


#: a child process that saves corrected labels over ``path`` and stops half-way through the
#: write, saying so on its standard output, until it is killed
CHILD = textwrap.dedent("""
    import sys
    from praatio import textgrid
    sys.path.insert(0, {tests!r})
    from test_label_save import corrected, recognized
    from facetraj_engine.io.labelling import write_labels

    def half_and_wait(self, fn, *args, **kwargs):
        with open(fn, "w") as out:
            out.write('File type = "ooTextFile"\\nObject class = "TextGrid"\\n\\nxmin = 0\\n')
            out.flush()
            print(fn, flush=True)           # the parent kills us now
            sys.stdin.read()

    textgrid.Textgrid.save = half_and_wait
    write_labels({path!r}, corrected(recognized()), 40.0, overwrite=True)
""")


def test_a_save_killed_half_way_leaves_the_old_file_whole(tmp_path):
    import os
    import signal
    from pathlib import Path

    path = tmp_path / "rec.TextGrid"
    write_labels(path, recognized(), 40.0)
    before = path.read_bytes()
    child = subprocess.Popen([sys.executable, "-c", CHILD.format(tests=str(Path(__file__).parent),
                                                                 path=str(path))],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        part = Path(child.stdout.readline().strip())      # the write is under way
        assert part.parent == tmp_path and part.name.startswith(".rec.part-")
        assert part.read_text().startswith('File type = "ooTextFile"')
        os.kill(child.pid, signal.SIGKILL)
        assert child.wait(timeout=60) == -signal.SIGKILL
    finally:
        if child.poll() is None:
            child.kill()
    assert path.read_bytes() == before
    back = read_label_file(path, 16000, 40.0)
    assert back.phones[1].label == "n" and back.provenance.corrected == 0
