"""Every row of docs/bad-input.md, produced for real: the documented message is the one given."""

import errno
import json
import logging
import os
import re
import struct
import tempfile
import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from alignment_cases import alignment_cases
from conftest import edited_model_file
from fuzzing import _c3d_rate

from facetraj_app.display import require_display
from facetraj_engine.config import SynthConfig
from facetraj_engine.data import PhoneSegment, Utterance
from facetraj_engine.errors import FILE_WARNINGS, FacetrajError
from facetraj_engine.fanout import fan_out
from facetraj_engine.io.audio import read_audio
from facetraj_engine.io.corpus import CorpusInfo, load_corpus, save_corpus_info
from facetraj_engine.io.export import TRAJECTORY_SUFFIXES
from facetraj_engine.io.files import atomic_write, check_output_path
from facetraj_engine.io.labelfiles import (
    read_lab,
    read_label_file,
    read_labels,
    read_textgrid,
    validate_phones,
)
from facetraj_engine.io.markerfiles import read_c3d, read_markers, read_mocha_ema, write_c3d
from facetraj_engine.labels.labelmap import read_label_map
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.training import MarkerSetup, train

DOC = Path(__file__).resolve().parent.parent / "docs" / "bad-input.md"


def _rows():
    rows = []
    for line in DOC.read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 3 and cells[0] not in ("case", "---") and not cells[0].startswith("-"):
            rows.append((cells[0], re.findall(r'"([^"]+)"', cells[2])))
    return rows


def _copy_utt(src: Path, dst: Path, stem: str, utt_id: str = "u"):
    for ext in ("wav", "TextGrid", "c3d"):
        (dst / f"{utt_id}.{ext}").write_bytes((src / f"{stem}.{ext}").read_bytes())


class BadInputs:
    """What the bad inputs are made from: the toy corpus's utterance ``toy030``, a model, and a
    scratch folder ``tmp`` to write them in."""

    def __init__(self, tmp: Path, toy_dir: Path, model: Model):
        self.tmp, self.toy_dir, self.model = tmp, toy_dir, model
        self.wav = toy_dir / "toy030.wav"
        self.audio, self.rate = read_audio(self.wav)
        self.phones = read_labels(toy_dir / "toy030.TextGrid")
        self.info = load_corpus(toy_dir).info
        self.toy_markers = read_c3d(toy_dir / "toy030.c3d").markers
        self.setup = MarkerSetup(self.info.fixed_markers, self.info.upper_lip, self.info.lower_lip)
        self.names = self.info.marker_names
        self.lab1 = next(s.label for s in self.phones if s.label != "sil")
        self.gappy = self.toy_markers.copy()
        self.gappy[20:40] = np.nan
        self.sparse = np.where(np.arange(len(self.toy_markers))[:, None, None] % 3 == 0,
                               self.toy_markers, np.nan)
        self.newer = {"format": "facetraj-model", "version": 9}

    def corpus_with(self, markers=None, names=None):
        _copy_utt(self.toy_dir, self.tmp, "toy030")
        if markers is not None:
            write_c3d(self.tmp / "u.c3d", markers, 60.0, names or self.info.marker_names)
        save_corpus_info(self.tmp, CorpusInfo(**{**self.info.__dict__, "train": ["u"], "test": []}))
        return load_corpus(self.tmp).utterance("u")

    def small_corpus(self, short: tuple[str, ...] = ()) -> Path:
        """Three toy utterances in ``tmp/c``: toy001's C3D truncated, or the markers of the
        utterances in ``short`` shorter than their audio."""
        root = self.tmp / "c"
        root.mkdir()
        for utt in ("toy000", "toy001", "toy030"):
            _copy_utt(self.toy_dir, root, utt, utt)
        for utt in short:
            write_c3d(root / f"{utt}.c3d", read_c3d(root / f"{utt}.c3d").markers[:-20], 60.0,
                      self.names)
        if not short:
            (root / "toy001.c3d").write_bytes((root / "toy001.c3d").read_bytes()[:300])
        save_corpus_info(root, CorpusInfo(**{**self.info.__dict__, "train": ["toy000", "toy001"],
                                             "test": ["toy030"]}))
        return root

    def write(self, name: str, data: bytes | str) -> Path:
        path = self.tmp / name
        path.write_bytes(data if isinstance(data, bytes) else data.encode())
        return path

    def with_phone(self, label: str):
        return [PhoneSegment(s.start, s.end, label if i == 1 else s.label)
                for i, s in enumerate(self.phones)]


def audio_and_label_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Audio and label files."""
    return {
    "audio file missing": lambda: read_audio(f.tmp / "none.wav"),
    "audio file of 0 bytes": lambda: read_audio(f.write("e.wav", b"")),
    "corrupt or unreadable audio": lambda: read_audio(f.write("c.wav", b"RIFF....WAVEjunk" * 9)),
    "audio with no samples": lambda: (sf.write(f.tmp / "n.wav", np.zeros(0), 16000),
                                      read_audio(f.tmp / "n.wav")),
    "sample rate below 8 kHz": lambda: (sf.write(f.tmp / "r.wav", np.zeros(100), 6000),
                                        read_audio(f.tmp / "r.wav")),
    "stereo or multi-channel audio": lambda: (sf.write(f.tmp / "s.wav", np.zeros((100, 2)), 16000),
                                              read_audio(f.tmp / "s.wav")),
    "labels that end before or after the audio": lambda: validate_phones(
        [PhoneSegment(0, 1, "a")], 2.0, "l.lab"),
    "labels that start late": lambda: validate_phones([PhoneSegment(0.5, 2, "a")], 2.0, "l.lab"),
    "overlapping or unsorted labels": lambda: validate_phones(
        [PhoneSegment(0, 1.2, "a"), PhoneSegment(1, 2, "b")], 2.0, "l.lab"),
    "a segment that ends before it starts": lambda: validate_phones(
        [PhoneSegment(0, 1, "a"), PhoneSegment(1, 0.5, "b")], 2.0, "l.lab"),
    "an empty label file": lambda: validate_phones([], 2.0, "l.lab"),
    "unknown label format": lambda: read_labels(f.tmp / "x.seg"),
    "a phone the model does not know": lambda: (synthesize(f.model, f.audio, f.rate, f.with_phone("ux")),
                                                synthesize(f.model, f.audio, f.rate, f.with_phone("zz"))),
    "label text that is not UTF-8": lambda: read_lab(f.write("b.lab", b"0 1 \xe9\xff\xfe\xfa")),
    "an ARPAbet phone the model has never seen (a model trained on a few sentences)": lambda:
        synthesize(f.model, f.audio, f.rate, f.with_phone("zh"), source="u.lab"),
    "an audio file cut short (a WAV or FLAC holding fewer samples than its header says)": lambda:
        read_audio(f.write("t.wav", f.wav.read_bytes()[:3000])),
    "a WAV header that does not match its data (block size or byte rate against channels, bits "
    "and rate; a 'data' chunk of part of a sample frame; bytes after the 'fmt ' chunk that are not "
    "a chunk)": lambda: read_audio(f.write("h.wav", _block_size_damaged(f.wav.read_bytes()))),
    "audio read with `--read-damaged-audio`": lambda:
        read_audio(f.write("r.wav", f.wav.read_bytes()[:3000]), allow_damaged=True),
    "an output format facetraj does not write (`face.bvh`, `face.glb`)": lambda:
        check_output_path(f.tmp / "face.bvh", formats=TRAJECTORY_SUFFIXES, probe=True),
    "an output in a place that takes no new files (`/proc/x.tsv`)": lambda:
        check_output_path("/proc/x.tsv", formats=TRAJECTORY_SUFFIXES, probe=True),
    }


def _block_size_damaged(wav: bytes) -> bytes:
    """``wav`` with its fmt chunk's block size (bytes 32-33) made wrong."""
    return wav[:32] + struct.pack("<H", struct.unpack("<H", wav[32:34])[0] + 1) + wav[34:]


def marker_and_training_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Marker files, training and synthesis."""
    return {
    "a C3D whose marker set differs from the corpus": lambda: f.corpus_with(
        f.toy_markers[:, :11], f.names[:11]),
    "a marker file that is not C3D": lambda: read_c3d(f.write("m.c3d", b"x" * 600)),
    "markers shorter than the audio": lambda: f.corpus_with(f.toy_markers[:40]),
    "markers mostly missing (NaN)": lambda: f.corpus_with(f.sparse),
    "marker gaps longer than 100 ms": lambda: train(
        [Utterance("g", f.audio, f.rate, f.phones, f.gappy, 60.0, f.names)], f.setup),
    "training utterances with different marker sets": lambda: train(
        [Utterance("a", f.audio, f.rate, f.phones, f.toy_markers, 60.0, f.names),
         Utterance("b", f.audio, f.rate, f.phones, f.toy_markers[:, :11], 60.0, f.names[:11])], f.setup),
    "a one-frame marker file": lambda: train(
        [Utterance("a", f.audio, f.rate, f.phones, f.toy_markers[:1], 60.0, f.names)], f.setup),
    "audio too short to synthesize (under two marker frames)": lambda: synthesize(
        f.model, f.audio[:200], f.rate, None, SynthConfig(mode="acoustic")),
    "phonetic synthesis without labels": lambda: synthesize(f.model, f.audio, f.rate, None),
    }


def model_and_corpus_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Model files and corpus folders."""
    return {
    "a model file that is not ours": lambda: (np.savez(f.tmp / "o.npz", a=np.zeros(2)),
                                              Model.load(f.tmp / "o.npz")),
    "a truncated model file": lambda: Model.load(
        f.write("t.npz", f.model.save(f.tmp / "full.npz").read_bytes()[:500])),
    "a model file from a newer facetraj": lambda: (
        np.savez(f.tmp / "n.npz", meta=np.array(json.dumps(f.newer))), Model.load(f.tmp / "n.npz")),
    "a model file whose LSF index was damaged": lambda: Model.load(edited_model_file(
        f.model.save(f.tmp / "full.npz"), f.tmp / "d.npz", ix_offsets=f.model.index.offsets[:-1])),
    "a corpus folder without corpus.json": lambda: load_corpus(f.tmp),
    "a corpus.json that is not JSON": lambda: (f.write("corpus.json", "{"), load_corpus(f.tmp)),
    "a corpus.json naming an unknown marker": lambda: (
        save_corpus_info(f.tmp, CorpusInfo(**{**f.info.__dict__, "lower_lip": "NOSE"})),
        load_corpus(f.tmp)),
    }


def file_format_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Label maps, label and marker file details."""
    return {
    "an output file that exists": lambda: (f.write("o.tsv", "x"),
                                           atomic_write(f.tmp / "o.tsv", overwrite=False).__enter__()),
    "an unknown marker format": lambda: read_markers(f.tmp / "m.trc"),
    "a MOCHA EMA file with the wrong column count": lambda: read_mocha_ema(
        f.write("x.ema", "0 1 2 3\n1 1 2 3\n")),
    "a label map line that is not a pair": lambda: read_label_map(f.write("map.txt", "a b c\n")),
    "a label map that maps a label to a phone the model does not know": lambda: synthesize(
        f.model, f.audio, f.rate, f.phones, label_map=read_label_map(f.write("m.tsv", f"{f.lab1}\tzz\n"))),
    "a label file or label map given as a folder": lambda: (
        (f.tmp / "f.lab").mkdir(), read_labels(f.tmp / "f.lab")),
    "TextGrid intervals out of order or overlapping": lambda: read_textgrid(f.write(
        "o.TextGrid", (f.toy_dir / "toy030.TextGrid").read_text().replace(
            "xmin = 0.25", "xmin = 0.001", 1))),
    "a .lab time that is not a finite number (`inf`, `nan`)": lambda: read_lab(
        f.write("i.lab", "0 0.5 a\n0.5 inf b\n")),
    "an empty phone tier": lambda: read_labels(f.write("e.lab", "# nothing\n")),
    "a transcript (`<id>.txt`) that is not UTF-8": lambda: (
        f.write("u.txt", b"caf\xe9"), f.corpus_with()),
    "markers whose names differ from the corpus (same count)": lambda: f.corpus_with(
        f.toy_markers, [n + "_X" if i == 3 else n for i, n in enumerate(f.names)]),
    "marker table or EMA times that give no sane rate": lambda: read_markers(f.write(
        "t.tsv", "time\ta_x\ta_y\ta_z\n0\t1\t2\t3\n1e-6\t1\t2\t3\n")),
    "marker times that do not increase": lambda: read_markers(f.write(
        "t.tsv", "time\ta_x\ta_y\ta_z\n0\t1\t2\t3\n0\t1\t2\t3\n")),
    }


def articulograph_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Articulograph files (tests/articulograph.py writes them to their published layouts)."""
    from articulograph import sensors, write_ag501, write_est, write_mview_v5, write_txy
    from scipy.io import savemat

    from facetraj_engine.io.corpus import init_corpus

    def ag501(name: str = "s.pos", xyz=None):
        return write_ag501(f.tmp / name, sensors(10, 4) if xyz is None else xyz)

    def dead_channel():
        xyz = sensors(10, 4)
        xyz[:, 1] = np.nan
        return ag501("d.pos", xyz)

    def pos_folder():
        for ext in ("wav", "TextGrid"):
            (f.tmp / f"u.{ext}").write_bytes((f.toy_dir / f"toy030.{ext}").read_bytes())
        ag501("u.pos", sensors(400, 4))
        return init_corpus(f.tmp, upper_lip="Ch1", lower_lip="Ch2")

    return {
    "a Carstens .pos file cut short, or with another channel count than its header says":
        lambda: read_markers(f.write("c.pos", ag501().read_bytes()[:-6])),
    "a Carstens AG50x header that is damaged": lambda: read_markers(f.write(
        "h.pos", ag501().read_bytes().replace(b"NumberOfChannels", b"NumberOfSensors"))),
    "a sensor without a single valid sample": lambda: read_markers(dead_channel()),
    "missing samples (NaN, XRMB's 1000000, a status not OK, an rms over 30)": lambda: read_markers(
        write_txy(f.tmp / "m.txy", sensors(9, 8)[..., :2], np.arange(9) * 7.0,
                  np.eye(9, 8, dtype=bool))),
    "channel names that do not fit the file": lambda: read_markers(ag501(), channel_names=["UL"]),
    "no fixed markers for data not known to be head-corrected": pos_folder,
    "an EST track whose channels have no sensor names": lambda: read_markers(write_est(
        f.tmp / "e.ema", ["a", "b", "c"], np.zeros((4, 3)), np.arange(4) / 100)),
    "an EST track without names of exactly MOCHA's 20 channels": lambda: read_markers(write_est(
        f.tmp / "m.ema", [], np.zeros((4, 20)), np.arange(4) / 500, named=False)),
    "an EST track cut short": lambda: read_markers(f.write("t.ema", write_est(
        f.tmp / "t0.ema", ["a_x", "a_y"], np.zeros((4, 2)), np.arange(4) / 100).read_bytes()[:-4])),
    "an MVIEW file that is not a readable MATLAB file": lambda: read_markers(f.write(
        "x.mat", b"MATLAB 5.0 MAT-file" + b"\0" * 200)),
    "a MATLAB file without an MVIEW struct": lambda: (savemat(f.tmp / "o.mat", {"x": np.zeros(3)}),
                                                      read_markers(f.tmp / "o.mat")),
    "an MVIEW file without a sensor channel": lambda: read_markers(write_mview_v5(
        f.tmp / "a.mat", [{"NAME": "AUDIO", "SRATE": 16000.0, "SIGNAL": np.zeros((800, 1))}])),
    "an XRMB file with another column count": lambda: read_markers(f.write("x.txy", "0 1 2\n7 1 2\n")),
    }


def model_detail_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """C3D details, damaged model entries, corpus.json details."""
    return {
    "a C3D whose header or parameters ask for more than the file holds": lambda: read_c3d(
        f.write("h.c3d", (f.toy_dir / "toy030.c3d").read_bytes()[:3000])),
    "a C3D whose parameter section is damaged": lambda: read_c3d(f.write(
        "p.c3d", _damaged_parameter((f.toy_dir / "toy030.c3d").read_bytes()))),
    "a C3D frame rate outside 1-10000 Hz": lambda: read_c3d(f.write(
        "r.c3d", _c3d_rate((f.toy_dir / "toy030.c3d").read_bytes(), 1e6))),
    "a model whose metadata has wrong types or values": lambda: Model.load(edited_model_file(
        f.model.save(f.tmp / "full.npz"), f.tmp / "m.npz", meta=np.array(json.dumps(
            {**_meta(f.tmp / "full.npz"), "marker_rate": "60"})))),
    "a model array of the wrong shape or data type": lambda: Model.load(edited_model_file(
        f.model.save(f.tmp / "full.npz"), f.tmp / "m.npz", cb_lsf=f.model.codebook.lsf[:, 1:])),
    "a model array holding NaN or infinite values": lambda: Model.load(edited_model_file(
        f.model.save(f.tmp / "full.npz"), f.tmp / "m.npz", means=f.model.means * np.nan)),
    "a model entry whose .npy header asks for too much memory": lambda: Model.load(
        _forged_header(f.model.save(f.tmp / "full.npz"), f.tmp / "m.npz")),
    "a model entry with an unsupported zip compression method": lambda: Model.load(
        _bzip2(f.model.save(f.tmp / "full.npz"), f.tmp / "m.npz")),
    "a corpus.json that is not an object": lambda: (f.write("corpus.json", "[]"), load_corpus(f.tmp)),
    "a corpus.json entry of the wrong type or range": lambda: (f.write("corpus.json", json.dumps(
        {**f.info.to_json(), "marker_rate": 0})), load_corpus(f.tmp)),
    "a corpus.json nested too deeply": lambda: (f.write("corpus.json", "[" * 10**5 + "]" * 10**5),
                                                load_corpus(f.tmp)),
    "a corpus.json whose data folder is missing": lambda: (f.write("corpus.json", json.dumps(
        {**f.info.to_json(), "data_dir": "gone"})), load_corpus(f.tmp)),
    "a corpus.json whose sensor_roles name a marker it does not have": lambda: (f.write(
        "corpus.json", json.dumps({**f.info.to_json(), "sensor_roles": {"tongue": ["XX"]}})),
        load_corpus(f.tmp)),
    }


def output_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Options, outputs and the display."""
    return {
    "an option value out of its range (`-N 0`, `--xi nan`, `--lpc-order 0`)": lambda: _parse(
        ["synth", "m.npz", "a.wav", "-o", "o.tsv", "-N", "0"]),
    "a folder at the output path (even with `--overwrite`)": lambda: (
        (f.tmp / "o.tsv").mkdir(), atomic_write(f.tmp / "o.tsv").__enter__()),
    "an output whose parent is a regular file": lambda: (
        f.write("f", "x"), atomic_write(f.tmp / "f" / "o.tsv").__enter__()),
    "an output name too long for the file system": lambda: atomic_write(
        f.tmp / ("x" * 300)).__enter__(),
    "an output folder without write permission": lambda: _patched(
        os, "access", lambda *a: False, lambda: atomic_write(f.tmp / "o.tsv").__enter__()),
    "an output on a read-only file system": lambda: _patched(
        tempfile, "mkstemp", _erofs, lambda: atomic_write(f.tmp / "o.tsv").__enter__()),
    "a window (`facetraj gui`, `facetraj live` without `-o`) on a machine without a display":
        lambda: _patched(os, "environ", {k: v for k, v in os.environ.items() if k not in (
            "DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM")},
            lambda: require_display("the Live window")),
    }


def model_value_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Model arrays whose values or cross-references are wrong (issue 26)."""
    def damaged(**arrays):
        return lambda: Model.load(edited_model_file(f.model.save(f.tmp / "full.npz"),
                                                    f.tmp / "m.npz", **arrays))

    cb, meta = f.model.codebook, lambda: _meta(f.model.save(f.tmp / "full.npz"))
    return {
    "a model array of the wrong kind of numbers (fractions where ids belong)": damaged(
        cb_contexts=cb.contexts.astype(float)),
    "a model's ids beyond what they index (phones, markers, utterances)": damaged(
        cb_contexts=cb.contexts + len(f.model.phones)),
    "a model's LSFs outside 0 to pi or out of order": damaged(cb_lsf=cb.lsf[:, ::-1].copy()),
    "a model's phone tokens that end before they start": damaged(
        cb_token_start=cb.token_end + 1.0),
    "a model's PCs that are not orthonormal": damaged(pca_components=2 * f.model.pca.components),
    "a model's distances that are not a distance matrix": damaged(distances=-f.model.distances),
    "a model's cross-validated settings out of range": lambda: Model.load(edited_model_file(
        f.model.save(f.tmp / "full.npz"), f.tmp / "m.npz", meta=np.array(json.dumps(
            {**meta(), "tuned": {"settings": {"n_context_phones": 10**9}}})))),
    }


def corpus_command_cases(f: BadInputs) -> dict[str, Callable[[], object]]:
    """Corpus-wide commands with several jobs, label alphabets, sizes (issue 26)."""
    return {
    "a bad file in a corpus-wide command with several jobs (`-j 2`)":
        lambda: _cli(["eval", str(f.model.save(f.tmp / "m.npz")), str(f.small_corpus()), "-j", "2"]),
    "bad files left out with `--skip-bad`": lambda: _cli(
        ["eval", str(f.model.save(f.tmp / "m.npz")), str(f.small_corpus()), "-j", "2", "--skip-bad"]),
    "a worker process that dies (killed, out of memory)": lambda: list(fan_out(_exit_on_b, "abc", 2)),
    "the same problem in many files of a corpus": lambda: _cli(
        ["eval", str(f.model.save(f.tmp / "m.npz")), str(f.small_corpus(short=("toy000", "toy030")))]),
    "a label file in another phone alphabet (TIMIT, MOCHA-TIMIT, SAMPA, X-SAMPA, IPA)": lambda:
        read_label_file(f.write("s.lab", "".join(f"{s.start} {s.end} {_SAMPA.get(s.label, s.label)}\n"
                                             for s in f.phones)), f.rate, f.phones[-1].end),
    "labels in no phone alphabet facetraj knows": lambda: read_label_file(
        f.write("z.lab", "".join(f"{s.start} {s.end} {'zz' if i == 1 else s.label}\n"
                                 for i, s in enumerate(f.phones))), f.rate, f.phones[-1].end),
    "an audio header that claims more samples than the file holds": lambda: read_audio(
        _huge_flac(f.tmp, f.audio, f.rate)),
    "a label file or marker table over 256 MiB": lambda: (
        open(f.tmp / "big.lab", "wb").truncate(300 << 20), read_labels(f.tmp / "big.lab")),
    }


CASE_GROUPS = (audio_and_label_cases, marker_and_training_cases, model_and_corpus_cases,
               file_format_cases, model_detail_cases, output_cases, model_value_cases,
               corpus_command_cases, articulograph_cases)

#: the toy phones in SAMPA
_SAMPA = {"aa": "A:", "iy": "i:", "uw": "u:"}


def _exit_on_b(item: str) -> str:
    if item == "b":
        os._exit(9)
    return item


def _cli(argv: list[str]) -> None:
    """Run ``facetraj argv``; its stderr is the message (raised when the exit status is not 0)."""
    import contextlib
    import io

    from facetraj.cli import main

    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(argv)
    if code != 0:
        raise FacetrajError(f"exit {code}: {err.getvalue()}")
    logging.getLogger("facetraj").info("%s", err.getvalue())


def _huge_flac(tmp: Path, audio: np.ndarray, rate: int) -> Path:
    sf.write(tmp / "a.flac", audio, rate)
    d = bytearray((tmp / "a.flac").read_bytes())
    d[21] |= 0x0F
    d[22:26] = b"\xff\xff\xff\xff"
    (tmp / "huge.flac").write_bytes(bytes(d))
    return tmp / "huge.flac"


def produce(case: str, tmp: Path, toy_dir: Path, model: Model, caplog) -> str:
    """Make the bad input of ``case`` happen; return the message (error or log)."""
    inputs = BadInputs(tmp, toy_dir, model)
    cases: dict[str, Callable[[], object]] = {}
    for group in CASE_GROUPS:
        cases.update(group(inputs))
    cases.update(alignment_cases(tmp))
    caplog.clear()
    FILE_WARNINGS.clear()       # each case counts its own files
    try:
        with caplog.at_level(logging.INFO):
            cases[case]()
    except (FacetrajError, FileExistsError) as exc:
        return str(exc) + "\n" + caplog.text
    return caplog.text


def _meta(path: Path) -> dict:
    with np.load(path) as z:
        return json.loads(str(z["meta"]))


def _forged_header(src: Path, dst: Path) -> Path:
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item)
            if item.filename == "cb_lsf.npy":
                hdr = "{'descr': '<f8', 'fortran_order': False, 'shape': (1099511627776, 18), }"
                hdr = hdr.ljust(117) + "\n"
                data = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(hdr)) + hdr.encode()
            zout.writestr(item.filename, data)
    return dst


def _bzip2(src: Path, dst: Path) -> Path:
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_BZIP2) as zout:
        for item in zin.infolist():
            zout.writestr(item.filename, zin.read(item))
    return dst


def _damaged_parameter(c3d: bytes) -> bytes:
    """The C3D with POINT:USED's offset to the next entry pointing far past the section."""
    i = c3d.find(b"USED", 512)
    return c3d[: i + 4] + b"\xff\x7f" + c3d[i + 6:]


def _parse(argv: list[str]) -> None:
    """Parse a command line; the option parser's error (exit 2) becomes the message."""
    import contextlib
    import io

    from facetraj.cli import build_parser

    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        try:
            build_parser().parse_args(argv)
        except SystemExit as exc:
            assert exc.code == 2
            raise FacetrajError(err.getvalue().splitlines()[-1]) from None


def _patched(module, name: str, value, action):
    old = getattr(module, name)
    setattr(module, name, value)
    try:
        return action()
    finally:
        setattr(module, name, old)


def _erofs(*args, **kwargs):
    raise OSError(errno.EROFS, "Read-only file system")


@pytest.mark.parametrize("case, phrases", _rows(), ids=[r[0] for r in _rows()])
def test_documented_message(case, phrases, tmp_path, toy_corpus_dir, toy_model, caplog):
    assert phrases, f"no quoted message in the row {case!r}"
    message = produce(case, tmp_path, toy_corpus_dir, toy_model, caplog)
    for phrase in phrases:
        assert phrase in message, f"{case}: {phrase!r} not in {message!r}"


def test_every_row_is_checked():
    assert len(_rows()) >= 30
