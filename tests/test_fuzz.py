"""The bounded bad-input fuzz run (a few hundred seeded cases, in-process), and one test per class
of bad input that issue #14 found ending in a traceback (each now a one-line error, exit 2).

The long run is ``make fuzz`` (tests/fuzzing.py); its table is in docs/bad-input.md.
"""

from __future__ import annotations

import io
import json
import os
import signal
import stat
import struct
import zipfile
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from conftest import edited_model_file
from fuzzing import (
    CATEGORIES,
    _c3d_rate,
    cases,
    run_case,
    run_forked,
    run_in_process,
    table,
)

from facetraj_engine.errors import InputError
from facetraj_engine.io.files import atomic_write
from facetraj.cli import main

N_CASES = 420


@pytest.fixture(scope="module")
def workspace(fuzz_workspace):
    return fuzz_workspace


#: the in-process run's categories: the app's are driven by tests/test_app_bad_input.py
IN_PROCESS = tuple(c for c in CATEGORIES if c != "app")


def test_bounded_fuzz_run(workspace):
    """Seeded mutated inputs of every category but the app's: no traceback, exit 0 or 2 with one
    error line (or 3 with a summary for --skip-bad), the same with -j 1 and -j 2, nothing partial
    or clobbered, no NaN written, label files in other alphabets synthesized."""
    here = sorted(os.listdir("."))
    workspace.quick = True
    outcomes = [run_case(c, run_in_process) for c in cases(workspace, N_CASES, 1, IN_PROCESS)]
    assert sorted(os.listdir(".")) == here, "a case wrote outside its own folder"
    report = table(outcomes)
    failures = [f"[{o.case.category}] {o.case.name}: {o.status} {o.detail}\n  facetraj "
                f"{' '.join(o.case.argv)}" for o in outcomes if o.failed]
    assert not failures, "\n".join(failures) + "\n" + report
    seen = {o.case.category for o in outcomes}
    assert seen == set(IN_PROCESS)
    # the run exercised both outcomes: real refusals and real successes
    assert sum(o.status == "refused" for o in outcomes) > N_CASES // 3
    assert sum(o.status == "ok" for o in outcomes) > 20


def test_forked_run_limits_memory_and_time(workspace):
    """The long run's forked mode on a few cases: same verdicts, memory measured."""
    some = list(cases(workspace, 14, 5, IN_PROCESS))
    for case in some:
        o = run_forked(case, timeout=120)
        assert not o.failed, (o.status, o.detail, case.argv)
        assert 0 < o.max_rss and o.grown < 2 << 30


# --------------------------------------------------------------------------- the classes of #14
def run(argv: list[str], capsys) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    return code, err


def refused(argv, capsys, *phrases) -> str:
    code, err = run(argv, capsys)
    assert code == 2, err
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ": error: " in ln]
    assert len(lines) == 1, err
    for phrase in phrases:
        assert phrase in lines[0], lines[0]
    return lines[0]


def test_huge_audio_samples_synthesize(workspace, tmp_path, capsys):
    x, rate = sf.read(workspace.wav)
    for scale in (1e154, 1e300):
        sf.write(tmp_path / "big.wav", x * scale, rate, subtype="DOUBLE")
        code, err = run(["synth", workspace.model, tmp_path / "big.wav", "-o",
                         tmp_path / f"o{scale:.0e}.tsv"], capsys)
        assert code == 0, err
        assert b"nan" not in (tmp_path / f"o{scale:.0e}.tsv").read_bytes().lower()


@pytest.mark.parametrize("meta, phrase", [
    ([], "metadata is not a JSON object"),
    ({"version": None}, "version is None"),
    ({"marker_rate": "60"}, "'marker_rate' is '60', not a positive number"),
    ({"phones": "aa"}, "'phones' is 'aa', not a list of distinct names"),
    ({"upper_lip": 999}, "'upper_lip' is 999"),
])
def test_model_meta_is_checked(workspace, tmp_path, capsys, meta, phrase):
    with np.load(workspace.model) as z:
        old = json.loads(str(z["meta"]))
    new = meta if isinstance(meta, list) else {**old, **meta}
    bad = edited_model_file(workspace.model, tmp_path / "m.npz", meta=np.array(json.dumps(new)))
    refused(["synth", bad, workspace.wav, "-o", tmp_path / "o.tsv"], capsys, str(bad), phrase)


@pytest.mark.parametrize("name, value, phrase", [
    ("cb_lsf", lambda a: a[:, :-1], "array 'cb_lsf' has shape"),
    ("pca_components", lambda a: a.astype(np.complex64), "has data type complex64"),
    ("means", lambda a: np.full_like(a, np.nan), "array 'means' holds NaN"),
    ("pca_mean", lambda a: np.full_like(a, np.nan), "array 'pca_mean' holds NaN"),
    ("fixed", lambda a: a + 1000, "array 'fixed' holds indices outside"),
])
def test_model_arrays_are_checked(workspace, tmp_path, capsys, name, value, phrase):
    with np.load(workspace.model) as z:
        arr = z[name]
    bad = edited_model_file(workspace.model, tmp_path / "m.npz", **{name: value(arr)})
    refused(["synth", bad, workspace.wav, "-o", tmp_path / "o.tsv"], capsys, phrase)
    assert not (tmp_path / "o.tsv").exists()


def _rezip(src: Path, dst: Path, edit) -> Path:
    with zipfile.ZipFile(src) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    edit(members)
    with zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zf:
        for k, v in members.items():
            zf.writestr(k, v)
    return dst


def test_model_npy_header_asking_for_terabytes(workspace, tmp_path, capsys):
    def edit(m):
        hdr = "{'descr': '<f8', 'fortran_order': False, 'shape': (1099511627776, 20), }"
        hdr = hdr.ljust(117) + "\n"
        m["cb_lsf.npy"] = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(hdr)) + hdr.encode()
    bad = _rezip(workspace.model, tmp_path / "m.npz", edit)
    refused(["similarity", bad], capsys, "entry 'cb_lsf' asks for", "more than a model holds")


def test_model_compression_and_deflate(workspace, tmp_path, capsys):
    good = _rezip(workspace.model, tmp_path / "deflated.npz", lambda m: None)
    data = bytearray(good.read_bytes())
    for sig, off in ((b"PK\x03\x04", 8), (b"PK\x01\x02", 10)):
        i = data.find(sig)
        while i >= 0:
            data[i + off:i + off + 2] = struct.pack("<H", 12)   # bzip2
            i = data.find(sig, i + 4)
    (tmp_path / "bz.npz").write_bytes(bytes(data))
    refused(["similarity", tmp_path / "bz.npz"], capsys, "unsupported compression method (12)")
    broken = bytearray(good.read_bytes())
    start = broken.find(b"PK\x03\x04", 10) - 300   # inside the first member's deflate stream
    broken[start:start + 40] = b"\xff" * 40
    (tmp_path / "broken.npz").write_bytes(bytes(broken))
    refused(["similarity", tmp_path / "broken.npz"], capsys, "not a readable facetraj model")


@pytest.mark.parametrize("argv, phrase", [
    (["-N", "0"], "-N/--n-context-phones: expected a whole number from 1"),
    (["-N", "-1"], "expected a whole number from 1"),
    (["--xi", "0"], "--xi: expected a number in [1, "),
    (["--xi", "nan"], "--xi: expected a number in"),
    (["--xi", "-20"], "--xi: expected a number in"),
])
def test_synth_options_ranges(workspace, tmp_path, capsys, argv, phrase):
    with pytest.raises(SystemExit) as exc:
        main(["synth", str(workspace.model), str(workspace.wav), "-o", str(tmp_path / "o.tsv"),
              *argv])
    assert exc.value.code == 2
    assert phrase in capsys.readouterr().err


@pytest.mark.parametrize("argv, phrase", [
    (["--lpc-order", "0"], "--lpc-order: expected a whole number from 2 to 64"),
    (["--context", "-1"], "--context: expected a whole number from 0 to 10"),
    (["--codewords-per-phone", "0"], "expected a whole number from 1 to 100"),
    (["--max-gap-s", "inf"], "--max-gap-s: expected a number in [0, 10]"),
    (["--index-cells", "-5"], "--index-cells: expected a whole number from 1"),
])
def test_train_options_ranges(workspace, tmp_path, capsys, argv, phrase):
    with pytest.raises(SystemExit) as exc:
        main(["train", str(workspace.corpus), "-o", str(tmp_path / "m.npz"), *argv])
    assert exc.value.code == 2
    assert phrase in capsys.readouterr().err


def test_verbosity_after_the_subcommand(workspace, tmp_path, capsys):
    code, err = run(["synth", workspace.model, workspace.wav, "-o", tmp_path / "o.tsv", "-q"],
                    capsys)
    assert code == 0 and "INFO" not in err


def _corpus_copy(workspace, tmp_path) -> Path:
    import shutil

    dst = tmp_path / "corpus"
    shutil.copytree(workspace.corpus, dst)
    return dst


@pytest.mark.parametrize("edit, phrase", [
    (lambda o: [], "a JSON list, not an object"),
    (lambda o: {**o, "marker_rate": 0}, "'marker_rate' is 0, not a number of frames per second"),
    (lambda o: {**o, "train": "toy000"}, "'train' is \"toy000\", not a list"),
    (lambda o: {**o, "upper_lip": 5}, "'upper_lip' is 5, not a marker name"),
    (lambda o: {**o, "data_dir": "nowhere"}, "its data folder 'nowhere'"),
    (lambda o: json.loads("[" * 50 + "]" * 50), "not an object"),
])
def test_corpus_json_schema(workspace, tmp_path, capsys, edit, phrase):
    corpus = _corpus_copy(workspace, tmp_path)
    obj = json.loads((corpus / "corpus.json").read_text())
    (corpus / "corpus.json").write_text(json.dumps(edit(obj)))
    refused(["corpus", "show", corpus], capsys, "corpus.json", phrase)


def test_corpus_json_nested_too_deeply(workspace, tmp_path, capsys):
    corpus = _corpus_copy(workspace, tmp_path)
    (corpus / "corpus.json").write_text("[" * 100000 + "]" * 100000)
    refused(["corpus", "show", corpus], capsys, "nested too deeply")


def test_transcript_not_utf8(workspace, tmp_path, capsys):
    corpus = _corpus_copy(workspace, tmp_path)
    (corpus / "toy030.txt").write_bytes(b"caf\xe9")
    refused(["corpus", "show", corpus], capsys, "toy030.txt: the transcript is not UTF-8 text")


def test_two_frame_c3d_in_the_test_split_evaluates(workspace, tmp_path, capsys):
    from facetraj_engine.io.markerfiles import read_c3d, write_c3d

    corpus = _corpus_copy(workspace, tmp_path)
    m = read_c3d(corpus / "toy030.c3d")
    write_c3d(corpus / "toy030.c3d", m.markers[:2], m.rate, m.names)
    code, err = run(["eval", workspace.model, corpus, "--split", "test"], capsys)
    assert code == 0, err


@pytest.mark.parametrize("rate", [1e6, 0.001])
def test_absurd_c3d_rates(workspace, tmp_path, capsys, rate):
    corpus = _corpus_copy(workspace, tmp_path)
    (corpus / "toy030.c3d").write_bytes(_c3d_rate((corpus / "toy030.c3d").read_bytes(), rate))
    refused(["corpus", "show", corpus], capsys, "toy030.c3d", "is outside 1-10000 Hz")


def test_c3d_parameter_block_damage_is_bounded(workspace, tmp_path):
    """Four random bytes in the parameter section: refused or read, never gigabytes (forked)."""
    from fuzzing import Case

    corpus = _corpus_copy(workspace, tmp_path)
    src = (corpus / "toy030.c3d").read_bytes()
    rng = np.random.default_rng(3)
    for k in range(6):
        d = bytearray(src)
        for i in rng.integers(512, 512 * (src[16] - 1), 4):
            d[i] = int(rng.integers(256))
        (corpus / "toy030.c3d").write_bytes(bytes(d))
        o = run_forked(Case("c3d", f"params {k}", ["corpus", "show", str(corpus), "-q"],
                            cwd=tmp_path), timeout=60)
        assert not o.failed, (o.status, o.detail)
        assert o.grown < 1 << 30, o.grown     # the child's own growth, not pytest's pages


def test_output_errors(workspace, tmp_path, capsys):
    base = ["synth", workspace.model, workspace.wav, "-o"]
    (tmp_path / "folder.tsv").mkdir()
    refused([*base, tmp_path / "folder.tsv", "--overwrite"], capsys, "a folder is at this path")
    (tmp_path / "file").write_text("x")
    refused([*base, tmp_path / "file" / "o.tsv"], capsys, "is a file, not a folder")
    refused([*base, tmp_path / ("x" * 300 + ".tsv")], capsys, "the file name is too long")
    refused(["train", workspace.corpus, "-o", tmp_path / "file"], capsys,
            "already exists; choose to overwrite it")
    assert (tmp_path / "file").read_text() == "x"


def test_unwritable_and_read_only(tmp_path, monkeypatch):
    import errno
    import tempfile

    def refuse(*a, **k):
        raise OSError(errno.EROFS, "Read-only file system")
    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(InputError, match="o.tsv: cannot be written \\(the file system is read-only\\)"):
        with atomic_write(tmp_path / "o.tsv"):
            pass
    monkeypatch.setattr(os, "access", lambda *a: False)
    with pytest.raises(InputError, match="no permission to write in"):
        with atomic_write(tmp_path / "o.tsv"):
            pass


def test_labels_and_label_map_given_as_folders(workspace, tmp_path, capsys):
    (tmp_path / "l.TextGrid").mkdir()
    refused(["synth", workspace.model, workspace.wav, "--labels", tmp_path / "l.TextGrid", "-o",
             tmp_path / "o.tsv"], capsys, "is a folder, not a file")
    (tmp_path / "map").mkdir()
    refused(["synth", workspace.model, workspace.wav, "--labels", workspace.textgrid,
             "--label-map", tmp_path / "map", "-o", tmp_path / "o.tsv"], capsys,
            "is a folder, not a label map file")


def test_corpus_init_needs_overwrite(workspace, tmp_path, capsys):
    corpus = _corpus_copy(workspace, tmp_path)
    before = (corpus / "corpus.json").read_bytes()
    argv = ["corpus", "init", corpus, "--fixed", "FH_L", "FH_R", "NB", "NT", "--upper-lip",
            "UL_C", "--lower-lip", "LL_C"]
    refused(argv, capsys, "already exists")
    assert (corpus / "corpus.json").read_bytes() == before
    code, err = run([*argv, "--overwrite"], capsys)
    assert code == 0, err


def test_train_checks_output_before_training(workspace, tmp_path, capsys, monkeypatch):
    import facetraj_engine.method.training

    (tmp_path / "m.npz").write_bytes(b"mine")
    monkeypatch.setattr(facetraj_engine.method.training, "train", lambda *a, **k: pytest.fail("trained"))
    refused(["train", workspace.corpus, "-o", tmp_path / "m.npz"], capsys, "already exists")


def test_output_modes_follow_umask_and_old_file(tmp_path):
    old = os.umask(0o022)
    try:
        with atomic_write(tmp_path / "new.txt") as tmp:
            tmp.write_text("a")
        assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o644
        os.umask(0o077)
        with atomic_write(tmp_path / "new2.txt") as tmp:
            tmp.write_text("a")
        assert stat.S_IMODE((tmp_path / "new2.txt").stat().st_mode) == 0o600
        os.chmod(tmp_path / "new.txt", 0o664)
        with atomic_write(tmp_path / "new.txt") as tmp:
            tmp.write_text("b")
        assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o664
    finally:
        os.umask(old)


def test_sigterm_during_a_write_removes_the_part_file(tmp_path):
    out = tmp_path / "o.txt"
    out.write_text("old")
    with pytest.raises(SystemExit) as exc, atomic_write(out) as tmp:
        tmp.write_text("half")
        os.kill(os.getpid(), signal.SIGTERM)
    assert exc.value.code == 128 + signal.SIGTERM
    assert out.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["o.txt"]
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL


def test_label_map_to_unknown_phone_blames_the_map(workspace, tmp_path, capsys):
    from facetraj_engine.io.labelfiles import read_labels

    first = next(s.label for s in read_labels(workspace.textgrid) if s.label != "sil")
    (tmp_path / "map.tsv").write_text(f"{first}\tzz\n")
    line = refused(["synth", workspace.model, workspace.wav, "--labels", workspace.textgrid,
                    "--label-map", tmp_path / "map.tsv", "-o", tmp_path / "o.tsv"], capsys,
                   f"map.tsv: maps '{first}'", "to 'zz', which is not in the model")
    assert not line.split(": error: ")[1].startswith(str(workspace.textgrid))


def test_audio_too_short_blames_the_audio(workspace, tmp_path, capsys):
    x, rate = sf.read(workspace.wav)
    sf.write(tmp_path / "short.wav", x[:100], rate)
    refused(["synth", workspace.model, tmp_path / "short.wav", "--labels", workspace.textgrid,
             "-o", tmp_path / "o.tsv"], capsys, "short.wav: the audio is too short")


def test_empty_phone_tier_holds_no_segments(workspace, tmp_path, capsys):
    text = workspace.textgrid.read_text()
    head = text[: text.index("intervals: size")]
    (tmp_path / "e.TextGrid").write_text(head + "intervals: size = 0\n")
    refused(["synth", workspace.model, workspace.wav, "--labels", tmp_path / "e.TextGrid", "-o",
             tmp_path / "o.tsv"], capsys, "the label file holds no segments")


def _swap_first_intervals(text: str, overlap: bool) -> str:
    import re

    blocks = re.split(r"(?=\n\s*intervals \[\d+\]:)", text)
    if overlap:  # the second interval starts before the first ends
        m = re.search(r"(intervals \[2\]:\s*\n\s*xmin = )([0-9.]+)", text)
        return text[: m.start(2)] + "0.001" + text[m.end(2):]
    return blocks[0] + blocks[2] + blocks[1] + "".join(blocks[3:])


@pytest.mark.parametrize("overlap", [True, False])
def test_textgrid_overlap_and_order_in_one_line(workspace, tmp_path, capsys, overlap):
    (tmp_path / "b.TextGrid").write_text(_swap_first_intervals(workspace.textgrid.read_text(),
                                                               overlap))
    refused(["synth", workspace.model, workspace.wav, "--labels", tmp_path / "b.TextGrid", "-o",
             tmp_path / "o.tsv"], capsys, "overlaps or precedes the one before")


def test_lab_with_an_inf_time(workspace, tmp_path, capsys):
    lines = workspace.lab.read_text().splitlines()
    lines[1] = "inf " + lines[1].split(" ", 1)[1]
    (tmp_path / "i.lab").write_text("\n".join(lines) + "\n")
    refused(["synth", workspace.model, workspace.wav, "--labels", tmp_path / "i.lab", "-o",
             tmp_path / "o.tsv"], capsys, "segment 2 has a time that is not a finite number")


def test_marker_names_that_differ_are_named(workspace, tmp_path, capsys):
    from facetraj_engine.io.markerfiles import read_c3d, write_c3d

    corpus = _corpus_copy(workspace, tmp_path)
    m = read_c3d(corpus / "toy030.c3d")
    write_c3d(corpus / "toy030.c3d", m.markers, m.rate, ["JAW_X" if n == "CHIN" else n
                                                          for n in m.names])
    refused(["corpus", "show", corpus], capsys, "'CHIN' missing", "'JAW_X' not expected")


def test_c3d_reader_advice_is_not_shown(workspace, tmp_path):
    """ezc3d's own refusal (a flag bit in the parameter section, found by the fuzz run) is shown
    without its advice to set ignoreBadFormatting, which a user cannot."""
    from facetraj_engine.io.markerfiles import read_c3d

    data = bytearray(workspace.c3d.read_bytes())
    data[553] ^= 1
    (tmp_path / "x.c3d").write_bytes(bytes(data))
    with pytest.raises(InputError) as exc:
        read_c3d(tmp_path / "x.c3d")
    assert str(exc.value).endswith("not a readable C3D file (The format is not standard)")


def test_error_messages_are_one_line():
    assert str(InputError("a.txt", "first\n  second")) == "a.txt: first second"


def test_fuzz_table_counts(workspace):
    outcomes = [run_in_process(c) for c in cases(workspace, 7, 9, IN_PROCESS)]
    text = table(outcomes)
    assert text.splitlines()[-1].startswith("| **all** | 7 |")
    assert io.StringIO(text).read().count("\n") == 2 + len({o.case.category for o in outcomes})


# --------------------------------------------------------------------------- sizes (issue #26)
def _flac_claiming(src: Path, dst: Path, total: int) -> Path:
    """``src`` (a FLAC) with STREAMINFO's 36-bit total sample count set to ``total``."""
    d = bytearray(src.read_bytes())
    off = 8 + 10 + 3             # 'fLaC', the block header, then 10 bytes before rate/ch/bps/total
    d[off] = (d[off] & 0xF0) | ((total >> 32) & 0x0F)
    d[off + 1:off + 5] = struct.pack(">I", total & 0xFFFFFFFF)
    dst.write_bytes(bytes(d))
    return dst


def test_audio_header_claiming_too_much_is_refused_before_allocating(workspace, tmp_path):
    """A FLAC whose header claims 2^36 samples (550 GB as float64): refused with the count, the
    forked run staying far below the memory limit; a WAV whose data size field is damaged reads
    the samples the file holds."""
    from fuzzing import Case

    from facetraj_engine.io.audio import read_audio

    x, rate = sf.read(workspace.wav)
    sf.write(tmp_path / "a.flac", x, rate)
    bad = _flac_claiming(tmp_path / "a.flac", tmp_path / "bad.flac", 2**36 - 1)
    with pytest.raises(InputError, match="bad.flac: the header says it holds 68719476735 samples"):
        read_audio(bad)
    o = run_forked(Case("audio", "huge FLAC header", ["synth", str(workspace.model), str(bad), "-o",
                                                      str(tmp_path / "o.tsv"), "-q"],
                        cwd=tmp_path), timeout=60)
    # the child starts with this process's pages (pytest's, Qt's, ...): only its growth is its own
    assert o.status == "refused" and 0 < o.max_rss and o.grown < 256 << 20, (o.status, o.grown)
    data = bytearray(workspace.wav.read_bytes())
    i = data.find(b"data")
    data[i + 4:i + 8] = struct.pack("<I", 0xFFFFFFF0)
    (tmp_path / "size.wav").write_bytes(bytes(data))
    np.testing.assert_array_equal(read_audio(tmp_path / "size.wav")[0], read_audio(workspace.wav)[0])


def test_multichannel_audio_is_mixed_down_block_by_block(tmp_path, monkeypatch):
    """Mixed down as the mean of the channels, the same as all at once, over several blocks."""
    import facetraj_engine.io.audio as audio

    rng = np.random.default_rng(4)
    x = rng.uniform(-0.5, 0.5, (50000, 3))
    sf.write(tmp_path / "c.wav", x, 16000, subtype="DOUBLE")
    monkeypatch.setattr(audio, "_BLOCK_SAMPLES", 3 * 7001)        # 8 blocks, the last short
    samples, rate = audio.read_audio(tmp_path / "c.wav")
    assert rate == 16000
    np.testing.assert_array_equal(samples, x.mean(axis=1))


def test_oversized_text_and_est_headers_are_refused(tmp_path):
    from facetraj_engine.io.files import MAX_TEXT_BYTES
    from facetraj_engine.io.labelfiles import read_labels
    from facetraj_engine.io.markerfiles import read_mocha_ema

    big = tmp_path / "big.lab"
    with open(big, "wb") as fh:
        fh.truncate(MAX_TEXT_BYTES + 1)     # sparse: nothing is written
    with pytest.raises(InputError, match="more than facetraj reads as a label file"):
        read_labels(big)
    (tmp_path / "e.ema").write_bytes(b"EST_File Track\nDataType binary\nNumFrames -5\n"
                                     b"NumChannels 3\nEST_Header_End\n" + b"\0" * 64)
    with pytest.raises(InputError, match="EST header gives -5 frames of 3 channels"):
        read_mocha_ema(tmp_path / "e.ema")


def test_corpus_init_with_a_tiny_test_fraction(workspace, tmp_path, capsys):
    """--test-fraction=1e-320 ended in an OverflowError (found by make fuzz): no test utterance."""
    corpus = _corpus_copy(workspace, tmp_path)
    code, err = run(["corpus", "init", corpus, "--fixed", "FH_L", "FH_R", "NB", "NT", "--upper-lip",
                     "UL_C", "--lower-lip", "LL_C", "-o", tmp_path / "d.json",
                     "--test-fraction=1e-320"], capsys)
    assert code == 0, err
    assert json.loads((tmp_path / "d.json").read_text())["test"] == []
