"""Carstens articulograph position files (``.pos``): AG500, and AG501 (headers V002, V003).

Each frame holds, per channel, 7 little-endian float32 values: x, y, z (mm), phi, theta (degrees),
rms and an extra value -- the layout Praat's reader and Carstens' tools use.

- AG500: no header; 12 channels at 200 Hz.
- AG501 (and AG500 files written by the AG50x tools): a text header, ``AG50xDATA_V00y``, the
  header's length in bytes (8 digits), ``NumberOfChannels=``, ``SamplingFrequencyHz=``, then (V003)
  ``key=value`` lines of the tools that made it; the data starts at the header's length.

Channels are unnamed: ``Ch1``, ``Ch2``, ... (as Carstens' text export calls them); map them with
``--channel-names``. Positions are kept in the device's axes. A sample whose position is NaN or
whose rms is over :data:`MAX_RMS` is missing. A V003 header that records Carstens' head
normalisation (``normpos`` lines) says the data is head-corrected.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ...errors import InputError
from .common import check_rate, mark_missing, read_binary
from .recording import MarkerRecording, unnamed
from .registry import MarkerFormat

VALUES = 7              # x, y, z, phi, theta, rms, extra
AG500_CHANNELS = 12
AG500_RATE = 200.0
#: A sample whose rms (the position fit's error, Carstens' units) exceeds this is missing.
MAX_RMS = 30.0
MAGIC = b"AG50xDATA_V00"
_HEADER_LINES = (re.compile(rb"^AG50xDATA_V00([123])$"), re.compile(rb"^(\d{8})$"),
                 re.compile(rb"^NumberOfChannels=(\d+)$"),
                 re.compile(rb"^SamplingFrequencyHz=(\d+(?:\.\d*)?)$"))


def positions(path: Path, data: np.ndarray, rate: float, head_corrected: bool | None
              ) -> MarkerRecording:
    """A recording of ``(frames, channels, 7)`` Carstens values: NaN or high-rms samples missing."""
    markers = np.array(data[..., :3], dtype=np.float64)
    rms = data[..., 5]
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(markers).all(axis=2) | ~(rms <= MAX_RMS)
    rec = MarkerRecording(markers, rate, unnamed(data.shape[1]), head_corrected=head_corrected)
    rec.missing = mark_missing(path, markers, bad, f"NaN or rms over {MAX_RMS:g}")
    return rec


def _frames(path: Path, data: bytes, channels: int, where: str) -> np.ndarray:
    frame = channels * VALUES * 4
    if not data or len(data) % frame:
        raise InputError(path, f"{where}{len(data)} bytes of data, not a whole number of {frame}-byte "
                               f"frames ({channels} channels x {VALUES} float32 values): truncated, "
                               f"or not this many channels")
    return np.frombuffer(data, "<f4").reshape(-1, channels, VALUES)


def read_ag500(path: Path) -> MarkerRecording:
    """Read an AG500 ``.pos`` file (no header: 12 channels at 200 Hz)."""
    raw = read_binary(path, "Carstens AG500 .pos file")
    return positions(path, _frames(path, raw, AG500_CHANNELS, "an AG500 file (no header) holds "),
                     AG500_RATE, None)


def ag501_header(path: Path, raw: bytes) -> tuple[int, int, int, float, list[str]]:
    """An AG50x header's version, length in bytes, channels, rate and further lines."""
    lines = raw[:4096].split(b"\n", 4)
    for i, pattern in enumerate(_HEADER_LINES):
        if i >= len(lines) or not pattern.match(lines[i].rstrip(b"\r")):
            got = lines[i][:40].decode("latin-1") if i < len(lines) else "nothing"
            raise InputError(path, f"AG50x header line {i + 1} is {got!r}, not "
                                   f"{pattern.pattern.decode()[1:-1]!r}")
    version, size, channels = (int(_HEADER_LINES[i].match(lines[i].rstrip(b"\r"))[1])
                               for i in range(3))
    rate = float(_HEADER_LINES[3].match(lines[3].rstrip(b"\r"))[1])
    start = sum(len(ln) + 1 for ln in lines[:4])
    if not start <= size <= len(raw):
        raise InputError(path, f"the AG50x header says it is {size} bytes long, but its lines take "
                               f"{start} and the file holds {len(raw)}")
    if not 1 <= channels <= 64:
        raise InputError(path, f"the AG50x header gives {channels} channels (1 to 64 read)")
    extra = raw[start:size].split(b"\x00", 1)[0].decode("latin-1").splitlines()
    return version, size, channels, check_rate(path, rate, " (SamplingFrequencyHz)"), extra


def read_ag501(path: Path) -> MarkerRecording:
    """Read an AG50x ``.pos`` file with its text header (V001-V003)."""
    raw = read_binary(path, "Carstens AG50x .pos file")
    _, size, channels, rate, extra = ag501_header(path, raw)
    frames = _frames(path, raw[size:], channels, f"after its {size}-byte header it holds ")
    corrected = True if any(line.lower().startswith("normpos") for line in extra) else None
    return positions(path, frames, rate, corrected)


FORMATS = (
    MarkerFormat("Carstens AG501 .pos", (".pos",), read_ag501,
                 sniff=lambda head: head.startswith(MAGIC), signature="'AG50xDATA_V00y' header",
                 order=40),
    MarkerFormat("Carstens AG500 .pos", (".pos",), read_ag500, signature="no header", order=41),
)
