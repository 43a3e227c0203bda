"""The benchmarks' smoke mode runs in-process on the toy corpus and fills its table (issue 7).

No timing thresholds: only that every expected row is there with a positive finite number.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from toycorpus import build_toy_corpus


@pytest.fixture(scope="module")
def toy(tmp_path_factory) -> Path:
    return build_toy_corpus(tmp_path_factory.mktemp("toy"), n_train=12, n_test=3)


def test_smoke_table(toy: Path, tmp_path: Path, capsys) -> None:
    from benchmarks.__main__ import main

    out = tmp_path / "benchmarks.md"
    assert main(["--smoke", "--corpus", str(toy), "--out", str(out),
                 "--only", "train", "synth", "scaling"]) == 0
    printed = capsys.readouterr().out
    text = out.read_text()
    for needle in ("## Machine", "CPU:", "numpy:", "| group | benchmark |"):
        assert needle in text
    expected = [
        "LSF extraction (lsf_at)", "PCA (pca_of)", "train() total",
        "train() peak traced memory (tracemalloc)",
        "phonetic, 1 s input", "phonetic, 2 s input", "acoustic, 1 s input", "acoustic, 2 s input",
        "LSF index build (k-means), codebook x4",
        "acoustic, full search (paper), codebook x1", "acoustic, full search (paper), codebook x4",
        "acoustic, exact prefilter K=32, codebook x1", "acoustic, indexed K=32, probe 8, codebook x4",
        "growth exponent, full search (paper)", "growth exponent, indexed K=32",
        "test whole-face correlation, acoustic full search (paper)",
        "test whole-face correlation, acoustic indexed K=128 (default)",
    ]
    for name in expected:
        assert name in printed, name
        assert name in text, name


def test_smoke_rows_positive_finite(toy: Path, monkeypatch) -> None:
    from benchmarks.__main__ import run_all
    from benchmarks.common import load_context
    from facetraj_engine.threads import THREADS_ENV

    monkeypatch.setenv(THREADS_ENV, "2")
    ctx = load_context(toy, smoke=True)
    rows = run_all(ctx, ("train", "synth", "scaling"))
    groups = {r.group for r in rows}
    assert groups == {"train", "synth", "scaling", "stages"}
    synth = [r.name for r in rows if r.group == "synth"]     # 2 modes x 2 durations, each also
    assert len(synth) == 8                                    # on one frame thread
    assert sum(name.endswith(", one frame thread") for name in synth) == 4
    for mode in ("phonetic", "acoustic"):                     # the stages add up to the call
        parts = [r.value for r in rows if r.group == "stages" and r.name.startswith(mode)
                 and not r.name.endswith("whole call")]
        whole = [r.value for r in rows if r.group == "stages" and r.name.startswith(mode)
                 and r.name.endswith("whole call")]
        assert len(parts) >= 5 and len(whole) == 1
        assert sum(parts) == pytest.approx(whole[0], rel=1e-9)
    for r in rows:
        assert math.isfinite(r.value), r
        if r.unit != "e":                                       # growth exponents may be ~0
            assert r.value > 0, r
        assert r.ok is None                                     # smoke mode judges no aims


def test_playback_skipped_without_module(monkeypatch) -> None:
    import importlib.util

    from benchmarks.__main__ import run_playback

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "benchmarks.playback" else real(name, *a))
    rows = run_playback(smoke=True)
    assert len(rows) == 1 and rows[0].group == "playback" and "skipped" in rows[0].note


def test_smoke_eval_rows(toy: Path) -> None:
    """The whole-corpus evaluation benchmark: serial and parallel wall times, results equal."""
    from benchmarks.__main__ import run_all
    from benchmarks.common import load_context

    rows = run_all(load_context(toy, smoke=True), ("eval",))
    assert [r.group for r in rows] == ["eval", "eval"]
    assert all(math.isfinite(r.value) and r.value > 0 for r in rows)
    assert "scores equal to the serial run: True" in rows[1].note


def test_smoke_command_rows(toy: Path) -> None:
    """The whole-command benchmark (issue 28) in smoke size: every row there, finite, unjudged."""
    from benchmarks import cli
    from benchmarks.common import load_context

    ctx = load_context(toy, smoke=True)
    rows = cli.one_file(ctx) + cli.batch(ctx)
    names = [r.name for r in rows]
    for want in ("facetraj synth, phonetic, 2 s to .npz: main()",
                 "facetraj synth, acoustic, 2 s to .npz: main()",
                 *(f"facetraj synth, {mode}, 2 s to .{fmt}: the whole process"
                   for mode in ("phonetic", "acoustic") for fmt in ("npz", "tsv", "csv", "c3d")),
                 "text writer: 121 frames x ", "cold start: facetraj --version",
                 "batch of 6 files of 3-5 s, 1 worker", "batch of 6 files of 3-5 s, 2 workers",
                 "batch of 6 files: 2 workers against 1", "batch of 6 files: peak memory"):
        assert any(n.startswith(want) for n in names), want
    for r in rows:
        assert math.isfinite(r.value) and r.value > 0 and r.ok is None, r


def test_corpus_scaling_smoke(toy: Path, tmp_path: Path) -> None:
    """The corpus scaling benchmark (issue 41): the corpus repeated under new names (links to the
    same files, a corpus.json listing both splits repeated), the real `facetraj train` and `eval`
    run in child processes and measured from outside, and its section of the Markdown."""
    from benchmarks import corpus_scale
    from benchmarks.common import load_context
    from facetraj_engine.io.corpus import load_corpus

    corpus = load_corpus(toy)
    twice = load_corpus(corpus_scale.repeat_corpus(corpus, tmp_path / "x2", 2))
    assert twice.info.train == corpus.info.train + [f"{u}_r01" for u in corpus.info.train]
    assert (tmp_path / "x2" / f"{corpus.info.test[0]}_r01.wav").resolve() == \
        (toy / f"{corpus.info.test[0]}.wav").resolve()
    rows = corpus_scale.run(load_context(toy, smoke=True))
    names = {r.name: r for r in rows}
    for command in ("train", "eval"):
        for f in corpus_scale.SMOKE_FACTORS:
            assert names[f"{command} x{f}: time"].value > 0
            assert 30 < names[f"{command} x{f}: peak memory"].value < 2048
        assert math.isfinite(names[f"{command}: time growth exponent"].value)
    section = "\n".join(corpus_scale.section(rows))
    assert "| x2 |" in section and "### Past one machine" in section
