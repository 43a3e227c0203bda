"""docs/api.md runs: its Python blocks, in order, in one namespace, in a folder holding a small
corpus and a recording with its labels (the default corpus's: real sentences, so that the
alignment block aligns real speech). The page cannot go stale without this failing."""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "api.md"
BLOCK = re.compile(r"```python\n(.*?)```", re.S)


def blocks() -> list[str]:
    return BLOCK.findall(DOC.read_text(encoding="utf-8"))


@pytest.fixture
def workspace(tmp_path, default_corpus):
    """``corpus/``: 40 training and 2 test sentences of the default corpus (their files linked,
    not copied); ``speech.wav``, ``speech.TextGrid`` and ``speech.txt``: a test sentence."""
    from facetraj_engine.io.audio import read_audio, write_audio

    info = json.loads((default_corpus.root / "corpus.json").read_text())
    train, test = info["train"][:40], info["test"][:2]
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    for utt in train + test:
        for path in default_corpus.root.glob(f"{utt}.*"):
            (corpus / path.name).symlink_to(path)
    info.update(train=train, test=test)
    (corpus / "corpus.json").write_text(json.dumps(info))
    audio, rate = read_audio(default_corpus.root / f"{test[0]}.flac")
    write_audio(tmp_path / "speech.wav", audio, rate)
    for suffix in ("TextGrid", "txt"):
        shutil.copy(default_corpus.root / f"{test[0]}.{suffix}", tmp_path / f"speech.{suffix}")
    return tmp_path


def test_the_page_has_its_blocks():
    assert len(blocks()) >= 5


def test_every_block_of_the_api_page_runs(workspace, monkeypatch, capsys):
    monkeypatch.chdir(workspace)
    namespace: dict = {}
    for k, code in enumerate(blocks()):
        try:
            exec(compile(code, f"docs/api.md, block {k + 1}", "exec"), namespace)
        except Exception as exc:               # the block that failed, named
            raise AssertionError(f"docs/api.md block {k + 1} failed: {exc!r}\n{code}") from exc
    out = capsys.readouterr().out
    assert (workspace / "model.npz").is_file() and (workspace / "face.c3d").is_file()
    assert re.search(r"\(\d+, 54, 3\)", out)                          # the markers' shape
    assert "phonetic mode: hand-checked labels" in out                # synthesize_recording's line
    assert "no-such-file.wav" in out
    assert os.path.getsize(workspace / "face.c3d") > 1000
