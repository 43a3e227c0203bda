"""Tiny articulograph files written to each published layout, for the readers' tests and the fuzz
run: Carstens AG500 and AG50x (V002, V003) ``.pos``, NDI WaveFront TSV, MVIEW ``.mat`` (v5 via
scipy, v7.3 as MATLAB lays out HDF5), XRMB ``.txy``, EST tracks (ascii, binary).

Positions are given as ``(frames, sensors, 3)`` in the file's own axes and units (mm unless said).
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from facetraj_engine.data import PhoneSegment

rng = np.random.default_rng(37)


def sensors(frames: int, count: int, seed: int = 0) -> np.ndarray:
    """Smooth random trajectories ``(frames, count, 3)`` in mm around distinct rest positions."""
    r = np.random.default_rng(seed)
    rest = r.uniform(-60, 60, (1, count, 3))
    t = np.arange(frames)[:, None, None] / 100.0
    freq, phase = r.uniform(0.5, 4, (1, count, 3)), r.uniform(0, 6, (1, count, 3))
    return rest + 5 * np.sin(2 * np.pi * freq * t + phase)


# --------------------------------------------------------------------------- Carstens
def carstens_values(xyz: np.ndarray, rms: np.ndarray | None = None) -> np.ndarray:
    """``(frames, channels, 7)`` float32: x y z, phi theta (deg), rms, extra."""
    out = np.zeros((*xyz.shape[:2], 7), np.float32)
    out[..., :3] = xyz
    out[..., 3] = rng.uniform(-180, 180, xyz.shape[:2])
    out[..., 4] = rng.uniform(-90, 90, xyz.shape[:2])
    out[..., 5] = 3.0 if rms is None else rms
    return out


def write_ag500(path: Path, xyz: np.ndarray, rms: np.ndarray | None = None) -> Path:
    path.write_bytes(carstens_values(xyz, rms).astype("<f4").tobytes())
    return path


def ag50x_header(channels: int, rate: float, version: int = 2, extra: list[str] = (),
                 pad: int = 2) -> bytes:
    """The AG50x text header: magic, its own length (8 digits), channels, rate, V003's further
    lines, then padding (``\\0`` and ``\\x1a`` as the AG501 writes it)."""
    body = f"NumberOfChannels={channels}\nSamplingFrequencyHz={rate:g}\n" + "".join(f"{ln}\n" for ln in extra)
    size = 15 + 9 + len(body) + pad
    return f"AG50xDATA_V00{version}\n{size:08d}\n{body}".encode() + (b"\x00\x1a" + b"\x00" * pad)[:pad]


V003_LINES = ["sweepsaver.version=2.1 (1021)", "recorded=2019-05-02 10:11:12",
              "calcpos.version=3.3 (204)", "calcpos.timestamp=2019-05-02 11:00:00",
              "calcpos.filter=lowpass", "normpos.version=2.4 (1187)",
              "normpos.timestamp=2019-05-02 11:02:00", "normpos.reference=1,2,3",
              "Taxonomic_Distance_Mean=0.31", "Taxonomic_Distance_StdDev=0.05"]


def write_ag501(path: Path, xyz: np.ndarray, rate: float = 250.0, version: int = 2,
                extra: list[str] = (), rms: np.ndarray | None = None) -> Path:
    header = ag50x_header(xyz.shape[1], rate, version, extra, pad=2 if version == 2 else 38)
    path.write_bytes(header + carstens_values(xyz, rms).astype("<f4").tobytes())
    return path


# --------------------------------------------------------------------------- NDI
def write_ndi(path: Path, xyz: np.ndarray, times: np.ndarray, status: np.ndarray | None = None,
              layout: str = "wavefront") -> Path:
    """WaveFront's export: ``wavefront`` = time, meas id, wav id, then per sensor Id, Status,
    Tx Ty Tz, Q0-Qz; ``phonlab`` = time, then per sensor Id, Frame, State, Q0-Qz, Tx Ty Tz."""
    n = xyz.shape[1]
    status = np.full(xyz.shape[:2], "OK", object) if status is None else status
    if layout == "wavefront":
        head = ["Wav Time", "Meas Id", "Wav Id"] + [c for k in range(1, n + 1) for c in (
            f"Sensor {k} Id", f"Sensor {k} Status", "Tx", "Ty", "Tz", "Q0", "Qx", "Qy", "Qz")]
    else:
        head = ["Wav Time"] + [c for k in range(n) for c in (
            "Sensor Id", "Frame", "State", "Q0", "Qx", "Qy", "Qz", "Tx", "Ty", "Tz")]
    lines = ["\t".join(head)]
    for f, t in enumerate(times):
        row = [f"{t:.4f}"] + ([str(f), str(f)] if layout == "wavefront" else [])
        for s in range(n):
            pos = ["" if status[f, s] != "OK" else f"{v:.3f}" for v in xyz[f, s]]
            quat = ["0.7071", "0.7071", "0.0000", "0.0000"]
            if layout == "wavefront":
                row += [str(s), str(status[f, s]), *pos, *quat]
            else:
                row += [str(s), str(f), str(status[f, s]), *quat, *pos]
        lines.append("\t".join(row))
    path.write_text("\n".join(lines) + "\n")
    return path


# --------------------------------------------------------------------------- XRMB
PELLETS = ("UL", "LL", "T1", "T2", "T3", "T4", "MNI", "MNM")


def write_txy(path: Path, xy_mm: np.ndarray, times_ms: np.ndarray,
              missing: np.ndarray | None = None) -> Path:
    """x, y of the 8 pellets in micrometres, 1000000 where ``missing``."""
    um = np.round(xy_mm * 1000).astype(np.int64)
    if missing is not None:
        um[missing] = 1000000
    rows = [" ".join([f"{t:.0f}", *(str(v) for v in r.ravel())]) for t, r in zip(times_ms, um, strict=True)]
    path.write_text("\n".join(rows) + "\n")
    return path


# --------------------------------------------------------------------------- EST
def write_est(path: Path, names: list[str], values: np.ndarray, times: np.ndarray,
              kind: str = "binary", byte_order: str = "10", breaks: np.ndarray | None = None,
              named: bool = True) -> Path:
    """An EST track as the Speech Tools write it (``save_est_binary_ts``, ``save_est_ts``)."""
    flags = np.ones(len(times)) if breaks is None else breaks
    header = ["EST_File Track", f"DataType {kind}"]
    header += [f"ByteOrder {byte_order}"] if kind == "binary" else []
    header += [f"NumFrames {len(times)}", f"NumChannels {values.shape[1]}", "EqualSpace 1",
               "BreaksPresent true", "CommentChar ;", ""]
    header += [f"Channel_{i} {n}" for i, n in enumerate(names)] if named else []
    header += ["EST_Header_End"]
    rows = np.column_stack([times, flags, values])
    if kind == "binary":
        body = rows.astype(">f4" if byte_order == "10" else "<f4").tobytes()
    else:
        body = "".join(f"{r[0]:f}\t{int(r[1])} \t" + " ".join(f"{v:f}" for v in r[2:]) + " \n"
                       for r in rows).encode()
    path.write_bytes("\n".join(header).encode() + b"\n" + body)
    return path


# --------------------------------------------------------------------------- MVIEW
def mview_entries(names: list[str], xyz: np.ndarray, rate: float, audio: np.ndarray | None = None,
                  audio_rate: int = 16000, phones: list[PhoneSegment] = (),
                  words: list[PhoneSegment] = (), sentence: str = "") -> list[dict]:
    """The channels of an MVIEW struct: the audio (with PHONES, WORDS, SENTENCE) then sensors."""
    def labels(segs):
        return [{"LABEL": s.label, "OFFS": np.array([[s.start, s.end]])} for s in segs]

    out = []
    if audio is not None:
        out.append({"NAME": "AUDIO", "SRATE": float(audio_rate), "SIGNAL": audio[:, None],
                    "PHONES": labels(phones), "WORDS": labels(words), "SENTENCE": sentence})
    for i, name in enumerate(names):
        out.append({"NAME": name, "SRATE": float(rate), "SIGNAL": xyz[:, i], "PHONES": [],
                    "WORDS": [], "SENTENCE": ""})
    return out


def _record(entries: list[dict], fields: list[str]) -> np.ndarray:
    arr = np.empty((1, len(entries)), dtype=[(f, "O") for f in fields])
    for i, e in enumerate(entries):
        for f in fields:
            v = e[f]
            if isinstance(v, list):
                v = _record(v, ["LABEL", "OFFS"]) if v else np.zeros((0, 0))
            arr[0, i][f] = v
    return arr


def write_mview_v5(path: Path, entries: list[dict]) -> Path:
    from scipy.io import savemat

    savemat(path, {path.stem: _record(entries, list(entries[0]))})
    return path


MAT73_HEADER = (b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon May  6 10:00:00 2019 "
                b"HDF5 schema 1.00 .").ljust(116) + b"\x00" * 8 + b"\x00\x02IM"


def write_mview_v73(path: Path, entries: list[dict]) -> Path:
    """The struct array as MATLAB v7.3 lays it out in HDF5 (see facetraj_engine.io.markerformats.mview_h5)."""
    import h5py

    count = itertools.count()
    with h5py.File(path, "w", userblock_size=512) as h5:
        refs = h5.create_group("#refs#")

        def store(value):
            name = f"r{next(count)}"
            if isinstance(value, list) and value:
                group = refs.create_group(name)
                group.attrs["MATLAB_class"] = np.bytes_(b"struct")
                for field in value[0]:
                    group.create_dataset(field, data=np.array([[store(v[field])] for v in value],
                                                              dtype=h5py.ref_dtype))
                return group.ref
            if isinstance(value, str):
                ds = refs.create_dataset(name, data=np.array([[ord(c)] for c in value] or [[0]],
                                                             dtype=np.uint16))
                ds.attrs["MATLAB_class"] = np.bytes_(b"char")
                ds.attrs["MATLAB_int_decode"] = 2
                return ds.ref
            arr = np.atleast_2d(np.asarray(value, dtype=np.float64))
            if isinstance(value, list) or arr.size == 0:
                ds = refs.create_dataset(name, data=np.array([0, 0], dtype=np.uint64))
                ds.attrs["MATLAB_empty"] = 1
            else:
                ds = refs.create_dataset(name, data=arr.T)
            ds.attrs["MATLAB_class"] = np.bytes_(b"double")
            return ds.ref

        top = h5.create_group(path.stem)
        top.attrs["MATLAB_class"] = np.bytes_(b"struct")
        for field in entries[0]:
            top.create_dataset(field, data=np.array([[store(e[field])] for e in entries],
                                                    dtype=h5py.ref_dtype))
    with open(path, "r+b") as fh:
        fh.write(MAT73_HEADER)
    return path


# --------------------------------------------------------------------------- folders
def at_rate(markers: np.ndarray, rate: float, target: float) -> np.ndarray:
    """Trajectories at another rate (linear interpolation over the gaps: a file's samples)."""
    t_in = np.arange(len(markers)) / rate
    t_out = np.arange(int((len(markers) - 1) / rate * target) + 1) / target
    flat = markers.reshape(len(markers), -1)
    out = np.stack([np.interp(t_out, t_in[np.isfinite(c)], c[np.isfinite(c)]) for c in flat.T], axis=1)
    return out.reshape(len(t_out), *markers.shape[1:])


def _toy(toy_corpus_dir: Path, utt_id: str):
    from facetraj_engine.io.markerfiles import read_c3d

    return read_c3d(toy_corpus_dir / f"{utt_id}.c3d").markers


#: the toy markers written as XRMB's pellets UL LL T1 T2 T3 T4 MNI MNM (the toy face has no
#: tongue: nose and cheek markers stand in for T1-T4)
XRMB_FROM_TOY = ("UL_C", "LL_C", "NB", "NT", "LC_R", "CHK_R", "CHIN", "JAW_R")
#: a toy corpus's first utterances
IDS = ["toy000", "toy001", "toy002", "toy003", "toy004", "toy005"]
#: what write_folder writes, and each kind's marker file suffix
FOLDER_KINDS = {"ag501": ".pos", "ag500": ".pos", "ndi": ".tsv", "est": ".ema", "xrmb": ".txy",
                "mview": ".mat"}


def write_folder(kind: str, toy: Path, out: Path, ids=IDS) -> Path:
    """A folder of the toy corpus's ``ids`` (tests/toycorpus.py: 12 markers at 60 Hz) in format
    ``kind``, at each format's usual rate: audio and TextGrid beside (MVIEW: inside, v5 and v7.3
    in turn; XRMB: the z, y of the markers of :data:`XRMB_FROM_TOY` as the pellets' x, y)."""
    import shutil

    from toycorpus import NAMES

    from facetraj_engine.io.labelfiles import read_textgrid

    out.mkdir(parents=True, exist_ok=True)
    for utt in ids:
        m = _toy(toy, utt)
        if kind != "mview":
            for ext in ("wav", "TextGrid"):
                shutil.copy(toy / f"{utt}.{ext}", out / f"{utt}.{ext}")
        if kind == "ag501":
            write_ag501(out / f"{utt}.pos", at_rate(m, 60, 250), 250.0)
        elif kind == "ag500":
            padded = np.concatenate([m, np.zeros((len(m), 12 - m.shape[1], 3))], axis=1)
            write_ag500(out / f"{utt}.pos", at_rate(padded, 60, 200))
        elif kind == "ndi":
            m100 = at_rate(m, 60, 100)
            write_ndi(out / f"{utt}.tsv", m100, np.arange(len(m100)) / 100)
        elif kind == "est":
            m200 = at_rate(m, 60, 200)
            names = [f"{n}_{a}" for n in NAMES for a in "xyz"]
            write_est(out / f"{utt}.ema", names, m200.reshape(len(m200), -1), np.arange(len(m200)) / 200)
        elif kind == "xrmb":
            m = at_rate(m, 60, 145.6)[:, [NAMES.index(n) for n in XRMB_FROM_TOY]]
            write_txy(out / f"{utt}.txy", np.stack([m[..., 2], m[..., 1]], axis=-1),
                      np.arange(len(m)) * 1000 / 145.6)
        elif kind == "mview":
            import soundfile as sf

            audio, rate = sf.read(toy / f"{utt}.wav")
            phones = read_textgrid(toy / f"{utt}.TextGrid")
            writer = write_mview_v5 if int(utt[-1]) % 2 else write_mview_v73
            writer(out / f"{utt}.mat", mview_entries(NAMES, at_rate(m, 60, 100)[:, :, [2, 0, 1]], 100.0,
                                                     audio, rate, phones, [], "toy sentence"))
    return out


# --------------------------------------------------------------------------- MVIEW from MOCHA
#: HPRC's sensors (Haskins' MVIEW files) and the MOCHA-TIMIT coil each is made of: the tongue
#: rear, body and tip, the lips and the jaw (MOCHA's lower incisor)
HPRC_FROM_MOCHA = {"TR": "TD", "TB": "TB", "TT": "TT", "UL": "UL", "LL": "LL", "JAW": "LI"}
#: the two HPRC sensors MOCHA has no coil for, made up from the lips and the jaw (mm, facetraj's
#: axes x right, y up, z forward): the mouth's left corner 24 mm to the left of the lips' midpoint
#: and 12 mm behind it, the jaw's left sensor 30 mm left of JAW, 6 mm up and 38 mm back
ML_FROM_LIPS = np.array([-24.0, 0.0, -12.0])
JAWL_FROM_JAW = np.array([-30.0, 6.0, -38.0])
HPRC_NAMES = ["TR", "TB", "TT", "UL", "LL", "ML", "JAW", "JAWL"]


def mview_from_mocha(mocha: Path, out: Path, rate: float = 100.0) -> Path:
    """An MVIEW ``.mat`` file in HPRC's layout made from the MOCHA-TIMIT sample ``mocha``
    (``fsew0_001``): the audio with its phones (MOCHA's labels mapped onto ARPAbet, upper case as
    HPRC writes them) and sentence inside, the sensors of :data:`HPRC_NAMES` at ``rate`` Hz in
    MVIEW's axes (x forward, y lateral, z up); ML and JAWL are made up (:data:`ML_FROM_LIPS`,
    :data:`JAWL_FROM_JAW`), so the file is 3-D as HPRC's are. Written as ``out/fsew0_001.mat``;
    nothing is written beside the sample."""
    import soundfile as sf

    from facetraj_engine.evaluation.label_accuracy import merged
    from facetraj_engine.io.labelfiles import read_lab
    from facetraj_engine.io.markerformats.mocha import read_mocha_text
    from facetraj_engine.labels.labelmap import read_label_map

    rec = read_mocha_text(mocha / "fsew0_001.ema")
    coil = {n: rec.markers[:, i] for i, n in enumerate(rec.names)}
    xyz = {name: coil[src] for name, src in HPRC_FROM_MOCHA.items()}
    xyz["ML"] = (xyz["UL"] + xyz["LL"]) / 2 + ML_FROM_LIPS
    xyz["JAWL"] = xyz["JAW"] + JAWL_FROM_JAW
    sensors = at_rate(np.stack([xyz[n] for n in HPRC_NAMES], axis=1), rec.rate, rate)
    audio, audio_rate = sf.read(mocha / "fsew0_001.wav")
    phones = [PhoneSegment(p.start, p.end, p.label.upper())
              for p in merged(read_lab(mocha / "fsew0_001.lab"), read_label_map("mocha"))]
    out.mkdir(parents=True, exist_ok=True)
    return write_mview_v5(out / "fsew0_001.mat", mview_entries(
        HPRC_NAMES, sensors[:, :, [2, 0, 1]], rate, audio, audio_rate, phones, [],
        "This was easy for us."))
