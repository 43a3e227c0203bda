"""The marker-format registry and each articulograph reader, against tiny files written to each
published layout (tests/articulograph.py) and an independent, differently written parse of the
same file: raw ``struct`` reads following Praat's AG50x reader, ``csv`` on WaveFront's column
positions, ``scipy.io.loadmat`` records and raw h5py for MVIEW, ``np.loadtxt`` for XRMB, a
header walk and ``np.frombuffer`` for EST. Every bad file: one ``InputError`` naming the file."""

from __future__ import annotations

import csv
import logging
import struct

import numpy as np
import pytest
from articulograph import (
    PELLETS,
    V003_LINES,
    mview_entries,
    sensors,
    write_ag500,
    write_ag501,
    write_est,
    write_mview_v5,
    write_mview_v73,
    write_ndi,
    write_txy,
)

from facetraj_engine.data import PhoneSegment
from facetraj_engine.errors import InputError
from facetraj_engine.io.markerfiles import read_markers
from facetraj_engine.io.markerformats import accepted, format_for, formats, marker_suffixes, read_recording

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")


def refused(path, *phrases) -> str:
    """The one-line error reading ``path`` gives; it names the file and each phrase."""
    with pytest.raises(InputError) as exc:
        read_recording(path)
    message = str(exc.value)
    assert message.startswith(str(path)) and "\n" not in message, message
    for phrase in phrases:
        assert phrase in message, message
    return message


# --------------------------------------------------------------------------- the registry
def test_every_format_is_listed_in_the_unknown_format_error(tmp_path):
    (tmp_path / "m.trc").write_text("x")
    message = refused(tmp_path / "m.trc", "unknown marker format '.trc'")
    assert message.endswith(accepted() + ")")
    names = [f.name for f in formats()]
    assert len(names) == len(set(names)) >= 9
    for f in formats():
        assert f.name in message and all(s in message for s in f.suffixes)
    assert set(marker_suffixes()) == {s for f in formats() for s in f.suffixes}
    assert ".txt" not in marker_suffixes()        # <id>.txt is an utterance's transcript


def test_content_decides_before_the_suffix(tmp_path):
    xyz = sensors(10, 4)
    assert format_for(write_ag501(tmp_path / "a.pos", xyz)).name == "Carstens AG501 .pos"
    assert format_for(write_ag500(tmp_path / "b.pos", sensors(10, 12))).name == "Carstens AG500 .pos"
    est = write_est(tmp_path / "c.ema", ["a_x", "a_y"], xyz[:, 0, :2], np.arange(10) / 100)
    assert format_for(est).name == "EST track"
    assert format_for(write_ndi(tmp_path / "d.tsv", xyz, np.arange(10) / 100)).name == "NDI Wave TSV"
    (tmp_path / "e.tsv").write_text("time\tA_x\tA_y\tA_z\n0\t1\t2\t3\n0.01\t1\t2\t3\n")
    assert format_for(tmp_path / "e.tsv").name == "TSV/CSV marker table"
    (tmp_path / "f.mat").write_bytes(b"not matlab")
    assert format_for(tmp_path / "f.mat").name == "MVIEW"      # by suffix: its reader says why
    refused(tmp_path / "f.mat", "not a readable MATLAB file")


# --------------------------------------------------------------------------- Carstens
def praat_style_ag50x(path) -> tuple[int, float, np.ndarray]:
    """Praat's way (EMA.cpp): lines 1-4 read as text, the data from the header size on, then
    per frame and sensor 7 little-endian floats read one by one."""
    with open(path, "rb") as fh:
        fh.readline()
        size = int(fh.readline())
        channels = int(fh.readline().split(b"=")[1])
        rate = float(fh.readline().split(b"=")[1])
        fh.seek(0, 2)
        n_frames = (fh.tell() - size) // (channels * 28)
        fh.seek(size)
        out = np.empty((n_frames, channels, 3))
        for f in range(n_frames):
            for s in range(channels):
                out[f, s] = struct.unpack("<7f", fh.read(28))[:3]
    return channels, rate, out


@pytest.mark.parametrize("version, extra", [(2, []), (3, V003_LINES), (1, [])])
def test_ag50x_matches_praats_reading(tmp_path, version, extra):
    xyz = sensors(40, 16, seed=version)
    path = write_ag501(tmp_path / "s.pos", xyz, 250.0, version, extra)
    rec = read_recording(path)
    channels, rate, ref = praat_style_ag50x(path)
    assert (rec.rate, len(rec.names), rec.names[:2]) == (rate, channels, ["Ch1", "Ch2"])
    assert np.abs(rec.markers - ref).max() == 0.0
    assert np.abs(rec.markers - xyz).max() < 1e-5            # float32 of the written positions
    assert rec.head_corrected is (True if version == 3 else None)   # V003's normpos lines


def test_ag500_has_no_header(tmp_path):
    xyz = sensors(30, 12)
    rec = read_recording(write_ag500(tmp_path / "s.pos", xyz))
    raw = np.fromfile(tmp_path / "s.pos", "<f4").reshape(30, 12, 7)
    assert rec.rate == 200.0 and rec.names[-1] == "Ch12" and rec.head_corrected is None
    assert np.abs(rec.markers - raw[..., :3]).max() == 0.0


def test_carstens_missing_samples(tmp_path, caplog):
    xyz = sensors(50, 8)
    xyz[10:13, 2] = np.nan
    rms = np.full((50, 8), 4.0)
    rms[20:30, 5] = 80.0                                       # a poor fit: not a position
    with caplog.at_level(logging.INFO):
        rec = read_recording(write_ag501(tmp_path / "s.pos", xyz, 200.0, rms=rms))
    assert rec.missing == 13
    assert np.isnan(rec.markers[10:13, 2]).all() and np.isnan(rec.markers[20:30, 5]).all()
    assert np.isfinite(rec.markers[:10]).all() and np.isfinite(rec.markers[30:]).all()
    assert "13 of 400 marker samples marked missing (NaN or rms over 30)" in caplog.text


def test_carstens_bad_files(tmp_path):
    path = write_ag501(tmp_path / "t.pos", sensors(10, 16), 250.0)
    data = path.read_bytes()
    (tmp_path / "cut.pos").write_bytes(data[:-5])
    refused(tmp_path / "cut.pos", "not a whole number of 448-byte frames (16 channels x 7")
    (tmp_path / "n.pos").write_bytes(data.replace(b"NumberOfChannels=16", b"NumberOfChannels=12"))
    refused(tmp_path / "n.pos", "not a whole number of 336-byte frames (12 channels")
    (tmp_path / "h.pos").write_bytes(data.replace(b"\n00000070\n", b"\n0000070x\n"))
    refused(tmp_path / "h.pos", "AG50x header line 2 is '0000070x'")
    (tmp_path / "r.pos").write_bytes(data.replace(b"=250\n", b"=0\n\0"))
    refused(tmp_path / "r.pos", "the marker rate 0 Hz (SamplingFrequencyHz) is outside")
    (tmp_path / "s.pos").write_bytes(data.replace(b"00000070", b"99999999"))
    refused(tmp_path / "s.pos", "header says it is 99999999 bytes long")
    write_ag500(tmp_path / "a500.pos", sensors(3, 12))
    (tmp_path / "a500.pos").write_bytes((tmp_path / "a500.pos").read_bytes()[:-28])
    refused(tmp_path / "a500.pos", "an AG500 file (no header) holds 980 bytes")
    (tmp_path / "dead.pos").write_bytes(data)
    xyz = sensors(10, 16)
    xyz[:, 3] = np.nan
    refused(write_ag501(tmp_path / "dead.pos", xyz), "no valid sample of Ch4 (10 samples marked missing)",
            "--channel-names NAME=-")


@pytest.mark.skipif(not __import__("shutil").which("praat"), reason="praat is not installed")
def test_ag50x_against_praat_itself(tmp_path):
    """Praat reads AG50x files (its EMA reader); this compares its positions with ours. Praat
    before its EMA reader (6.3.07, Debian 12's) answers that it does not know the file: skipped."""
    import subprocess

    xyz = sensors(12, 4, seed=5)
    path = write_ag501(tmp_path / "s.pos", xyz, 250.0, 3, V003_LINES)
    script = tmp_path / "read.praat"
    script.write_text(f'ema = Read from file: "{path}"\nSave as text file: "{tmp_path / "ema.txt"}"\n')
    run = subprocess.run(["praat", "--run", str(script)], capture_output=True, text=True, timeout=60)
    if run.returncode != 0:
        pytest.skip(f"this Praat does not read AG50x files: {run.stderr.strip().splitlines()[0][:80]}")
    numbers = {}
    for line in (tmp_path / "ema.txt").read_text().splitlines():
        key, _, value = line.strip().partition(" = ")
        if key in ("x", "y", "z"):
            numbers.setdefault(key, []).append(float(value))
    praat = np.stack([numbers[a] for a in "xyz"], axis=1).reshape(12, 4, 3)
    assert np.abs(read_recording(path).markers - praat).max() < 1e-6


# --------------------------------------------------------------------------- NDI
def wavefront_by_position(path) -> np.ndarray:
    """ematoblender's reading: 3 columns, then 9 per sensor (id, status, x, y, z, q0-qz)."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh, delimiter="\t"))[1:]
    n = (len(rows[0]) - 3) // 9
    return np.array([[[float(r[3 + 9 * s + k]) if r[3 + 9 * s + 1] == "OK" else np.nan
                       for k in (2, 3, 4)] for s in range(n)] for r in rows])


@pytest.mark.parametrize("layout", ["wavefront", "phonlab"])
def test_ndi_wave_export(tmp_path, layout):
    xyz = sensors(60, 5)
    status = np.full((60, 5), "OK", object)
    status[7:9, 1] = "Out of Volume"
    rec = read_recording(write_ndi(tmp_path / "s.tsv", xyz, 0.5 + np.arange(60) / 400, status, layout))
    assert rec.rate == 400.0 and rec.names == ["Ch1", "Ch2", "Ch3", "Ch4", "Ch5"]
    assert rec.missing == 2 and np.isnan(rec.markers[7:9, 1]).all()
    assert np.nanmax(np.abs(rec.markers - xyz)) < 5e-4            # written to 3 decimals
    if layout == "wavefront":
        ref = wavefront_by_position(tmp_path / "s.tsv")
        np.testing.assert_array_equal(np.isnan(rec.markers), np.isnan(ref))
        assert np.nanmax(np.abs(rec.markers - ref)) == 0.0


def test_ndi_dropped_rows_are_missing_frames(tmp_path):
    xyz = sensors(20, 2)
    path = write_ndi(tmp_path / "s.tsv", xyz, np.arange(20) / 100)
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[:6] + lines[9:]) + "\n")     # frames 5-7 never written
    rec = read_recording(path)
    assert rec.markers.shape == (20, 2, 3) and rec.missing == 6
    assert np.isnan(rec.markers[5:8]).all() and np.abs(rec.markers[8:] - xyz[8:]).max() < 5e-4


def test_ndi_bad_files(tmp_path):
    path = write_ndi(tmp_path / "s.tsv", sensors(5, 2), np.arange(5) / 100)
    text = path.read_text()
    (tmp_path / "t.tsv").write_text(text.replace("0.0300", "0.0100"))
    refused(tmp_path / "t.tsv", "its times do not increase (line 5)")
    (tmp_path / "v.tsv").write_text(text.replace("\tOK\t", "\tOK\tx", 1))
    refused(tmp_path / "v.tsv", "a time or position is not a number")
    (tmp_path / "h.tsv").write_text(text.splitlines()[0] + "\n")
    refused(tmp_path / "h.tsv", "has a header but no rows")
    head = text.splitlines()[0].replace("Tz", "Tw")
    (tmp_path / "z.tsv").write_text("\n".join([head, *text.splitlines()[1:]]))
    refused(tmp_path / "z.tsv", "sensor 1 (columns 4-12) has no Tx Ty Tz columns")


# --------------------------------------------------------------------------- XRMB
def test_xrmb_pellets(tmp_path):
    xy = sensors(40, 8)[..., :2]
    missing = np.zeros((40, 8), bool)
    missing[5:9, 2] = True
    path = write_txy(tmp_path / "tp001.txy", xy, np.arange(40) * 1000 / 145.6, missing)
    rec = read_recording(path)
    raw = np.loadtxt(path)
    assert rec.names == list(PELLETS) and rec.dimensions == 2 and rec.head_corrected
    assert abs(rec.rate - 145.6) < 0.2 and rec.missing == 4
    assert not np.nanmax(np.abs(rec.markers[..., 0]))                         # midsagittal
    ref_forward, ref_up = raw[:, 1::2] / 1000, raw[:, 2::2] / 1000
    ok = raw[:, 1::2] != 1000000
    assert np.abs(rec.markers[..., 2][ok] - ref_forward[ok]).max() == 0.0
    assert np.abs(rec.markers[..., 1][ok] - ref_up[ok]).max() == 0.0
    assert np.isnan(rec.markers[5:9, 2]).all()


def test_xrmb_bad_files(tmp_path):
    path = write_txy(tmp_path / "a.txy", sensors(5, 8)[..., :2], np.arange(5) * 7.0)
    lines = path.read_text().splitlines()
    (tmp_path / "c.txy").write_text("\n".join(ln.rsplit(" ", 1)[0] for ln in lines))
    refused(tmp_path / "c.txy", "expected 17 columns", "found 16")
    (tmp_path / "t.txy").write_text("\n".join([*lines[:-1], lines[-1][:20]]))
    refused(tmp_path / "t.txy", "line 5 has", "truncated or damaged?")
    (tmp_path / "n.txy").write_text("\n".join(lines).replace(lines[2].split()[3], "abc", 1))
    refused(tmp_path / "n.txy", "line 3: 'abc' is not a number")


# --------------------------------------------------------------------------- EST
def est_by_header_walk(path) -> tuple[list[str], np.ndarray]:
    """Channel names from the header, values from the bytes after it (big-endian float32)."""
    raw = path.read_bytes()
    head, _, body = raw.partition(b"EST_Header_End\n")
    names = [ln.split()[1] for ln in head.decode().splitlines() if ln.startswith("Channel_")]
    frames = np.frombuffer(body, ">f4").reshape(-1, 2 + len(names))
    return names, frames[:, 2:].astype(np.float64)


@pytest.mark.parametrize("kind, order", [("binary", "10"), ("binary", "01"), ("ascii", "")])
def test_est_mngu0_style_channels_by_name(tmp_path, kind, order):
    """The 24-channel file of the issue, T1_px ... T8_pz: eight 3-D sensors by name, not MOCHA
    coils by position."""
    xyz = sensors(30, 8)
    names = [f"T{s + 1}_p{a}" for s in range(8) for a in "xyz"]
    path = write_est(tmp_path / "s.ema", names, xyz.reshape(30, 24), np.arange(30) / 200, kind, order)
    rec = read_recording(path)
    assert rec.names == [f"T{s}" for s in range(1, 9)] and rec.rate == 200.0
    assert np.abs(rec.markers - xyz).max() < (1e-5 if kind == "binary" else 1e-6 + 5e-7 * 100)
    if order == "10":
        ref_names, ref = est_by_header_walk(path)
        assert ref_names == names and np.abs(rec.markers.reshape(30, 24) - ref).max() == 0.0


def test_est_orientation_channels_and_breaks(tmp_path, caplog):
    xyz = sensors(20, 2)
    values = np.column_stack([xyz[:, 0], np.ones(20), xyz[:, 1]])
    names = ["TT_x", "TT_y", "TT_z", "TT_phi", "UL_x", "UL_y", "UL_z"]
    breaks = np.ones(20)
    breaks[4:6] = 0
    with caplog.at_level(logging.INFO):
        rec = read_recording(write_est(tmp_path / "s.ema", names, values, np.arange(20) / 100,
                                       breaks=breaks))
    assert rec.names == ["TT", "UL"] and "left out: TT_phi" in caplog.text
    assert rec.missing == 4 and np.isnan(rec.markers[4:6]).all()


def test_est_unnamed_channels_are_not_guessed(tmp_path, caplog):
    values = sensors(10, 8).reshape(10, 24)
    path = write_est(tmp_path / "s.ema", [], values, np.arange(10) / 200, named=False)
    refused(path, "its 24 channels (#0 #1", "facetraj does not guess which channel is which")
    twenty = write_est(tmp_path / "m.ema", [], values[:, :20], np.arange(10) / 500, named=False)
    with caplog.at_level(logging.WARNING):
        rec = read_recording(twenty)
    assert rec.names[0] == "UI" and "read as MOCHA-TIMIT's coils in the MOCHAtools column order" \
        in caplog.text


def test_est_bad_files(tmp_path):
    path = write_est(tmp_path / "s.ema", ["a_x", "a_y"], sensors(10, 1)[:, 0, :2], np.arange(10) / 100)
    data = path.read_bytes()
    (tmp_path / "t.ema").write_bytes(data[:-9])
    refused(tmp_path / "t.ema", "binary EST data holds", "expected (truncated?)")
    (tmp_path / "n.ema").write_bytes(data.replace(b"NumChannels 2", b"NumChannels 3"))
    refused(tmp_path / "n.ema", "expected (truncated?)")
    (tmp_path / "e.ema").write_bytes(data.replace(b"EST_Header_End", b"EST_Header_Xnd"))
    refused(tmp_path / "e.ema", "without EST_Header_End")
    asc = write_est(tmp_path / "a.ema", ["a_x", "a_y"], sensors(10, 1)[:, 0, :2], np.arange(10) / 100,
                    "ascii")
    (tmp_path / "ta.ema").write_bytes(asc.read_bytes().rsplit(b"\n", 3)[0])
    refused(tmp_path / "ta.ema", "EST data holds 8 frames, its header says 10")


# --------------------------------------------------------------------------- MVIEW
def _mview(frames: int = 120):
    xyz = sensors(frames, 4)
    audio = np.sin(np.arange(frames * 160) / 7.0) * 0.3
    phones = [PhoneSegment(0, 0.4, "sil"), PhoneSegment(0.4, 0.8, "AA1"), PhoneSegment(0.8, 1.2, "sil")]
    words = [PhoneSegment(0.4, 0.8, "ah")]
    return xyz, mview_entries(["TT", "TB", "UL", "LL"], xyz, 100.0, audio, 16000, phones, words,
                              "Ah."), audio


def loadmat_records(path) -> tuple[list[str], np.ndarray, np.ndarray]:
    """scipy's raw records (struct_as_record, nothing squeezed): names, sensors, audio."""
    from scipy.io import loadmat

    rec = loadmat(path, squeeze_me=False)[path.stem][0]
    names = [str(e["NAME"][0]) for e in rec[1:]]
    return names, np.stack([e["SIGNAL"] for e in rec[1:]], axis=1), rec[0]["SIGNAL"][:, 0]


def h5py_raw(path) -> tuple[list[str], np.ndarray]:
    """The v7.3 file walked with h5py alone: references, transposed arrays, uint16 text."""
    import h5py

    with h5py.File(path, "r") as h5:
        top = h5[path.stem]
        names = ["".join(map(chr, h5[r][()].ravel())) for r in top["NAME"][()].ravel()]
        signals = [h5[r][()].T for r in top["SIGNAL"][()].ravel()]
    return names[1:], np.stack(signals[1:], axis=1)


@pytest.mark.parametrize("version", ["v5", "v7.3"])
def test_mview_positions_audio_and_labels(tmp_path, version):
    xyz, entries, audio = _mview()
    writer = write_mview_v5 if version == "v5" else write_mview_v73
    path = writer(tmp_path / "F01_B01_S01_R01_N.mat", entries)
    rec = read_recording(path)
    names, ref = (loadmat_records(path)[:2] if version == "v5" else h5py_raw(path))
    assert rec.names == names == ["TT", "TB", "UL", "LL"] and rec.rate == 100.0
    assert np.abs(rec.markers - ref[:, :, [1, 2, 0]]).max() == 0.0     # MVIEW x, y, z -> z, x, y
    assert np.abs(rec.markers - xyz[:, :, [1, 2, 0]]).max() == 0.0     # doubles, as written
    assert rec.head_corrected and rec.audio_rate == 16000
    np.testing.assert_array_equal(rec.audio, audio)
    assert [(p.start, p.end, p.label) for p in rec.phones] == [(0, 0.4, "sil"), (0.4, 0.8, "AA1"),
                                                                (0.8, 1.2, "sil")]
    assert [w.label for w in rec.words] == ["ah"] and rec.transcript == "Ah."


def test_mview_sensor_rates_and_missing_samples(tmp_path):
    _, entries, _ = _mview()
    entries[2]["SRATE"] = 50.0                                   # TB at half the rate
    entries[2]["SIGNAL"] = entries[2]["SIGNAL"][::2].copy()
    entries[3]["SIGNAL"] = entries[3]["SIGNAL"].copy()
    entries[3]["SIGNAL"][30:40] = np.nan
    rec = read_recording(write_mview_v5(tmp_path / "s.mat", entries))
    assert rec.rate == 100.0 and rec.markers.shape[0] == 120
    assert rec.missing >= 10 and np.isnan(rec.markers[30:40, 2]).all()


def test_mview_bad_files(tmp_path):
    _, entries, _ = _mview()
    path = write_mview_v5(tmp_path / "s.mat", entries)
    (tmp_path / "t.mat").write_bytes(path.read_bytes()[:2000])
    refused(tmp_path / "t.mat", "not a readable MATLAB file")
    from scipy.io import savemat

    savemat(tmp_path / "o.mat", {"x": np.zeros(3)})
    refused(tmp_path / "o.mat", "no MVIEW struct array (NAME, SRATE, SIGNAL per channel)")
    v73 = write_mview_v73(tmp_path / "v.mat", entries)
    (tmp_path / "tv.mat").write_bytes(v73.read_bytes()[:3000])
    refused(tmp_path / "tv.mat", "not a readable MATLAB v7.3 file")
    only_audio = write_mview_v5(tmp_path / "a.mat", entries[:1])
    refused(only_audio, "no sensor channel")


# --------------------------------------------------------------------------- channel names
def test_channel_names_rename_drop_and_by_position(tmp_path, caplog):
    path = write_ag501(tmp_path / "s.pos", sensors(10, 4), 200.0)
    rec = read_markers(path, channel_names=["Ch1=UL", "Ch2=LL", "Ch4=-"])
    assert rec.names == ["UL", "LL", "Ch3"] and rec.markers.shape == (10, 3, 3)
    with caplog.at_level(logging.INFO):
        rec = read_markers(path, channel_names=["REF", "UL", "LL", "TT"])
    assert rec.names == ["REF", "UL", "LL", "TT"]
    assert "channels named by position: Ch1 -> REF, Ch2 -> UL, Ch3 -> LL, Ch4 -> TT" in caplog.text
    for spec, phrase in [(["UL", "LL"], "2 channel names for its 4 channels"),
                         (["Ch9=UL"], "rename Ch9, not channels of this file"),
                         (["Ch1=UL", "LL"], "mix OLD=NEW and plain names"),
                         (["Ch1=UL", "Ch2=UL"], "name UL twice"),
                         (["Ch1=a b"], "is not a name")]:
        with pytest.raises(InputError, match=phrase):
            read_markers(path, channel_names=spec)
