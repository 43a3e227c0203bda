"""The bad-input fuzz suite: seeded, mutated inputs run through the ``facetraj`` command line.

Each case mutates one input (audio, labels, a model file, corpus.json, a C3D file, an option
value, an output path) of a command that works on the unmutated inputs, runs the command and
checks the README's promise: no traceback, exit status 0 or 2, an error as one line
``facetraj: error: <file>: <problem>``, no output left at the output path after a failure, no
``.part`` file, nothing the user had is changed without ``--overwrite``, no NaN in a written
trajectory, no hang, no run above :data:`MEMORY_LIMIT`.

``tests/test_fuzz.py`` runs a few hundred cases in-process (``facetraj.cli.main``) under a
minute; ``make fuzz`` (``python tests/fuzzing.py``) runs thousands, each in a forked child with
an address-space limit (``resource.setrlimit``) and a timeout, and prints a table per category.
Option cases are built from the parser itself (every option of every subcommand with a
``type``), so new commands are covered as they are added.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import json
import os
import random
import resource
import shutil
import signal
import struct
import sys
import time
import traceback
import zipfile
from collections import Counter, defaultdict
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

#: Address-space limit above the parent's own size for each forked run, and the RSS ceiling.
MEMORY_LIMIT = 2 << 30
#: Seconds a forked run may take before it counts as a hang.
TIMEOUT_S = 60.0
#: Commands whose runs open windows or render (only their option parsing is fuzzed).
PARSE_ONLY = {"gui", "report", "video", "build", None}
BAD_NUMBERS = ["0", "-1", "-20", "nan", "inf", "-inf", "1e309", "1e-320", "abc", "", "3.5",
               "99999999999999999999", "0x10", "1e6", "-0", "1e-9", "2"]

CATEGORIES = ("audio", "damaged", "labels", "model", "corpus", "c3d", "markers", "articulograph",
              "options", "output", "fanout", "alphabet", "app")
#: Exit status of a corpus-wide command that left bad files out (--skip-bad): allowed only there.
EXIT_INCOMPLETE = 3


@dataclass
class Case:
    """One fuzz run: ``argv`` for ``facetraj``, the files it must not change, its output path."""

    category: str
    name: str
    argv: list[str]
    protected: dict[Path, tuple[str, int]] = field(default_factory=dict)  # sha256, mode
    output: Path | None = None
    parse_only: bool = False
    keep_mode: int | None = None   # the mode an overwritten output must keep
    cwd: Path | None = None        # where it runs (relative output paths land there)
    skip_bad: bool = False         # --skip-bad given: exit 3 with a summary is allowed
    expect_ok: bool = False        # valid input (a label file in another alphabet): must exit 0
    serial_argv: list[str] | None = None   # the same with -j 1: must end the same way
    app: list[str] | None = None   # an app case: what the window opens (tests/fuzz_app.py)
    blame: list[Path] = field(default_factory=list)   # damaged inputs: refused, each named
    summary: Path | None = None    # a batch's synth-summary.json: the blamed inputs failed there


@dataclass
class Outcome:
    case: Case
    status: str          # ok (exit 0), refused (exit 2), or a failure: traceback, hang, ...
    code: int
    detail: str = ""
    seconds: float = 0.0
    max_rss: int = 0
    error_line: str = ""   # the error (exit 2) or the skip summary (exit 3), for -j 1 vs -j 2
    rss_at_fork: int = 0   # a forked child starts with its parent's pages: they are not its own

    @property
    def grown(self) -> int:
        """The peak resident size the case itself added (bytes): ``max_rss`` less the fork's start."""
        return max(0, self.max_rss - self.rss_at_fork)

    @property
    def failed(self) -> bool:
        return self.status not in ("ok", "refused", "skipped bad files")


# --------------------------------------------------------------------------- the workspace
@dataclass
class Workspace:
    """Valid inputs every case starts from: a small corpus, a model trained on it, audio, labels."""

    root: Path
    corpus: Path
    model: Path
    wav: Path
    textgrid: Path
    lab: Path
    c3d: Path
    n: int = 0
    current: Path | None = None    # the folder of the case being made
    quick: bool = False            # in-process runs: corpus-wide commands of a second or less

    def fresh(self, name: str) -> Path:
        """A new empty folder for one case."""
        self.n += 1
        d = self.root / "cases" / f"{self.n:05d}-{name}"
        d.mkdir(parents=True)
        self.current = d
        return d


def make_workspace(root: Path, toy_dir: Path | None = None, model_path: Path | None = None
                   ) -> Workspace:
    """A small corpus (3 utterances of the toy corpus) and a model trained on it, in ``root``."""
    from facetraj_engine.io.corpus import CorpusInfo, load_corpus, save_corpus_info
    from facetraj_engine.io.labelfiles import read_labels

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    if toy_dir is None:
        from toycorpus import build_toy_corpus

        toy_dir = build_toy_corpus(root / "toy")
    corpus = root / "corpus"
    corpus.mkdir(parents=True, exist_ok=True)
    ids = ["toy000", "toy001", "toy030"]
    for utt in ids:
        for ext in ("wav", "TextGrid", "c3d"):
            shutil.copy(toy_dir / f"{utt}.{ext}", corpus / f"{utt}.{ext}")
    info = load_corpus(toy_dir).info
    save_corpus_info(corpus, CorpusInfo(**{**info.__dict__, "train": ids[:2], "test": ids[2:]}))
    model = root / "model.npz"
    if model_path is not None:
        shutil.copy(model_path, model)
    else:
        from facetraj_engine.method.training import train

        train(load_corpus(toy_dir)).save(model)
    lab = root / "toy030.lab"
    segs = read_labels(corpus / "toy030.TextGrid")
    lab.write_text("".join(f"{s.start:.4f} {s.end:.4f} {s.label}\n" for s in segs))
    (root / "toy030.phn").write_text("".join(f"{round(s.start * 16000)} {round(s.end * 16000)} "
                                             f"{s.label}\n" for s in segs))
    return Workspace(root, corpus, model, corpus / "toy030.wav", corpus / "toy030.TextGrid", lab,
                     corpus / "toy030.c3d")


# --------------------------------------------------------------------------- byte mutations
def mutate_bytes(rng: random.Random, data: bytes, start: int = 0,
                 end: int | None = None) -> tuple[bytes, str]:
    """A random damage: truncation, bit flips, random bytes, a zeroed or repeated block."""
    end = len(data) if end is None else min(end, len(data))
    start = min(start, max(end - 1, 0))
    d = bytearray(data)
    kind = rng.choice(["truncate", "flip", "bytes", "zero", "ff", "insert", "delete", "empty"])
    if kind == "truncate":
        d = d[: rng.randrange(0, max(len(d), 1))]
    elif kind == "empty":
        d = bytearray()
    elif kind in ("flip", "bytes"):
        for _ in range(rng.choice([1, 2, 4, 8, 32])):
            i = rng.randrange(start, max(end, start + 1))
            if i < len(d):
                d[i] = d[i] ^ (1 << rng.randrange(8)) if kind == "flip" else rng.randrange(256)
    elif kind in ("zero", "ff"):
        i = rng.randrange(start, max(end, start + 1))
        n = rng.choice([2, 4, 16, 128])
        d[i:i + n] = (b"\0" if kind == "zero" else b"\xff") * len(d[i:i + n])
    elif kind == "insert":
        i = rng.randrange(start, max(end, start + 1))
        d[i:i] = bytes(rng.randrange(256) for _ in range(rng.choice([1, 3, 64])))
    else:
        i = rng.randrange(start, max(end, start + 1))
        del d[i:i + rng.choice([1, 4, 100])]
    return bytes(d), kind


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _protect(*paths: Path) -> dict[Path, tuple[str, int]]:
    """Files a case must leave as they are: their digests and modes."""
    return {p: (_digest(p), p.stat().st_mode) for p in paths if p.is_file()}


def _synth_argv(ws: Workspace, model: Path, audio: Path, out: Path, labels: Path | None = None,
                extra: list[str] | None = None) -> list[str]:
    argv = ["synth", str(model), str(audio), "-o", str(out), "-q"]
    if labels is not None:
        argv += ["--labels", str(labels)]
    return argv + (extra or [])


# --------------------------------------------------------------------------- audio
def audio_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    import numpy as np
    import soundfile as sf

    samples, rate = sf.read(str(ws.wav), dtype="float64")
    while True:
        d = ws.fresh("audio")
        kind = rng.choice(["bytes", "bytes", "huge", "nan", "rate", "channels", "format", "short",
                           "silence", "clip"])
        path = d / "in.wav"
        if kind == "bytes":
            data, how = mutate_bytes(rng, ws.wav.read_bytes(), 0, rng.choice([64, 2000, None]))
            path.write_bytes(data)
            name = f"damaged ({how})"
        elif kind == "huge":
            scale = 10.0 ** rng.choice([10, 100, 154, 200, 300, 307, 308])
            x = samples * scale if rng.random() < 0.5 else np.where(
                np.arange(len(samples)) == rng.randrange(len(samples)), scale, samples)
            sf.write(str(path), x, rate, subtype="DOUBLE")
            name = f"huge samples {scale:.0e}"
        elif kind == "nan":
            x = samples.copy()
            x[rng.randrange(len(x))] = rng.choice([np.nan, np.inf, -np.inf])
            sf.write(str(path), x, rate, subtype="FLOAT")
            name = "NaN or inf sample"
        elif kind == "rate":
            r = rng.choice([1, 100, 7999, 8000, 11025, 44100, 96000, 192000, 384000, 655350])
            sf.write(str(path), samples[: rng.choice([10, 1000, len(samples)])], r)
            name = f"rate {r} Hz"
        elif kind == "channels":
            ch = rng.choice([2, 6, 64])
            sf.write(str(path), np.repeat(samples[:, None], ch, axis=1), rate)
            name = f"{ch} channels"
        elif kind == "format":
            path = d / rng.choice(["in.flac", "in.WAV", "in.ogg", "in.txt", "in"])
            sf.write(str(path), samples, rate, format="FLAC") if path.suffix == ".flac" else \
                path.write_bytes(ws.wav.read_bytes())
            name = f"file named {path.name}"
        elif kind == "short":
            n = rng.choice([0, 1, 10, 100, 500, 1000])
            sf.write(str(path), samples[:n], rate)
            name = f"{n} samples"
        elif kind == "silence":
            sf.write(str(path), np.zeros(len(samples)), rate)
            name = "silence"
        else:
            sf.write(str(path), np.clip(samples * 1e4, -1, 1), rate)
            name = "clipped"
        labels = ws.textgrid if rng.random() < 0.3 and kind not in ("short", "rate") else None
        out = d / "out.tsv"
        yield Case("audio", name, _synth_argv(ws, ws.model, path, out, labels),
                   _protect(ws.model, ws.textgrid), out)


# --------------------------------------------------------------------------- damaged audio
def damaged_wav(rng: random.Random, wav: bytes) -> tuple[bytes, str]:
    """``wav`` (16-bit PCM, the 44-byte header) cut short or with a header that no longer matches
    its data: every one a file facetraj must refuse, naming it (issue 38)."""
    kind = rng.choice(["cut", "cut", "data size", "riff size", "fmt field", "chunk id", "rate"])
    if kind == "cut":
        n = rng.randrange(1, len(wav) - 45)
        return wav[:len(wav) - n], f"cut short by {n} bytes"
    m = bytearray(wav)
    if kind == "data size":
        size = struct.unpack("<I", wav[40:44])[0]
        new = size + rng.choice([-1, 1]) * 2 * rng.randrange(4, 1000)
        m[40:44] = struct.pack("<I", max(0, min(new, 0xFFFFFFFE)) or 2)
        return bytes(m), f"data size {size} -> {struct.unpack('<I', m[40:44])[0]}"
    if kind == "riff size":
        size = struct.unpack("<I", wav[4:8])[0]
        m[4:8] = struct.pack("<I", max(1, size + rng.choice([-1, 1]) * rng.randrange(2, 5000)))
        return bytes(m), f"RIFF size {size} -> {struct.unpack('<I', m[4:8])[0]}"
    if kind == "rate":                  # a header right in itself but for the rate (issue 46)
        rate = struct.unpack("<I", wav[24:28])[0]
        block = struct.unpack("<H", wav[32:34])[0]
        new_rate = rng.choice([rate // 2, rate * 2])
        m[24:32] = struct.pack("<II", new_rate, new_rate * block)
        return bytes(m), f"rate {rate} -> {new_rate} Hz, the byte rate with it"
    if kind == "fmt field":
        at, what, values = rng.choice([(22, "channels", [0, 2, 3, 255]), (24, "rate", [8000, 44100, 7]),
                                       (28, "byte rate", [1, 32001, 64000]),
                                       (32, "block align", [1, 3, 4]), (34, "bits", [8, 24, 32, 5])])
        width = 4 if what in ("rate", "byte rate") else 2
        m[at:at + width] = struct.pack("<I" if width == 4 else "<H", rng.choice(values))
        return bytes(m), f"{what} -> {struct.unpack('<I' if width == 4 else '<H', m[at:at + width])[0]}"
    m[36:40] = bytes(rng.randrange(256) for _ in range(4))
    return bytes(m), f"data chunk id {bytes(m[36:40])!r}"


def damaged_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    """Truncated and header-damaged WAVs, each with its labels beside it (which must not be
    blamed), through ``synth`` one at a time or as a batch beside an undamaged one (which is
    done, and no damaged one counted as done)."""
    wav = ws.wav.read_bytes()
    while True:
        d = ws.fresh("damaged")
        folder = d / "in"
        folder.mkdir()
        blame, hows = [], []
        for k in range(rng.choice([1, 1, 2, 3])):
            data, how = damaged_wav(rng, wav)
            (folder / f"r{k}.wav").write_bytes(data)
            shutil.copy(ws.textgrid, folder / f"r{k}.TextGrid")
            blame.append(folder / f"r{k}.wav")
            hows.append(how)
        if rng.random() < 0.5:
            out = d / "out.tsv"
            yield Case("damaged", f"one: {hows[0]}", _synth_argv(ws, ws.model, blame[0], out),
                       _protect(ws.model, *blame), out, blame=blame[:1])
            continue
        shutil.copy(ws.wav, folder / "good.wav")
        shutil.copy(ws.textgrid, folder / "good.TextGrid")
        out = d / "out"
        argv = ["synth", str(ws.model), str(folder), "-o", str(out), "--format", "tsv", "-q",
                "-j", rng.choice(["1", "2"])]
        yield Case("damaged", f"batch of {len(blame) + 1}: {'; '.join(hows)}"[:80], argv,
                   _protect(ws.model, *blame), blame=blame, summary=out / "synth-summary.json")


# --------------------------------------------------------------------------- labels
_NUMBERS = ["nan", "inf", "-inf", "-1", "0", "1e300", "1e-300", "99999", "x", "", "1,5", "2.0e5"]


def _mutate_text(rng: random.Random, text: str) -> tuple[str, str]:
    lines = text.splitlines()
    kind = rng.choice(["number", "number", "swap", "delete", "dup", "empty", "garbage", "blank",
                       "label"])
    if not lines:
        return "", "empty"
    i = rng.randrange(len(lines))
    if kind == "number":
        toks = lines[i].split()
        nums = [k for k, t in enumerate(toks) if t.replace(".", "", 1).replace("-", "", 1).isdigit()]
        if nums:
            k = rng.choice(nums)
            toks[k] = rng.choice(_NUMBERS)
            lead = lines[i][: len(lines[i]) - len(lines[i].lstrip())]
            lines[i] = lead + " ".join(toks)
    elif kind == "swap":
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif kind == "delete":
        del lines[i:i + rng.choice([1, 3, 10])]
    elif kind == "dup":
        lines[i:i] = lines[i:i + rng.choice([1, 4])]
    elif kind == "empty":
        lines = []
    elif kind == "garbage":
        lines[i] = "".join(rng.choice("\"=[]{}<>ab 01.\t\\") for _ in range(rng.randrange(1, 30)))
    elif kind == "blank":
        lines = [ln for ln in lines if "text" not in ln] if rng.random() < 0.5 else lines[:12]
    else:
        lines[i] = lines[i].replace('"', '"zz', 1) if '"' in lines[i] else lines[i] + " zz"
    return "\n".join(lines) + "\n", kind


def label_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    while True:
        d = ws.fresh("labels")
        src = rng.choice([ws.textgrid, ws.textgrid, ws.lab, ws.lab.with_suffix(".phn")])
        path = d / src.name
        kind = rng.random()
        if kind < 0.7:
            text, how = _mutate_text(rng, src.read_text())
            path.write_text(text)
            name = f"{src.suffix} {how}"
        elif kind < 0.8:
            path.write_bytes(src.read_bytes().replace(b"a", b"\xe9\xff", 3))
            name = f"{src.suffix} not UTF-8"
        elif kind < 0.9:
            data, how = mutate_bytes(rng, src.read_bytes())
            path.write_bytes(data)
            name = f"{src.suffix} bytes {how}"
        else:
            path = d / rng.choice(["l.seg", "l.TextGrid", "l.lab"])
            path.mkdir()
            name = "labels given as a folder"
        extra = []
        if rng.random() < 0.15:
            lm = d / "map.tsv"
            choice = rng.choice(["unknown", "folder", "bad", "utf"])
            if choice == "folder":
                lm.mkdir()
            elif choice == "bad":
                lm.write_text("a b c\n")
            elif choice == "utf":
                lm.write_bytes(b"\xff\xfe\x00a")
            else:
                lm.write_text("aa\tzz\niy\tqq\n")
            extra = ["--label-map", str(lm)]
            name += f", label map {choice}"
        out = d / "out.tsv"
        yield Case("labels", name, _synth_argv(ws, ws.model, ws.wav, out, path, extra),
                   _protect(ws.model, ws.wav), out)


# --------------------------------------------------------------------------- models
def _npz_members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as zf:
        return {i.filename: zf.read(i) for i in zf.infolist()}


def _write_npz(path: Path, members: dict[str, bytes], compression=zipfile.ZIP_STORED) -> None:
    with zipfile.ZipFile(path, "w", compression) as zf:
        for name, data in members.items():
            zf.writestr(name, data)


def _npy(arr) -> bytes:
    import numpy as np

    buf = io.BytesIO()
    np.lib.format.write_array(buf, np.asarray(arr), allow_pickle=False)
    return buf.getvalue()


def _mutated_meta(rng: random.Random, meta: dict) -> tuple[object, str]:
    """A model's metadata with one field (or itself) replaced by a wrong value, and what changed."""
    field_ = rng.choice([*list(meta), "config"])
    value = rng.choice([None, [], {}, "x", -1, 0, 1e309, True, 3.5, [1, 2], "nan", 10**30])
    if rng.random() < 0.15:
        meta = rng.choice([[], "text", 5, None])
        return meta, f"meta is {meta!r}"
    if field_ == "config" and isinstance(meta.get("config"), dict) and rng.random() < 0.7:
        key = rng.choice(list(meta["config"]))
        meta["config"][key] = value
        return meta, f"config {key} = {value!r}"
    meta[field_] = value
    return meta, f"meta {field_} = {value!r}"


def _mutated_array(rng: random.Random, a):
    """A model array with a NaN, another dtype or shape, emptied, doubled, text, transposed or
    negated; and which."""
    import numpy as np

    how = rng.choice(["nan", "dtype", "shape", "empty", "big", "str", "transpose", "neg"])
    if how == "nan":
        b = a.astype(float)
        if b.size:
            b.flat[rng.randrange(b.size)] = rng.choice([np.nan, np.inf])
    elif how == "dtype":
        ints = a.dtype.kind in "iu"
        b = a.astype(rng.choice(
            [np.int8, np.int32, np.uint32, np.uint64, ">i8", np.float64, np.bool_, np.complex64]
            if ints else
            [np.float32, np.float16, ">f8", np.longdouble, np.int64, np.int8, np.complex64,
             np.bool_, np.uint64]))
    elif how == "shape":
        b = a.reshape(-1)[: max(a.size - 1, 0)]
    elif how == "empty":
        b = np.zeros((0, *a.shape[1:]), a.dtype)
    elif how == "big":
        b = np.concatenate([a, a]) if a.ndim else a
    elif how == "str":
        b = np.array(["x"] * max(a.size, 1))
    elif how == "transpose":
        b = a.T.copy()
    else:
        b = -np.abs(a) - 1 if a.dtype.kind in "iuf" else a
    return b, how


def _xref_damage(rng: random.Random, a: dict, meta: dict):
    """One array damaged against what it refers to or how it is stored: ids beyond their lists,
    the LSF index no partition of the codebook, LSFs out of range or order, tokens ending before
    they start, other integer and float types (some of them valid). ``(name, array, how)``."""
    import numpy as np

    def swapped(x):
        y = x.copy()
        y[1], y[2] = y[2], y[1]
        return y

    def dup(x):
        y = x.copy()
        y[1] = y[0]
        return y

    damage = {
        "cb_contexts": [("+phones", lambda x: x + len(meta["phones"])), ("-1", lambda x: x - 1),
                        ("uint64", lambda x: x.astype(np.uint64)),
                        ("uint64 max", lambda x: np.where(x == x.max(), 2**63, x).astype(np.uint64)),
                        ("int16", lambda x: x.astype(np.int16)), ("float", lambda x: x + 0.5)],
        "fixed": [("dup", dup), ("+markers", lambda x: x + len(meta["marker_names"]))],
        "cb_token_utt": [("+utterances", lambda x: x + len(meta["train_utterances"]))],
        "ix_order": [("dup", dup), ("+1", lambda x: x + 1), ("int32", lambda x: x.astype(np.int32)),
                     ("reversed", lambda x: x[::-1].copy())],
        "ix_offsets": [("swapped", swapped), ("end+1", lambda x: x + (np.arange(len(x)) ==
                                                                      len(x) - 1))],
        "cb_lsf": [("reversed", lambda x: x[:, ::-1].copy()), ("+pi", lambda x: x + np.pi),
                   ("float32", lambda x: x.astype(np.float32)), (">f8", lambda x: x.astype(">f8"))],
        "cb_token_end": [("before start", lambda x: x - 1e3)],
        "distances": [("asymmetric", lambda x: x + np.triu(np.ones_like(x), 1))],
        "pca_components": [("scaled", lambda x: 1.5 * x)],
        "pca_variances": [("x1000", lambda x: 1000 * x)],
        "means": [("float16", lambda x: x.astype(np.float16))],
    }
    name = rng.choice([n for n in damage if n in a])
    how, fn = rng.choice(damage[name])
    with np.errstate(all="ignore"):
        return name, fn(a[name]), how


def _model_variant(rng: random.Random, src: Path, dst: Path) -> str:
    import numpy as np

    members = _npz_members(src)
    with np.load(src, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays["meta"]))
    kind = rng.choice(["meta", "meta", "array", "array", "xref", "xref", "header", "compression",
                       "deflate", "bytes", "missing", "pickle"])
    if kind == "meta":
        meta, desc = _mutated_meta(rng, meta)
        members["meta.npy"] = _npy(np.array(json.dumps(meta).replace("Infinity", "1e999")))
        _write_npz(dst, members)
        return desc
    if kind == "array":
        name = rng.choice([k for k in arrays if k != "meta"])
        b, how = _mutated_array(rng, arrays[name])
        members[f"{name}.npy"] = _npy(b)
        _write_npz(dst, members)
        return f"{name} {how}"
    if kind == "xref":
        name, b, how = _xref_damage(rng, arrays, meta)
        members[f"{name}.npy"] = _npy(b)
        _write_npz(dst, members)
        return f"{name} {how}"
    if kind == "header":
        name = rng.choice(list(members))
        shape = rng.choice([(2**40,), (2**20, 2**20), (-1,), (10**12, 20), (3, 0, 2**62)])
        descr = rng.choice(["<f8", "|O", "<U100000", "<f8", "|V8"])
        hdr = f"{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape!r}, }}"
        hdr = hdr.ljust(118) + "\n"
        members[name] = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(hdr)) + hdr.encode() + b"\0" * 64
        _write_npz(dst, members)
        return f"{name} header asks for {shape} of {descr}"
    if kind == "compression":
        _write_npz(dst, members, zipfile.ZIP_DEFLATED)
        data = bytearray(dst.read_bytes())
        method = rng.choice([12, 14, 99, 8, 1, 93])
        for sig, off in ((b"PK\x03\x04", 8), (b"PK\x01\x02", 10)):
            i = data.find(sig)
            while i >= 0:
                data[i + off:i + off + 2] = struct.pack("<H", method)
                i = data.find(sig, i + 4)
        dst.write_bytes(bytes(data))
        return f"compression method {method}"
    if kind == "deflate":
        _write_npz(dst, members, zipfile.ZIP_DEFLATED)
        data, how = mutate_bytes(rng, dst.read_bytes(), 40, len(dst.read_bytes()) - 200)
        dst.write_bytes(data)
        return f"deflate stream {how}"
    if kind == "missing":
        name = rng.choice(list(members))
        del members[name]
        _write_npz(dst, members)
        return f"{name} missing"
    if kind == "pickle":
        name = rng.choice(list(members))
        members[name] = b"\x93NUMPY\x01\x00" + struct.pack("<H", 118) + \
            "{'descr': '|O', 'fortran_order': False, 'shape': (1,), }".ljust(117).encode() + \
            b"\n" + b"\x80\x04\x95cos\nsystem\n."
        _write_npz(dst, members)
        return f"{name} pickled"
    data, how = mutate_bytes(rng, src.read_bytes())
    dst.write_bytes(data)
    return f"bytes {how}"


def model_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    while True:
        d = ws.fresh("model")
        path = d / "model.npz"
        name = _model_variant(rng, ws.model, path)
        out = d / "out.tsv"
        if rng.random() < 0.8:
            argv = _synth_argv(ws, path, ws.wav, out, ws.textgrid if rng.random() < 0.5 else None)
        else:
            argv, out = ["similarity", str(path), "-q"], None
        yield Case("model", name, argv, _protect(ws.wav), out)


# --------------------------------------------------------------------------- corpus.json
_VALUES = [None, [], {}, "", "x", -1, 0, 0.001, 1e6, 1e309, True, [1], ["x"], {"a": 1}, "mocha",
           "../nowhere", [""], ["a/b"], 2, 3, 4]


def corpus_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    info = json.loads((ws.corpus / "corpus.json").read_text())
    while True:
        d = ws.fresh("corpus")
        corpus = d / "corpus"
        shutil.copytree(ws.corpus, corpus)
        obj = json.loads(json.dumps(info))
        kind = rng.random()
        if kind < 0.6:
            key = rng.choice([*list(obj), "data_dir", "label_map"])
            obj[key] = rng.choice(_VALUES)
            text = json.dumps(obj).replace("Infinity", "1e999")
            name = f"{key} = {json.dumps(obj[key])[:30]}"
        elif kind < 0.7:
            text = json.dumps(rng.choice([[], "x", 5, None, [obj]]))
            name = f"top level {text[:20]}"
        elif kind < 0.75:
            depth = rng.choice([100, 10000, 100000])
            text = "[" * depth + "]" * depth
            name = f"nested {depth} deep"
        elif kind < 0.85:
            text, how = _mutate_text(rng, json.dumps(obj, indent=1))
            name = f"text {how}"
        elif kind < 0.9:
            text = json.dumps(obj)
            (corpus / "toy030.txt").write_bytes(b"caf\xe9 \xff")
            name = "transcript not UTF-8"
        elif kind < 0.95:
            text = json.dumps(obj)
            victim = corpus / f"toy030.{rng.choice(['wav', 'TextGrid', 'c3d'])}"
            victim.unlink()
            if rng.random() < 0.5:
                victim.mkdir()
            name = f"{victim.suffix} missing or a folder"
        else:
            text = json.dumps(obj)
            (corpus / "corpus.json").unlink()
            (corpus / "corpus.json").mkdir()
            name = "corpus.json is a folder"
        if (corpus / "corpus.json").is_file():
            (corpus / "corpus.json").write_text(text)
        out = d / "model.npz"
        r = rng.random()
        if r < 0.5:
            argv, out = ["corpus", "show", str(corpus), "-q"], None
        elif r < 0.8:
            argv = ["train", str(corpus), "-o", str(out), "-q"]
        else:
            argv, out = ["eval", str(ws.model), str(corpus), "--split", "test", "-q"], None
        yield Case("corpus", name, argv, _protect(ws.model), out)


# --------------------------------------------------------------------------- C3D
def _c3d_rate(data: bytes, rate: float) -> bytes:
    """The C3D with POINT:RATE and the header rate set to ``rate`` (Intel float32)."""
    d = bytearray(data)
    d[20:24] = struct.pack("<f", rate)
    i = d.find(b"RATE", 512)
    while i > 0:
        body = i + 4 + 2
        if d[body] == 4 and d[body + 1] == 0:  # float scalar
            d[body + 2:body + 6] = struct.pack("<f", rate)
        i = d.find(b"RATE", i + 4)
    return bytes(d)


def c3d_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    src = ws.c3d.read_bytes()
    data_start = struct.unpack("<H", src[16:18])[0]
    while True:
        d = ws.fresh("c3d")
        corpus = d / "corpus"
        shutil.copytree(ws.corpus, corpus)
        kind = rng.choice(["params", "params", "header", "data", "any", "rate", "frames"])
        if kind == "params":
            data, how = mutate_bytes(rng, src, 512, (data_start - 1) * 512)
        elif kind == "header":
            data, how = mutate_bytes(rng, src, 0, 512)
        elif kind == "data":
            data, how = mutate_bytes(rng, src, (data_start - 1) * 512)
        elif kind == "rate":
            rate = rng.choice([1e6, 0.001, 0.0, -60.0, float("nan"), 1e30, 59.9, 240.0])
            data, how = _c3d_rate(src, rate), f"{rate:g} Hz"
        elif kind == "frames":
            from facetraj_engine.io.markerfiles import read_c3d, write_c3d

            m = read_c3d(ws.c3d)
            n = rng.choice([0, 1, 2, 3])
            if n == 0:
                data, how = src[: (data_start - 1) * 512], "no frames"
            else:
                write_c3d(d / "t.c3d", m.markers[:n], m.rate, m.names)
                data, how = (d / "t.c3d").read_bytes(), f"{n} frames"
        else:
            data, how = mutate_bytes(rng, src)
        (corpus / "toy030.c3d").write_bytes(data)
        out = d / "model.npz"
        r = rng.random()
        if r < 0.5:
            argv, out = ["corpus", "show", str(corpus), "-q"], None
        elif r < 0.7:
            argv, out = ["eval", str(ws.model), str(corpus), "--split", "test", "-q"], None
        elif r < 0.85:
            shutil.copy(corpus / "toy030.c3d", corpus / "toy000.c3d")
            argv = ["train", str(corpus), "-o", str(out), "-q"]
        else:  # describing the folder reads the first marker file
            shutil.copy(corpus / "toy030.c3d", corpus / "toy000.c3d")
            out = d / "described.json"
            argv = ["corpus", "init", str(corpus), "-o", str(out), "--fixed", "FH_L", "FH_R", "NB",
                    "NT", "--upper-lip", "UL_C", "--lower-lip", "LL_C", "-q"]
        yield Case("c3d", f"{kind} {how}", argv, _protect(ws.model), out)


# --------------------------------------------------------------------------- TSV / EMA markers
def marker_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    """Marker tables (TSV/CSV) and MOCHA EMA text in place of the C3D, damaged as text."""
    from facetraj_engine.io.markerfiles import read_c3d, write_marker_tsv

    m = read_c3d(ws.c3d)
    while True:
        d = ws.fresh("markers")
        corpus = d / "corpus"
        shutil.copytree(ws.corpus, corpus)
        (corpus / "toy030.c3d").unlink()
        kind = rng.choice(["tsv", "tsv", "csv", "ema", "folder"])
        if kind in ("tsv", "csv"):
            path = corpus / f"toy030.{kind}"
            write_marker_tsv(path, m.markers, m.rate, m.names)
            text, how = _mutate_text(rng, path.read_text())
            if rng.random() < 0.3:  # equal, reversed or absurd times
                lines = text.splitlines()
                t = rng.choice(["0", "1e300", "nan", "-1", "1e-300"])
                text = "\n".join(lines[:1] + [t + ln[ln.find("\t"):] for ln in lines[1:]]) + "\n"
                how += f", times {t}"
            path.write_text(text)
        elif kind == "ema":
            path = corpus / "toy030.ema"
            rows = ["0.0 1 " + " ".join(["100"] * 20)] * 3
            text, how = _mutate_text(rng, "\n".join(rows))
            path.write_text(text)
        else:
            path = corpus / "toy030.tsv"
            path.mkdir()
            how = "a folder"
        if rng.random() < 0.5:
            argv, out = ["corpus", "show", str(corpus), "-q"], None
        else:
            argv, out = ["eval", str(ws.model), str(corpus), "--split", "test", "-q"], None
        yield Case("markers", f"{kind} {how}", argv, _protect(ws.model), out)


# --------------------------------------------------------------------------- articulographs
#: binary formats get byte damage, text formats text damage (and byte damage now and then)
_TEXT_KINDS = {"ndi", "xrmb"}


def _articulograph_base(ws: Workspace, kind: str) -> Path:
    """The workspace's corpus with its markers in format ``kind`` (tests/articulograph.py),
    described: channels named where the files do not name them; XRMB as its 8 pellets (2-D)."""
    from articulograph import PELLETS, write_folder

    from facetraj_engine.io.corpus import CorpusInfo, load_corpus, save_corpus_info

    base = ws.root / "articulograph" / kind
    if (base / "corpus.json").is_file():
        return base
    info = load_corpus(ws.corpus).info
    write_folder(kind, ws.corpus, base, info.ids)
    if kind == "xrmb":
        info = CorpusInfo(**{**info.__dict__, "marker_names": list(PELLETS), "fixed_markers": [],
                             "upper_lip": "UL", "lower_lip": "LL", "lip_corners": [],
                             "dimensions": 2, "head_corrected": True})
    elif kind in ("ag501", "ag500", "ndi"):
        info = CorpusInfo(**{**info.__dict__, "channel_names": list(info.marker_names)})
    save_corpus_info(base, info)
    return base


def _init_argv(kind: str, corpus: Path, out: Path) -> list[str]:
    from toycorpus import FIXED, NAMES

    lips = ["--upper-lip", "UL", "--lower-lip", "LL"] if kind == "xrmb" else \
        ["--upper-lip", "UL_C", "--lower-lip", "LL_C"]
    named = ["--channel-names", *NAMES] if kind in ("ag501", "ag500", "ndi") else []
    fixed = [] if kind in ("xrmb", "mview") else ["--fixed", *FIXED]
    return ["corpus", "init", str(corpus), "-o", str(out), *lips, *named, *fixed, "-q"]


def articulograph_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    """Carstens, NDI Wave, MVIEW (v5, v7.3), XRMB and EST files in place of the C3D, damaged."""
    from articulograph import FOLDER_KINDS

    while True:
        kind = rng.choice(sorted(FOLDER_KINDS))
        d = ws.fresh("articulograph")
        corpus = d / "corpus"
        shutil.copytree(_articulograph_base(ws, kind), corpus)
        r = rng.random()
        utt = "toy000" if r >= 0.8 else "toy030"       # corpus init reads the first file
        target = corpus / f"{utt}{FOLDER_KINDS[kind]}"
        if kind in _TEXT_KINDS and rng.random() < 0.7:
            text, how = _mutate_text(rng, target.read_text())
            target.write_text(text)
        else:
            data, how = mutate_bytes(rng, target.read_bytes(), 0, rng.choice([120, 600, None]))
            target.write_bytes(data)
        out = d / "model.npz"
        if r < 0.45:
            argv, out = ["corpus", "show", str(corpus), "-q"], None
        elif r < 0.65 and kind != "xrmb":                   # the model's 12 markers
            argv, out = ["eval", str(ws.model), str(corpus), "--split", "test", "-q"], None
        elif r < 0.8:
            argv = ["train", str(corpus), "-o", str(out), "--no-tune", "-q"]
        else:
            out = d / "described.json"
            argv = _init_argv(kind, corpus, out)
        yield Case("articulograph", f"{kind} {how}", argv, _protect(ws.model), out)


# --------------------------------------------------------------------------- options
def _positional_value(ws: Workspace, dest: str, d: Path) -> str:
    return {"model": str(ws.model), "audio": str(ws.wav), "inputs": str(ws.wav),
            "corpus": str(ws.corpus), "data_dir": str(ws.corpus),
            "output": str(d / "out")}.get(dest, str(d / dest))


def option_targets() -> list[tuple[tuple[str, ...], argparse.ArgumentParser, argparse.Action]]:
    """Every (command path, parser, option with a value type) of the ``facetraj`` parser."""
    from facetraj.cli import build_parser

    top = build_parser()
    out = []

    def walk(parser: argparse.ArgumentParser, path: tuple[str, ...]) -> None:
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                seen = set()
                for name, child in action.choices.items():
                    if id(child) not in seen:
                        seen.add(id(child))
                        walk(child, (*path, name))
            elif action.option_strings and (action.type is not None or action.choices):
                out.append((path, parser, action))

    walk(top, ())
    return out


def option_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    targets = option_targets()
    while True:
        path, parser, action = rng.choice(targets)
        d = ws.fresh("options")
        value = rng.choice(BAD_NUMBERS + ([*list(action.choices or [])[:1], "bogus"]
                                          if action.choices else []))
        argv = list(path)
        for pos in parser._actions:
            if not pos.option_strings and pos.nargs not in ("?", "*") and \
                    not isinstance(pos, argparse._SubParsersAction):
                argv.append(_positional_value(ws, pos.dest, d))
        out = None
        for req in parser._actions:
            if req.option_strings and req.required and req is not action:
                if req.dest == "output":
                    out = d / ("out.npz" if "train" in path else "out.tsv")
                    argv += [req.option_strings[0], str(out)]
                elif req.nargs == "+" and req.dest == "fixed":
                    argv += [req.option_strings[0], "FH_L", "FH_R", "NB", "NT"]
                elif req.dest == "upper_lip":
                    argv += [req.option_strings[0], "UL_C"]
                elif req.dest == "lower_lip":
                    argv += [req.option_strings[0], "LL_C"]
                else:
                    argv += [req.option_strings[0], "x"]
        if path[-1:] == ("init",):
            out = d / "corpus.json"
            argv += ["-o", str(out)]
        if path[:1] == ("eval",) or path[:1] == ("sweep",):
            argv += ["--split", "test"]
        argv += [action.option_strings[-1] + "=" + value, "-q"]
        parse_only = (not path or path[0] in PARSE_ONLY or path[-1] in PARSE_ONLY
                      or path[0] == "sweep")
        yield Case("options", f"{' '.join(path) or '(none)'} {action.option_strings[-1]}={value!r}",
                   argv, _protect(ws.model, ws.wav, ws.corpus / "corpus.json"), out, parse_only,
                   cwd=d)


# --------------------------------------------------------------------------- outputs
def output_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    while True:
        d = ws.fresh("output")
        kind = rng.choice(["exists", "exists-overwrite", "folder", "parent-file", "long",
                           "no-permission", "deep", "suffix", "init-exists", "train-exists"])
        extra: list[str] = []
        keep_mode = None
        protected = _protect(ws.model, ws.wav)
        out = d / "out.tsv"
        argv_of = None
        if kind in ("exists", "exists-overwrite"):
            out.write_text("the user's file\n")
            keep_mode = rng.choice([0o644, 0o600, 0o664])
            os.chmod(out, keep_mode)
            if kind == "exists":
                protected.update(_protect(out))
            else:
                extra = ["--overwrite"]
        elif kind == "folder":
            out.mkdir()
            (out / "keep.txt").write_text("x")
            protected.update(_protect(out / "keep.txt"))
            extra = ["--overwrite"] if rng.random() < 0.5 else []
        elif kind == "parent-file":
            (d / "file").write_text("x")
            protected.update(_protect(d / "file"))
            out = d / "file" / rng.choice(["out.tsv", "sub/out.tsv"])
        elif kind == "long":
            out = d / ("x" * rng.choice([250, 256, 300, 5000]) + ".tsv")
        elif kind == "no-permission":
            out = Path(rng.choice(["/sys/facetraj-fuzz.tsv", "/proc/facetraj-fuzz.tsv",
                                   "/proc/self/facetraj/out.tsv"]))
        elif kind == "deep":
            out = d / "a" / "b" / "c" / "out.tsv"
        elif kind == "suffix":
            out = d / rng.choice(["out.xyz", "out", "out.C3D", "out.csv", "out.npz", ".tsv", "out.bvh",
                                   "out.glb"])
        elif kind == "init-exists":
            corpus = d / "corpus"
            shutil.copytree(ws.corpus, corpus)
            protected.update(_protect(corpus / "corpus.json"))
            out = corpus / "corpus.json"
            argv_of = ["corpus", "init", str(corpus), "--fixed", "FH_L", "FH_R", "NB", "NT",
                       "--upper-lip", "UL_C", "--lower-lip", "LL_C", "-q"]
        else:
            out = d / "model.npz"
            out.write_bytes(b"the user's model")
            protected.update(_protect(out))
            argv_of = ["train", str(ws.corpus), "-o", str(out), "-q"]
        argv = argv_of or _synth_argv(ws, ws.model, ws.wav, out, extra=extra)
        yield Case("output", f"{kind} {out.name[:40]}", argv, protected, out, keep_mode=keep_mode)


# --------------------------------------------------------------------------- corpora, 2 workers
#: the corpus-wide commands and how often each is drawn (report and align take seconds)
FANOUT_COMMANDS = ("eval", "eval", "eval", "sweep", "train", "train", "train", "align", "align",
                   "report", "report")
QUICK_FANOUT_COMMANDS = ("eval", "eval", "sweep", "train", "train")


def _spoil(rng: random.Random, corpus: Path, utt: str, command: str) -> str:
    """Damage one file of utterance ``utt`` in ``corpus`` (mostly its audio or transcript for
    ``align``, which reads nothing else); what was done."""
    kinds = (["wav", "wav", "wav-header", "txt"] if command == "align" else
             ["c3d", "c3d", "c3d-cut", "wav", "wav-header", "labels", "alien", "missing", "short",
              "tsv"])
    kind = rng.choice(kinds)
    if kind == "c3d":
        src = corpus / f"{utt}.c3d"
        data, how = mutate_bytes(rng, src.read_bytes())
        src.write_bytes(data)
        return f"{utt}.c3d {how}"
    if kind == "c3d-cut":
        src = corpus / f"{utt}.c3d"
        src.write_bytes(src.read_bytes()[: rng.choice([0, 100, 512, 3000])])
        return f"{utt}.c3d cut"
    if kind == "wav":
        src = corpus / f"{utt}.wav"
        data, how = mutate_bytes(rng, src.read_bytes(), 0, rng.choice([64, None]))
        src.write_bytes(data)
        return f"{utt}.wav {how}"
    if kind == "wav-header":
        return f"{utt}.wav {_spoil_wav_header(rng, corpus / f'{utt}.wav')}"
    if kind == "txt":
        (corpus / f"{utt}.txt").write_bytes(rng.choice([b"caf\xe9 \xff", b"", b"\x00\x01",
                                                         b"zorblax qwfp"]))
        return f"{utt}.txt written"
    if kind in ("labels", "alien"):
        tg = corpus / f"{utt}.TextGrid"
        if kind == "labels":
            text, how = _mutate_text(rng, tg.read_text())
        else:
            text, how = tg.read_text().replace('"aa"', '"zz"').replace('"iy"', '"@@x"'), "alien"
        tg.write_text(text)
        return f"{utt}.TextGrid {how}"
    if kind == "missing":
        victim = corpus / f"{utt}.{rng.choice(['wav', 'TextGrid', 'c3d'])}"
        victim.unlink()
        return f"{victim.name} missing"
    if kind == "short":
        from facetraj_engine.io.markerfiles import read_c3d, write_c3d

        m = read_c3d(corpus / f"{utt}.c3d")
        write_c3d(corpus / f"{utt}.c3d", m.markers[: rng.choice([1, 2, 30])], m.rate, m.names)
        return f"{utt}.c3d short"
    from facetraj_engine.io.markerfiles import read_c3d, write_marker_tsv

    m = read_c3d(corpus / f"{utt}.c3d")
    (corpus / f"{utt}.c3d").unlink()
    write_marker_tsv(corpus / f"{utt}.tsv", m.markers, m.rate, m.names)
    text, how = _mutate_text(rng, (corpus / f"{utt}.tsv").read_text())
    (corpus / f"{utt}.tsv").write_text(text)
    return f"{utt}.tsv {how}"


def _spoil_wav_header(rng: random.Random, wav: Path) -> str:
    """A WAV whose data size, channel count, rate or bits field is damaged."""
    d = bytearray(wav.read_bytes())
    fmt, data = d.find(b"fmt "), d.find(b"data")
    field_, off, size = rng.choice([("data size", data + 4, 4), ("RIFF size", 4, 4),
                                    ("channels", fmt + 10, 2), ("rate", fmt + 12, 4),
                                    ("bits", fmt + 22, 2), ("block align", fmt + 20, 2)])
    value = rng.choice([0, 1, 3, 0xFFFF, 0xFFFFFFF0, 7, 2**31])
    d[off:off + size] = (value % (1 << (8 * size))).to_bytes(size, "little")
    wav.write_bytes(bytes(d))
    return f"{field_} = {value}"


def fanout_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    """eval, sweep, train, corpus align and report with 2 workers over a corpus with one bad file,
    with or without --skip-bad; eval, sweep and train also with -j 1, which must end the same."""
    while True:
        d = ws.fresh("fanout")
        corpus = d / "corpus"
        shutil.copytree(ws.corpus, corpus)
        command = rng.choice(QUICK_FANOUT_COMMANDS if ws.quick else FANOUT_COMMANDS)
        how = _spoil(rng, corpus, rng.choice(["toy000", "toy001", "toy030"]), command)
        skip = rng.random() < 0.5
        out: Path | None = None
        if command in ("eval", "sweep"):
            argv = [command, str(ws.model), str(corpus)] + (["--max-n", "2"] if command == "sweep"
                                                             else [])
        elif command == "train":
            out = d / "model.npz"
            argv = ["train", str(corpus), "-o", str(out)]
        elif command == "align":
            argv = ["corpus", "align", str(corpus), "--overwrite", "--recognize"]
        else:
            out = d / "report" / "results.md"
            argv = ["report", str(corpus), "-o", str(out.parent), "--max-n", "2"]
        argv += ["-q"] + (["--skip-bad"] if skip else [])
        serial = None
        if command in ("eval", "sweep", "train"):   # -j 1 writes its own model, if any
            serial = [str(d / "model-j1.npz") if a == str(out) else a for a in argv] + ["-j", "1"]
        yield Case("fanout", f"{command}{' --skip-bad' if skip else ''}: {how}", [*argv, "-j", "2"],
                   _protect(ws.model), out, skip_bad=skip, serial_argv=serial)


# --------------------------------------------------------------------------- other alphabets
#: the toy corpus's phones as each alphabet writes them (any of the spellings listed)
SPELLINGS: dict[str, dict[str, list[str]]] = {
    "ARPAbet": {"sil": ["sil", "sp", "SIL", "pau"], "aa": ["AA1", "aa", "AA0"],
                "iy": ["IY1", "iy", "IY2"], "uw": ["UW1", "uw"], "m": ["M", "m"], "f": ["F", "f"],
                "s": ["S", "s"], "t": ["T", "t"]},
    "TIMIT": {"sil": ["h#", "pau", "epi"], "aa": ["aa"], "iy": ["iy"], "uw": ["uw"], "m": ["m"],
              "f": ["f"], "s": ["s"], "t": ["tcl", "t"]},
    "MOCHA-TIMIT": {"sil": ["sil", "breath"], "aa": ["aa"], "iy": ["ii"], "uw": ["uu"], "m": ["m"],
                    "f": ["f"], "s": ["s"], "t": ["t"]},
    "SAMPA": {"sil": ["sil", "#"], "aa": ["A:"], "iy": ["i:"], "uw": ["u:"], "m": ["m"],
              "f": ["f"], "s": ["s"], "t": ["t"]},
    "X-SAMPA": {"sil": ["sil"], "aa": ["a:", "A:"], "iy": ["i:"], "uw": ["u:"], "m": ["m"],
                "f": ["f"], "s": ["s"], "t": ["t"]},
    "IPA": {"sil": ["sil", ""], "aa": ["\u0251\u02d0", "\u02c8\u0251", "\u0251"],
            "iy": ["i\u02d0", "\u02c8i\u02d0"], "uw": ["u\u02d0", "\u02c8u\u02d0", "\u02ccu"],
            "m": ["m"], "f": ["f"], "s": ["s"], "t": ["t"]},
}
ALIEN_LABELS = ["zz", "Q\\", "\u014b\u030a", "AA9", "ph", "#1", "i::", "\u0251\u0303", "x-ray", "*"]


def _write_label_file(path: Path, segs: list, rate: int = 16000) -> None:
    if path.suffix == ".TextGrid":
        from facetraj_engine.io.labelfiles import write_textgrid

        write_textgrid(path, {"phones": segs}, segs[-1].end)
    elif path.suffix == ".phn":
        path.write_text("".join(f"{round(s.start * rate)} {round(s.end * rate)} {s.label or 'h#'}\n"
                                for s in segs), encoding="utf-8")
    else:
        path.write_text("".join(f"{s.start:.5f} {s.end:.5f} {s.label or 'sil'}\n" for s in segs),
                        encoding="utf-8")


def alphabet_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    """The toy labels written in each alphabet (must synthesize), or with labels in no alphabet,
    alphabets mixed, case changed (refused or synthesized, never a traceback); given with
    --labels or found beside the audio; sometimes with --label-map (a file or an alphabet)."""
    from facetraj_engine.data import PhoneSegment
    from facetraj_engine.io.labelfiles import read_labels

    segs = read_labels(ws.textgrid)
    while True:
        d = ws.fresh("alphabet")
        name = rng.choice(list(SPELLINGS))
        table = SPELLINGS[name]
        out_segs = [PhoneSegment(s.start, s.end, rng.choice(table[s.label])) for s in segs]
        damage = rng.choice(["none", "none", "none", "alien", "mixed", "case", "stress", "aligner"])
        if damage == "aligner":        # an aligner's TextGrid (MFA): aligned by its conventions
            name, vowels = "ARPAbet", {"aa", "ae", "ah", "ao", "aw", "ay", "eh", "er", "ey", "ih",
                                       "iy", "ow", "oy", "uh", "uw"}
            out_segs = [PhoneSegment(s.start, s.end, "" if s.label == "sil" else s.label.upper()
                                     + (rng.choice("012") if s.label in vowels else ""))
                        for s in segs]
            out_segs[-1] = PhoneSegment(out_segs[-1].start, out_segs[-1].end, "spn")
        elif damage == "alien":
            k = rng.randrange(1, len(out_segs) - 1)
            out_segs[k] = PhoneSegment(out_segs[k].start, out_segs[k].end, rng.choice(ALIEN_LABELS))
        elif damage == "mixed":
            other = SPELLINGS[rng.choice(list(SPELLINGS))]
            out_segs = [PhoneSegment(a.start, a.end, rng.choice(other[s.label]))
                        if rng.random() < 0.3 else a for a, s in zip(out_segs, segs, strict=True)]
        elif damage == "case":
            out_segs = [PhoneSegment(a.start, a.end, a.label.swapcase()) for a in out_segs]
        elif damage == "stress":
            out_segs = [PhoneSegment(a.start, a.end, a.label + rng.choice(["1", "'", ":", ""]))
                        for a in out_segs]
        suffix = rng.choice([".lab", ".lab", ".TextGrid", ".phn"])
        beside = rng.random() < 0.4
        audio = d / "u.wav" if beside else ws.wav
        if beside:
            shutil.copy(ws.wav, audio)
        labels = d / f"u{suffix}"
        _write_label_file(labels, out_segs)
        extra = ["--mode", "phonetic"]
        if rng.random() < 0.2:
            extra += ["--label-map", rng.choice([name.lower().replace("-timit", ""),
                                                 rng.choice(["sampa", "ipa", "mocha", "timit"])])]
        out = d / "out.tsv"
        argv = _synth_argv(ws, ws.model, audio, out, None if beside else labels, extra)
        yield Case("alphabet", f"{name} {suffix}{' beside' if beside else ''}, {damage}"
                               f"{', ' + extra[-1] if len(extra) > 2 else ''}", argv,
                   _protect(ws.model, ws.wav), out,
                   expect_ok=damage in ("none", "aligner") and len(extra) == 2)


# --------------------------------------------------------------------------- the app
def app_cases(ws: Workspace, rng: random.Random) -> Iterator[Case]:
    """What the window opens: a damaged audio file, damaged labels (given, beside the audio, in
    another alphabet), a transcript beside the audio, a damaged model or corpus description, a
    damaged marker file of the utterance shown (tests/fuzz_app.py)."""
    from facetraj_engine.io.labelfiles import read_labels

    segs = read_labels(ws.textgrid)
    while True:
        d = ws.fresh("app")
        kind = rng.choice(["audio", "audio", "labels", "labels", "alphabet", "beside",
                           "transcript", "model", "model", "corpus", "c3d", "markers"])
        if kind == "audio":
            wav = d / "in.wav"
            if rng.random() < 0.3:
                shutil.copy(ws.wav, wav)
                how = _spoil_wav_header(rng, wav)
            else:
                data, how = mutate_bytes(rng, ws.wav.read_bytes(), 0, rng.choice([64, None]))
                wav.write_bytes(data)
            action = ["audio", str(wav), ""]
        elif kind in ("labels", "beside"):
            src = rng.choice([ws.textgrid, ws.lab, ws.lab.with_suffix(".phn")])
            audio = d / "in.wav" if kind == "beside" else ws.wav
            if kind == "beside":
                shutil.copy(ws.wav, audio)
            path = d / f"in{src.suffix}"
            text, how = _mutate_text(rng, src.read_text())
            path.write_text(text)
            action = ["audio", str(audio), "" if kind == "beside" else str(path)]
        elif kind == "alphabet":
            from facetraj_engine.data import PhoneSegment

            name = rng.choice(list(SPELLINGS))
            lab = [PhoneSegment(s.start, s.end, rng.choice(SPELLINGS[name][s.label])) for s in segs]
            if rng.random() < 0.4:
                lab[3] = PhoneSegment(lab[3].start, lab[3].end, rng.choice(ALIEN_LABELS))
                name += " with an unknown label"
            path = d / "in.lab"
            _write_label_file(path, lab)
            action, how = ["audio", str(ws.wav), str(path)], name
        elif kind == "transcript":
            audio = d / "in.wav"
            shutil.copy(ws.wav, audio)
            raw = rng.choice([b"caf\xe9 \xff", b"", b"zorblax wibble", b"\xff\xfe\x00",
                              b"the boy enjoyed the toy"])
            (d / "in.txt").write_bytes(raw)
            action, how = ["audio", str(audio), ""], f"transcript {raw[:12]!r}"
        elif kind == "model":
            path = d / "model.npz"
            how = _model_variant(rng, ws.model, path)
            action = ["corpus", str(ws.corpus), str(path)]
        elif kind == "corpus":
            corpus = d / "corpus"
            shutil.copytree(ws.corpus, corpus)
            info = json.loads((corpus / "corpus.json").read_text())
            key = rng.choice([*list(info), "data_dir"])
            info[key] = rng.choice(_VALUES)
            (corpus / "corpus.json").write_text(json.dumps(info).replace("Infinity", "1e999"))
            action, how = ["corpus", str(corpus), str(ws.model)], f"{key} = {info[key]!r}"[:40]
        else:
            corpus = d / "corpus"
            shutil.copytree(ws.corpus, corpus)
            how = _spoil(rng, corpus, "toy030", "eval")
            action = ["utterance", str(corpus), str(ws.model), "toy030"]
        yield Case("app", f"{kind}: {how}", [], app=action)


GENERATORS: dict[str, Callable[[Workspace, random.Random], Iterator[Case]]] = {
    "audio": audio_cases, "damaged": damaged_cases, "labels": label_cases, "model": model_cases,
    "corpus": corpus_cases, "c3d": c3d_cases, "markers": marker_cases,
    "articulograph": articulograph_cases, "options": option_cases, "output": output_cases,
    "fanout": fanout_cases, "alphabet": alphabet_cases, "app": app_cases,
}


def cases(ws: Workspace, n: int, seed: int,
          categories: tuple[str, ...] = CATEGORIES) -> Iterator[Case]:
    """``n`` cases, spread evenly over ``categories``, reproducible from ``seed``."""
    gens = {c: GENERATORS[c](ws, random.Random(f"{seed}-{c}")) for c in categories}
    for i in range(n):
        case = next(gens[categories[i % len(categories)]])
        case.cwd = case.cwd or ws.current   # relative paths land in the case's own folder
        yield case


# --------------------------------------------------------------------------- running a case
def _invoke(case: Case) -> int:
    """Run the command as ``facetraj`` would; parse-only cases stop after argparse."""
    from facetraj.cli import build_parser, main

    if case.parse_only:
        build_parser().parse_args(case.argv)
        return 0
    return main(case.argv)


def _judge(case: Case, code: int, err: str, status: str | None = None) -> Outcome:
    """The outcome of a finished run: its exit status, messages and files checked."""
    if status is not None:
        return Outcome(case, status, code, err[-300:])
    if "Traceback (most recent call last)" in err or code == 1:
        return Outcome(case, "traceback", code, err.strip().splitlines()[-1][:300] if err.strip()
                       else "")
    if code not in (0, 2, *((EXIT_INCOMPLETE,) if case.skip_bad else ())):
        return Outcome(case, f"exit {code}", code, err[-300:])
    lines = [ln for ln in err.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("facetraj") and ": error: " in ln]
    summary = [ln for ln in lines if ln.startswith("facetraj: ") and " skipped" in ln]
    # synth's batch (issue 28) ends with "facetraj: failed: <file>: <problem>" per input instead
    failed = [ln for ln in lines if ln.startswith("facetraj: failed: ") and ": " in ln[18:]]
    if (code == 2 and len(errors) != 1 and not (failed and not errors)) or \
            (code == EXIT_INCOMPLETE and (errors or not summary)):
        return Outcome(case, "unclear message", code, err[-300:])
    if case.expect_ok and code != 0:
        return Outcome(case, "refused valid input", code, err[-300:])
    blamed = _blame_problem(case, code, errors, failed)
    if blamed is not None:
        return Outcome(case, blamed[0], code, blamed[1])
    bad = _files_problem(case, code)
    if bad is not None:
        return Outcome(case, bad[0], code, bad[1])
    return Outcome(case, {0: "ok", 2: "refused"}.get(code, "skipped bad files"), code,
                   lines[-1][:200] if lines else "",
                   error_line=(errors or summary or failed or [""])[0])


def _blame_problem(case: Case, code: int, errors: list[str], failed: list[str]
                   ) -> tuple[str, str] | None:
    """A damaged input (issue 38) that was not refused, not named as the file at fault, or
    counted as done in a batch: (status, detail), else None."""
    if not case.blame:
        return None
    if code != 2:
        return "accepted damaged audio", f"exit {code}"
    for path in case.blame:
        named = [ln for ln in errors + failed
                 if ln.startswith((f"facetraj: error: {path}: ", f"facetraj: failed: {path}: "))]
        if not named:
            return "blamed the wrong file", f"{path} not named first in {errors + failed}"[:300]
    if case.summary is not None:
        inputs = json.loads(case.summary.read_text())["inputs"]
        done = [o["input"] for o in inputs if o["status"] == "done" and Path(o["input"]) in case.blame]
        if done:
            return "damaged audio counted as done", ", ".join(done)[:300]
    return None


def _files_problem(case: Case, code: int) -> tuple[str, str] | None:
    """A changed protected file, a partial output or NaN in one: (status, detail), else None."""
    for path, (data, mode) in case.protected.items():
        if not path.is_file() or _digest(path) != data:
            return "clobbered", f"{path} changed"
        if path.stat().st_mode != mode:
            return "clobbered", f"{path} mode changed"
    out = case.output
    if out is None:
        return None
    with contextlib.suppress(OSError):
        folder = out.parent
        if folder.is_dir() and any(".part-" in p.name for p in folder.iterdir()):
            return "partial", f".part file left in {folder}"
        if code == 2 and out.is_file() and out not in case.protected and \
                b"the user's file" not in out.read_bytes():
            return "partial", f"{out} written by a failed run"
        if code == EXIT_INCOMPLETE and not out.is_file():
            return "partial", f"{out} not written by a run that only skipped bad files"
        if code == 0 and case.keep_mode is not None and \
                (out.stat().st_mode & 0o7777) != case.keep_mode:
            return "clobbered", f"{out} mode {out.stat().st_mode:o}, {case.keep_mode:o} before"
        if code == 0 and out.is_file() and out.suffix in (".tsv", ".csv") and \
                b"nan" in out.read_bytes().lower():
            return "nan output", f"{out} holds NaN"
    return None


def run_in_process(case: Case) -> Outcome:
    """Run a case in this process (stdout and stderr captured)."""
    import logging

    err, out = io.StringIO(), io.StringIO()
    t0 = time.perf_counter()
    handlers = logging.getLogger().handlers[:]
    cwd = os.getcwd()
    os.chdir(case_workdir(case))
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            try:
                code = _invoke(case)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else 2
            except BaseException:
                traceback.print_exc()
                code = 1
    finally:
        logging.getLogger().handlers[:] = handlers
        os.chdir(cwd)
    outcome = _judge(case, code, err.getvalue())
    outcome.seconds = time.perf_counter() - t0
    return outcome


def run_forked(case: Case, timeout: float = TIMEOUT_S, memory: int = MEMORY_LIMIT) -> Outcome:
    """Run a case in a forked child with an address-space limit and a timeout."""
    err_path = case_workdir(case) / ".stderr"
    t0 = time.perf_counter()
    at_fork = vm_rss()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        code = 1
        try:
            fd = os.open(err_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
            os.dup2(fd, 2)
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, 1)
            sys.stderr = os.fdopen(2, "w", buffering=1)
            sys.stdout = os.fdopen(1, "w")
            os.chdir(case_workdir(case))
            for var in ("DISPLAY", "WAYLAND_DISPLAY"):  # the command line as on a server
                os.environ.pop(var, None)
            limit = _vm_size() + memory
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
            try:
                code = _invoke(case)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else 2
            except BaseException:
                traceback.print_exc()
                code = 1
            sys.stderr.flush()
            sys.stdout.flush()
        finally:
            os._exit(code)
    status = None
    while True:
        done, wstatus, usage = os.wait4(pid, os.WNOHANG)
        if done:
            break
        if time.perf_counter() - t0 > timeout:
            os.kill(pid, signal.SIGKILL)
            _, wstatus, usage = os.wait4(pid, 0)
            status = "hang"
            break
        time.sleep(0.005)
    code = os.waitstatus_to_exitcode(wstatus)
    err = err_path.read_text(errors="replace") if err_path.exists() else ""
    if status is None and code < 0:
        status = f"signal {-code}"
    outcome = _judge(case, code, err, status)
    outcome.seconds = time.perf_counter() - t0
    outcome.max_rss, outcome.rss_at_fork = usage.ru_maxrss * 1024, at_fork
    if outcome.grown > memory and not outcome.failed:
        outcome.status, outcome.detail = "memory", f"{outcome.grown / 2**30:.2f} GiB"
    return outcome


def case_workdir(case: Case) -> Path:
    """The folder of the case: where it runs and the forked run's stderr is kept."""
    if case.cwd is None:
        raise ValueError(f"case {case.name!r} has no folder of its own")
    return case.cwd


def _status_bytes(key: str) -> int:
    """A size from /proc/self/status (``VmSize``, ``VmRSS``) in bytes; 0 where there is none."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    return 0


def _vm_size() -> int:
    return _status_bytes("VmSize")


def vm_rss() -> int:
    """This process's resident size now (bytes)."""
    return _status_bytes("VmRSS")



def run_case(case: Case, runner: Callable[[Case], Outcome]) -> Outcome:
    """``runner(case)``, and for a case with a ``serial_argv`` the same with -j 1: it must end with
    the same exit status and the same error or skip summary (else "differs from -j 1")."""
    outcome = runner(case)
    if case.serial_argv is None or outcome.failed:
        return outcome
    argv = case.serial_argv
    out = Path(argv[argv.index("-o") + 1]) if "-o" in argv else case.output
    serial = runner(Case(case.category, case.name + " (-j 1)", argv, case.protected, out,
                         cwd=case.cwd, skip_bad=case.skip_bad))
    if serial.failed:
        return serial
    if (serial.code, serial.error_line) != (outcome.code, outcome.error_line):
        outcome.status = "differs from -j 1"
        outcome.detail = f"-j 2: {outcome.code} {outcome.error_line!r}; -j 1: {serial.code} " \
                         f"{serial.error_line!r}"
    outcome.seconds += serial.seconds
    outcome.max_rss = max(outcome.max_rss, serial.max_rss)
    return outcome


#: app cases run in one window per batch (a crash ends the batch: the rest run in a new one)
APP_BATCH = 40


def run_app_cases(ws: Workspace, app_cases: list[Case], timeout: float = TIMEOUT_S
                  ) -> list[Outcome]:
    """The app cases, in batches, each in a forked child with a window on the workspace's corpus
    (``tests/fuzz_app.py``); a case the child died on is a crash, one it did not finish a hang."""
    results = ws.root / "app-results.jsonl"
    done: dict[int, Outcome] = {}
    todo = list(range(len(app_cases)))
    while todo:
        batch = todo[:APP_BATCH]
        rss, code, seconds = _app_batch(ws, [(i, app_cases[i].app) for i in batch], results,
                                        timeout * len(batch) + 120)
        for line in results.read_text().splitlines() if results.exists() else []:
            r = json.loads(line)
            if r["index"] in batch and r["index"] not in done:
                done[r["index"]] = _judge_app(app_cases[r["index"]], r, rss)
        results.unlink(missing_ok=True)
        left = [i for i in batch if i not in done]
        if left:                            # the child died or hung on the first one left
            status = "hang" if code is None else f"crash (exit {code})"
            done[left[0]] = Outcome(app_cases[left[0]], status, -1, f"after {seconds:.0f} s",
                                    max_rss=rss)
        todo = [i for i in todo if i not in done]
    return [done[i] for i in range(len(app_cases))]


def _app_batch(ws: Workspace, actions: list, results: Path, timeout: float
               ) -> tuple[int, int | None, float]:
    """Fork a child that runs ``actions`` in one window; its peak memory, exit status (None when
    killed for taking longer than ``timeout``) and seconds."""
    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, 1)
            from fuzz_app import run_batch

            code = run_batch(str(ws.corpus), str(ws.model), actions, str(results))
        except BaseException:
            traceback.print_exc()
        finally:
            os._exit(code)
    while True:
        done, wstatus, usage = os.wait4(pid, os.WNOHANG)
        if done:
            return usage.ru_maxrss * 1024, os.waitstatus_to_exitcode(wstatus), \
                time.perf_counter() - t0
        if time.perf_counter() - t0 > timeout:
            os.kill(pid, signal.SIGKILL)
            _, wstatus, usage = os.wait4(pid, 0)
            return usage.ru_maxrss * 1024, None, time.perf_counter() - t0
        time.sleep(0.05)


def _judge_app(case: Case, report: dict, rss: int) -> Outcome:
    """An app case: a dialog naming a file the case opened ("refused"), or the file opened
    ("ok"); anything else (an internal error, an exception, no answer, the window gone) fails."""
    status, message = report["status"], report.get("message", "")
    names = {Path(a).name for a in case.app[1:3] if a} | {Path(a).parent.name for a in case.app[1:3]
                                                         if a}
    if status == "dialog":
        status = "refused" if any(n and n in message for n in names) else "unclear message"
    elif status in ("opened", "asked"):     # a question (words to pronounce) is the app working
        status = "ok"
    return Outcome(case, status, 2 if status == "refused" else 0, message[:300],
                   seconds=report.get("seconds", 0.0), max_rss=rss)


# --------------------------------------------------------------------------- the table
def table(outcomes: list[Outcome]) -> str:
    """Markdown table: per category the cases and their outcomes."""
    by_cat: dict[str, Counter] = defaultdict(Counter)
    rss: dict[str, int] = defaultdict(int)
    slow: dict[str, float] = defaultdict(float)
    for o in outcomes:
        by_cat[o.case.category][o.status] += 1
        rss[o.case.category] = max(rss[o.case.category], o.max_rss)
        slow[o.case.category] = max(slow[o.case.category], o.seconds)
    failures = sorted({o.status for o in outcomes if o.failed})
    head = ["category", "cases", "exit 0", "exit 2 (refused)", "exit 3 (skipped)", "tracebacks",
            "hangs",
            "partial or clobbered", *[f for f in failures if f not in
                                      ("traceback", "hang", "partial", "clobbered")],
            "slowest run (s)", "peak memory (MiB)"]
    rows = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    total: Counter = Counter()
    for cat in CATEGORIES:
        c = by_cat.get(cat)
        if not c:
            continue
        total.update(c)
        extra = [str(c[f]) for f in failures if f not in ("traceback", "hang", "partial",
                                                          "clobbered")]
        rows.append(f"| {cat} | {sum(c.values())} | {c['ok']} | {c['refused']} "
                    f"| {c['skipped bad files']} | {c['traceback']} "
                    f"| {c['hang']} | {c['partial'] + c['clobbered']} | " + "".join(
                        f"{x} | " for x in extra) + f"{slow[cat]:.1f} | {rss[cat] / 2**20:.0f} |")
    extra = [str(total[f]) for f in failures if f not in ("traceback", "hang", "partial",
                                                          "clobbered")]
    rows.append(f"| **all** | {sum(total.values())} | {total['ok']} | {total['refused']} | "
                f"{total['skipped bad files']} | "
                f"{total['traceback']} | {total['hang']} | {total['partial'] + total['clobbered']} "
                f"| " + "".join(f"{x} | " for x in extra)
                + f"{max(slow.values(), default=0):.1f} | {max(rss.values(), default=0) / 2**20:.0f} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description="the long bad-input fuzz run (make fuzz)")
    p.add_argument("--cases", type=int, default=3300)
    p.add_argument("--seed", type=int, default=14)
    p.add_argument("--workdir", type=Path, help="keep the cases here (default a temporary folder)")
    p.add_argument("--timeout", type=float, default=TIMEOUT_S)
    args = p.parse_args(argv)
    import tempfile

    root = args.workdir or Path(tempfile.mkdtemp(prefix="facetraj-fuzz-"))
    root.mkdir(parents=True, exist_ok=True)
    os.environ["FACETRAJ_CACHE_DIR"] = str(root / "cache")   # labels and models: never the user's
    ws = make_workspace(root)
    categories = CATEGORIES if os.environ.get("DISPLAY") else \
        tuple(c for c in CATEGORIES if c != "app")
    if "app" not in categories:
        print("no display: the app cases are left out (make fuzz runs under xvfb-run)",
              file=sys.stderr)
    outcomes, app = [], []
    t0 = time.perf_counter()
    for i, case in enumerate(cases(ws, args.cases, args.seed, categories), 1):
        if case.app is not None:
            app.append(case)
            continue
        outcomes.append(run_case(case, lambda c: run_forked(c, args.timeout)))
        _say(outcomes[-1])
        if i % 100 == 0:
            print(f"{i} cases, {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
    for o in run_app_cases(ws, app, args.timeout):
        outcomes.append(o)
        _say(o)
    print(f"\n{len(outcomes)} cases (seed {args.seed}) in {time.perf_counter() - t0:.0f} s; "
          f"memory limit {MEMORY_LIMIT >> 20} MiB above the parent, timeout {args.timeout:g} s "
          f"per run\n")
    print(table(outcomes))
    if args.workdir is None:
        shutil.rmtree(root, ignore_errors=True)
    return 1 if any(o.failed for o in outcomes) else 0


def _say(o: Outcome) -> None:
    if o.failed:
        what = f"facetraj {' '.join(o.case.argv)}" if o.case.app is None else f"app {o.case.app}"
        print(f"FAIL {o.status}: [{o.case.category}] {o.case.name}: {what}\n    {o.detail}",
              flush=True)


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    sys.exit(main())
