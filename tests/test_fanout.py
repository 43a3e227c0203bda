"""Work fanned out over processes (facetraj_engine.fanout, the one fan-out of the project) and the
corpus-wide commands, the synth batch and the corpus builder that use it: a bad file gives the
serial run's one-line error with any number of jobs, or with --skip-bad is left out with a summary
and exit status 3; a worker killed while on an item fails that item only, named; every facetraj
error survives pickling."""

from __future__ import annotations

import importlib
import json
import logging
import os
import pickle
import pkgutil
import shutil
import signal
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

import facetraj_engine
from facetraj.cli import main
from facetraj_engine.errors import FILE_WARNINGS, FacetrajError, InputError, warn_file
from facetraj_engine.fanout import Skips, fan_out


# --------------------------------------------------------------------------- pickling
def _engine_error_classes() -> list[type]:
    for mod in pkgutil.walk_packages(facetraj_engine.__path__, "facetraj_engine."):
        importlib.import_module(mod.name)
    found, todo = [], [FacetrajError]
    while todo:
        cls = todo.pop()
        found.append(cls)
        todo.extend(cls.__subclasses__())
    return sorted({c for c in found if c.__module__.startswith("facetraj_engine.")}, key=lambda c: c.__name__)


#: how to make each error class whose __init__ is not (path, problem) or (message,)
SPECIAL = {"MissingWordsError": lambda cls: cls("a.txt", ["zorblax", "noizee"])}


def test_every_engine_error_class_round_trips_through_pickle():
    classes = _engine_error_classes()
    assert {"InputError", "OutputError", "OutputExistsError", "ModelFileError",
            "MissingWordsError", "UnalignableError"} <= {c.__name__ for c in classes}
    for cls in classes:
        if cls.__name__ in SPECIAL:
            exc = SPECIAL[cls.__name__](cls)
        elif issubclass(cls, InputError):
            exc = cls("/data/a.c3d", "not a readable C3D file")
        else:
            exc = cls("something went wrong")
        back = pickle.loads(pickle.dumps(exc))
        assert type(back) is cls
        assert str(back) == str(exc) and back.args == exc.args
        assert back.__dict__ == exc.__dict__, cls
        assert isinstance(back, OSError) == isinstance(exc, OSError)
    missing = pickle.loads(pickle.dumps(SPECIAL["MissingWordsError"](
        next(c for c in classes if c.__name__ == "MissingWordsError"))))
    assert missing.words == ["zorblax", "noizee"]


# --------------------------------------------------------------------------- fan_out
def _bad_b(item: str) -> str:
    if item == "b":
        raise InputError(f"/data/{item}.c3d", "not a readable C3D file")
    return item.upper()


@pytest.mark.parametrize("workers", [1, 2])
def test_first_bad_item_stops_the_work_with_its_own_error(workers):
    with pytest.raises(InputError) as exc:
        list(fan_out(_bad_b, ["a", "b", "c", "d"], workers))
    assert str(exc.value) == "/data/b.c3d: not a readable C3D file"
    assert exc.value.item == "b"


@pytest.mark.parametrize("workers", [1, 2])
def test_skipped_items_are_left_out_and_counted(workers):
    skip = Skips("utterances")
    seen: list[tuple[float, str]] = []
    out = list(fan_out(_bad_b, ["a", "b", "c"], workers, skip=skip,
                       progress=lambda f, m: seen.append((f, m))))
    assert out == [("a", "A"), ("c", "C")]
    assert skip.bad == {"b": "/data/b.c3d: not a readable C3D file"}
    assert skip.summary() == "1 of 3 utterances skipped: /data/b.c3d: not a readable C3D file"
    assert seen[0] == (0.0, "a") and seen[-1] == (1.0, "done")


def _dies_on_b(item: str) -> str:
    if item == "b":
        os._exit(9)          # as a worker killed by the kernel, or a crash in a C library
    return item


def _killed_on_b(item: str) -> str:
    if item == "b":
        os.kill(os.getpid(), signal.SIGKILL)         # as the kernel's out-of-memory killer does
    return item


def test_a_worker_that_dies_is_a_clean_error():
    with pytest.raises(FacetrajError, match=r"a worker process stopped unexpectedly \(exit status "
                                            r"9: .*\) while working on b; run with --jobs 1 to see "
                                            r"why"):
        list(fan_out(_dies_on_b, ["a", "b", "c"], 2))
    skip = Skips()
    assert list(fan_out(_dies_on_b, ["a", "b", "c"], 2, skip=skip)) == [("a", "a"), ("c", "c")]
    assert list(skip.bad) == ["b"]


@pytest.mark.parametrize("ordered", [True, False])
def test_a_worker_killed_by_sigkill_fails_only_its_item_named(ordered, monkeypatch):
    """SIGKILL while on item b: b fails with its name and the signal, a new worker takes the
    dead one's place (in order, with two items ahead, the other worker waits for b's outcome:
    the new one is certain), every other item is done once; every child is reaped."""
    pids = _forks_noted(monkeypatch)
    items = [f"i{k}" for k in range(6)] + ["b"] + [f"j{k}" for k in range(6)]
    skip = Skips("utterances")
    got = list(fan_out(_killed_on_b, items, 2, skip=skip, ordered=ordered, ahead=2))
    assert sorted(got) == sorted((i, i) for i in items if i != "b")
    assert list(skip.bad) == ["b"]
    assert skip.bad["b"].startswith("a worker process stopped unexpectedly (killed by signal 9")
    assert skip.bad["b"].endswith("while working on b; run with --jobs 1 to see why")
    assert skip.summary().startswith("1 of 13 utterances skipped: a worker process")
    assert len(pids) == 3 if ordered else 2 <= len(pids) <= 3     # two, one in the dead one's place
    assert _all_reaped(pids)
    with pytest.raises(FacetrajError, match="killed by signal 9.* while working on b") as exc:
        list(fan_out(_killed_on_b, items, 2, ordered=ordered))
    assert exc.value.item == "b"


class _TwoArgError(Exception):
    def __init__(self, a, b):
        super().__init__(f"{a} and {b}")


class _OddInputError(InputError):
    def __init__(self, where):
        super().__init__(where, "odd")
        self.callback = lambda: None     # does not pickle


def _raises_unpicklable(item: str) -> str:
    if item == "x":
        raise _TwoArgError("one", "two")
    if item == "y":
        raise _OddInputError("/data/y.wav")
    return item


def test_errors_that_do_not_pickle_still_come_back():
    with pytest.raises(RuntimeError, match="_TwoArgError: one and two"):
        list(fan_out(_raises_unpicklable, ["a", "x"], 2))
    with pytest.raises(InputError, match="^/data/y.wav: odd$"):
        list(fan_out(_raises_unpicklable, ["a", "y"], 2))


def _warns(item: str) -> str:
    warn_file(logging.getLogger("facetraj_engine.test"), "/data/shared.c3d", "short markers",
              "markers end at 1.00 s")
    warn_file(logging.getLogger("facetraj_engine.test"), f"/data/{item}.c3d", "short markers",
              f"markers of {item} end early")
    return item


def test_file_warnings_of_workers_are_logged_once(caplog):
    FILE_WARNINGS.clear()
    with caplog.at_level(logging.WARNING, logger="facetraj_engine.test"):
        list(fan_out(_warns, ["a", "b", "c"], 2))
        list(fan_out(_warns, ["a", "b", "c"], 1))      # a second pass: nothing new
    lines = [r.getMessage() for r in caplog.records if r.name == "facetraj_engine.test"]
    assert lines.count("/data/shared.c3d: markers end at 1.00 s") == 1
    assert sorted(lines) == sorted(["/data/shared.c3d: markers end at 1.00 s",
                                    *[f"/data/{i}.c3d: markers of {i} end early" for i in "abc"]])
    assert FILE_WARNINGS.counts()["short markers"] == 4


# --------------------------------------------------------------------------- the commands
@pytest.fixture
def corpus_with_a_bad_file(tmp_path, toy_corpus_dir) -> Path:
    """Three utterances of the toy corpus (two train, one test); toy001's C3D truncated."""
    from facetraj_engine.io.corpus import CorpusInfo, load_corpus, save_corpus_info

    root = tmp_path / "corpus"
    root.mkdir()
    ids = ["toy000", "toy001", "toy030"]
    for utt in ids:
        for ext in ("wav", "TextGrid", "c3d"):
            shutil.copy(toy_corpus_dir / f"{utt}.{ext}", root)
    info = load_corpus(toy_corpus_dir).info
    save_corpus_info(root, CorpusInfo(**{**info.__dict__, "train": ids[:2], "test": ids[2:]}))
    (root / "toy001.c3d").write_bytes((root / "toy001.c3d").read_bytes()[:300])
    return root


def _run(argv, capsys) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


BAD = "toy001.c3d: not a readable C3D file (no C3D header)"


def _refused_alike(argv, capsys) -> None:
    """``argv`` with -j 1 and -j 2: exit 2, the same one error line naming the bad file."""
    errs = []
    for j in ("1", "2"):
        code, _, err = _run([*argv, "-j", j, "-q"], capsys)
        assert code == 2, err
        assert "Traceback" not in err
        lines = [ln for ln in err.splitlines() if ": error: " in ln]
        assert len(lines) == 1 and lines[0].endswith(BAD), err
        assert "--skip-bad" in err
        errs.append(lines[0])
    assert errs[0] == errs[1]


def test_eval_and_sweep_with_a_bad_file(corpus_with_a_bad_file, toy_model, tmp_path, capsys):
    from facetraj_engine.evaluation.scores import evaluate
    from facetraj_engine.io.corpus import load_corpus

    model = toy_model.save(tmp_path / "m.npz")
    root = corpus_with_a_bad_file
    _refused_alike(["eval", model, root], capsys)
    _refused_alike(["sweep", model, root, "--max-n", "2"], capsys)
    code, out, err = _run(["eval", model, root, "-j", "2", "--skip-bad", "--json", "-q"], capsys)
    assert code == 3, err
    assert f"facetraj: 1 of 3 utterances skipped: {root / BAD}" in err
    expected = evaluate(toy_model, load_corpus(root).without(["toy001"]))
    assert json.loads(out)["table"] == json.loads(json.dumps(expected.to_json()))["table"]
    code, out, err = _run(["sweep", model, root, "--max-n", "2", "-j", "2", "--skip-bad"], capsys)
    assert code == 3 and "1 of 3 utterances skipped" in err


def test_train_with_a_bad_file(corpus_with_a_bad_file, tmp_path, capsys):
    from facetraj_engine.io.corpus import load_corpus
    from facetraj_engine.method.model import Model
    from facetraj_engine.method.training import train

    root = corpus_with_a_bad_file
    _refused_alike(["train", root, "-o", tmp_path / "m.npz"], capsys)
    assert not (tmp_path / "m.npz").exists()
    code, _, err = _run(["train", root, "-o", tmp_path / "m.npz", "-j", "2", "--skip-bad"], capsys)
    assert code == 3 and "1 of 2 utterances skipped" in err
    got = Model.load(tmp_path / "m.npz")
    want = train(load_corpus(root).without(["toy001"]))
    assert got.train_utterances == ["toy000"]
    np.testing.assert_array_equal(got.codebook.lsf, want.codebook.lsf)
    np.testing.assert_array_equal(got.pca.components, want.pca.components)


def test_report_with_a_bad_file(corpus_with_a_bad_file, tmp_path, capsys):
    root = corpus_with_a_bad_file
    out = tmp_path / "report"
    _refused_alike(["report", root, "-o", out, "--max-n", "2"], capsys)
    assert not out.exists()             # nothing written
    code, _, err = _run(["report", root, "-o", out, "--max-n", "2", "-j", "2", "--skip-bad", "-q"],
                        capsys)
    assert code == 3, err
    text = (out / "results.md").read_text()
    assert "1 utterance with bad files was left out (`--skip-bad`): `toy001`" in text
    assert json.loads((out / "results.json").read_text())["corpus"]["n_train"] == 1


def test_corpus_align_with_a_bad_recording(tmp_path, capsys):
    from conftest import DEFAULT_CORPUS

    for stem in ("s001", "s002"):
        shutil.copy(DEFAULT_CORPUS / f"{stem}.flac", tmp_path)
        shutil.copy(DEFAULT_CORPUS / f"{stem}.txt", tmp_path)
    (tmp_path / "s000.wav").write_bytes(b"RIFF\x10\x00\x00\x00WAVEfmt garbage")
    for j in ("1", "2"):
        code, _, err = _run(["corpus", "align", tmp_path, "-j", j, "-q"], capsys)
        assert code == 2 and "s000.wav: cannot read audio" in err, err
    code, _, err = _run(["corpus", "align", tmp_path, "-j", "2", "--skip-bad", "--overwrite"],
                        capsys)
    assert code == 3, err
    assert "facetraj: 1 of 3 recordings skipped: " in err and "s000.wav: cannot read" in err
    assert (tmp_path / "s001.TextGrid").is_file() and (tmp_path / "s002.TextGrid").is_file()
    assert not (tmp_path / "s000.TextGrid").exists()


def test_warnings_once_per_file_and_once_per_corpus(corpus_with_a_bad_file, toy_corpus_dir,
                                                    toy_model, tmp_path, caplog, capsys):
    """Markers shorter than the audio in two files: one warning per file, however often the
    report reads them (training, three evaluations, the sweep, the baselines, in two processes),
    and one line for the corpus with the count."""
    from facetraj_engine.io.markerfiles import read_c3d, write_c3d

    root = corpus_with_a_bad_file
    shutil.copy(toy_corpus_dir / "toy001.c3d", root)            # toy001 good again
    for utt in ("toy000", "toy030"):
        m = read_c3d(root / f"{utt}.c3d")
        write_c3d(root / f"{utt}.c3d", m.markers[:-20], m.rate, m.names)
    FILE_WARNINGS.clear()
    caplog.set_level(logging.WARNING)
    code, _, err = _run(["report", root, "-o", tmp_path / "r", "--max-n", "2", "-j", "2"], capsys)
    assert code == 0, err
    said = [r.getMessage() for r in caplog.records]
    for utt in ("toy000", "toy030"):
        hits = [m for m in said if f"{utt}.c3d: markers end at" in m]
        assert len(hits) == 1, said
        assert hits[0].endswith("later frames are treated as unseen")
    assert said.count("markers shorter than the audio (later frames are treated as unseen): "
                      "2 files") == 1


def test_corpus_show_lists_the_good_utterances_with_skip_bad(corpus_with_a_bad_file, capsys):
    root = corpus_with_a_bad_file
    code, out, err = _run(["corpus", "show", root, "--skip-bad", "-q"], capsys)
    assert code == 3 and f"1 of 3 utterances skipped: {root / BAD}" in err
    assert [ln.split()[1] for ln in out.splitlines()[2:]] == ["toy000", "toy030"]
    code, out, err = _run(["corpus", "show", root, "-q"], capsys)
    assert code == 2 and err.startswith(f"facetraj: error: {root / BAD}")


def test_a_worker_of_the_synth_batch_killed_fails_its_input_only(default_model, tmp_path,
                                                                monkeypatch):
    """facetraj synth's batch (facetraj.batch, issue 28) fans out by the same fan-out: a worker
    killed by SIGKILL while on an input is that input's failure, named, with how it stopped;
    another worker takes its place and the other inputs are synthesized."""
    from conftest import DEFAULT_CORPUS

    import facetraj.batch as batch

    src = tmp_path / "in"
    src.mkdir()
    for name in ("s001", "s002", "s003", "s004"):
        shutil.copy(DEFAULT_CORPUS / f"{name}.flac", src)
        shutil.copy(DEFAULT_CORPUS / f"{name}.TextGrid", src)
    model = default_model.save(tmp_path / "m.npz")
    real = batch.synthesize_file

    def dies_on_s002(model, audio, output, job, *args, **kwargs):
        if audio.name == "s002.flac":
            os.kill(os.getpid(), signal.SIGKILL)
        return real(model, audio, output, job, *args, **kwargs)

    monkeypatch.setattr(batch, "synthesize_file", dies_on_s002)
    code = main(["-q", "synth", str(model), str(src), "-o", str(tmp_path / "out"), "--format",
                 "tsv", "-j", "2"])
    summary = json.loads((tmp_path / "out" / batch.SUMMARY_NAME).read_text())
    status = {Path(o["input"]).name: (o["status"], o["reason"]) for o in summary["inputs"]}
    assert code != 0 and summary["done"] == 3 and summary["failed"] == 1
    assert status["s002.flac"][0] == "failed"
    assert status["s002.flac"][1].startswith("a worker process stopped unexpectedly (killed by "
                                             "signal 9")
    assert status["s002.flac"][1].endswith(f"while working on {src / 's002.flac'}; run with "
                                           f"--jobs 1 to see why")
    assert sorted((tmp_path / "out").glob("*.tsv")) == [tmp_path / "out" / f"s00{k}.tsv"
                                                        for k in (1, 3, 4)]


def test_a_worker_of_the_corpus_builder_killed_fails_its_utterance_only(tmp_path, monkeypatch):
    """The corpus builder fans out by the same fan-out (it used a process pool, broken whole by
    one dead worker): the other utterances are built, then the build stops naming the one that
    was not, and writes no corpus.json."""
    from facetraj_engine.corpusgen import build

    def fake(utt_id, out_dir, seed, config):
        if utt_id == "s002":
            os.kill(os.getpid(), signal.SIGKILL)
        (Path(out_dir) / f"{utt_id}.txt").write_text("built\n")
        return build.UtteranceResult(utt_id, 1.0, Counter(), [], 0.5, 0.0)

    monkeypatch.setattr(build, "build_utterance", fake)
    with pytest.raises(FacetrajError, match=r"1 of 4 utterances not built: a worker process "
                                            r"stopped unexpectedly \(killed by signal 9.*\) "
                                            r"while working on s002"):
        build.build_corpus(tmp_path, n_sentences=4, workers=2, check_map=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s001.txt", "s003.txt", "s004.txt"]


def _square_noting_pid(i: int) -> tuple[int, int]:
    return i * i, os.getpid()


def test_items_are_each_done_once_by_the_workers_in_order_or_as_they_finish():
    items = list(range(200))
    got = list(fan_out(_square_noting_pid, items, 3))
    assert [i for i, _ in got] == items and all(r[0] == i * i for i, r in got)
    pids = {r[1] for _, r in got}
    assert os.getpid() not in pids and 1 <= len(pids) <= 3
    unordered = list(fan_out(_square_noting_pid, items, 3, ordered=False))
    assert sorted(i for i, _ in unordered) == items


def _raises_on_3(i: int) -> int:
    if i == 3:
        raise ValueError("three")
    return i


def _forks_noted(monkeypatch) -> list[int]:
    """The pids of the processes forked from here on (``os.fork`` wrapped)."""
    pids: list[int] = []
    real = os.fork

    def fork():
        pid = real()
        if pid:
            pids.append(pid)
        return pid

    monkeypatch.setattr(os, "fork", fork)
    return pids


def _all_reaped(pids: list[int]) -> bool:
    for pid in pids:
        try:
            os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            continue                         # reaped already: what fan_out must do
        return False
    return True


def test_a_bug_in_fn_is_raised_as_it_is_and_leaves_no_child(capfd, monkeypatch):
    pids = _forks_noted(monkeypatch)
    with pytest.raises(ValueError, match="three"):
        list(fan_out(_raises_on_3, list(range(8)), 2))
    assert "ValueError: three" in capfd.readouterr().err     # the worker's traceback
    assert len(pids) >= 2 and _all_reaped(pids)


def _slow_note(path_and_i: tuple[str, int]) -> int:
    path, i = path_and_i
    with open(path, "a") as fh:
        fh.write(f"{i}\n")
    return i


@pytest.mark.parametrize("ordered", [True, False])
def test_the_workers_run_at_most_ahead_items_beyond_the_caller(tmp_path, monkeypatch, ordered):
    """The caller takes two items and stops (an error, Ctrl-C): the workers have started at most
    ``ahead`` items beyond those two, whatever the number of items (what waits for the caller
    stays bounded), none after the close; every worker is reaped."""
    pids = _forks_noted(monkeypatch)
    log_file = str(tmp_path / "started")
    items = [(log_file, i) for i in range(5000)]
    it = fan_out(_slow_note, items, 2, ordered=ordered, ahead=3)
    first = [next(it), next(it)]
    it.close()
    started = (tmp_path / "started").read_text().split()
    assert all(i in range(5000) for _, i in first)
    assert 2 <= len(started) <= 2 + 3
    assert len(pids) == 2 and _all_reaped(pids)


def test_without_fork_the_items_run_here(monkeypatch):
    """Where ``fork`` is missing (Windows), the items run in this process, by the one rule
    ``can_fork``; the set-up too."""
    from facetraj_engine import fanout

    monkeypatch.setattr(fanout, "can_fork", lambda: False)
    pids = _forks_noted(monkeypatch)
    set_up: list[int] = []
    got = list(fan_out(_square_noting_pid, [1, 2, 3], 2, setup=lambda: set_up.append(os.getpid())))
    assert got == [(i, (i * i, os.getpid())) for i in (1, 2, 3)]
    assert set_up == [os.getpid()] and pids == []


def _exits_at_setup() -> None:
    os._exit(5)


def test_a_worker_that_fails_its_set_up_is_a_clean_error(monkeypatch):
    pids = _forks_noted(monkeypatch)
    with pytest.raises(FacetrajError, match=r"a worker process stopped as it was set up "
                                            r"\(exit status 5\); run with --jobs 1"):
        list(fan_out(_square_noting_pid, [1, 2, 3], 2, setup=_exits_at_setup))
    assert _all_reaped(pids)
