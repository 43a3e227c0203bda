"""Audio files: WAV and FLAC in, mono float samples out (and back)."""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np

from ..errors import InputError, warn_file
from .files import atomic_write

log = logging.getLogger(__name__)

MIN_SAMPLE_RATE = 8000
AUDIO_SUFFIXES = (".wav", ".flac")


#: the most samples (per channel) read from one file: 1 GiB as mono float64, 46 minutes at 48 kHz
#: or 2.3 hours at 16 kHz; a header that claims more is refused before anything is allocated
MAX_AUDIO_FRAMES = 1 << 27
#: bytes per sample of the uncompressed encodings, whose sample count the file's length bounds
_SAMPLE_BYTES = {"PCM_S8": 1, "PCM_U8": 1, "PCM_16": 2, "PCM_24": 3, "PCM_32": 4, "FLOAT": 4,
                 "DOUBLE": 8, "ULAW": 1, "ALAW": 1}
#: containers whose samples are compressed (their subtype names the decoded depth)
_COMPRESSED = {"FLAC", "OGG", "MPEG"}
#: encodings of whole numbers: their samples, as floats, are finite (not checked for NaN)
_INTEGER_SUBTYPES = {"PCM_S8", "PCM_U8", "PCM_16", "PCM_24", "PCM_32", "ULAW", "ALAW"}
#: samples (all channels) decoded per block while mixing down
_BLOCK_SAMPLES = 1 << 20


def _held_audio(path: Path) -> tuple[np.ndarray, int] | None:
    """The speech a marker file holds (an MVIEW ``.mat``), ``None`` for a file of no such format."""
    from .markerformats import held_recording

    rec = held_recording(path, "carries_audio")
    if rec is None:
        return None
    if rec.audio is None:
        raise InputError(path, f"the {rec.format} file holds no audio channel")
    return rec.audio, rec.audio_rate


def read_audio(path: str | os.PathLike[str], allow_damaged: bool = False) -> tuple[np.ndarray, int]:
    """Read a WAV or FLAC file as mono float64 samples and its rate (or the speech a marker file
    holds: an MVIEW ``.mat``).

    Stereo and multi-channel files are mixed down (a note is logged), block by block, so that
    only the mono samples are held. The header's sample count is checked against the file's
    length (uncompressed encodings) and :data:`MAX_AUDIO_FRAMES` before anything is allocated.
    A file whose header does not match its data -- cut short (fewer samples than its header
    says), or a WAV header whose fields contradict each other or its chunks
    (:func:`check_wav_header`) -- is refused as damaged, naming the audio file (issue 38: it
    was read as shorter audio, and the labels were blamed); ``allow_damaged`` reads what the file
    holds instead, with a warning (``--read-damaged-audio``).
    Raises :class:`InputError` for a missing, unreadable, damaged or empty file or a rate below
    8 kHz.
    """
    import soundfile as sf

    path = Path(path)
    if not path.exists():
        raise InputError(path, "no such audio file")
    if path.suffix.lower() not in AUDIO_SUFFIXES and not path.is_dir():
        held = _held_audio(path)
        if held is not None:
            return held
    if path.stat().st_size == 0:
        raise InputError(path, "the audio file is empty (0 bytes)")
    damage = check_wav_header(path)
    if damage is not None and not allow_damaged:
        raise DamagedAudioError(path, damage)
    try:
        with sf.SoundFile(str(path)) as f:
            rate, channels, frames = int(f.samplerate), int(f.channels), int(f.frames)
            whole = f.subtype in _INTEGER_SUBTYPES
            bound = _check_header(path, f.format, f.subtype, rate, channels, frames, allow_damaged)
            samples, done, stopped = _samples(f, bound, channels)
    except InputError:
        raise
    except Exception as exc:  # soundfile raises several types for corrupt data
        raise InputError(path, f"cannot read audio ({exc})") from exc
    if stopped and not done:
        raise InputError(path, f"the audio file is cut short or damaged: its header says "
                               f"{frames / rate:.3f} s ({frames} samples), none could be decoded "
                               f"({stopped})" if frames else f"cannot read audio ({stopped})")
    if done == 0:
        raise InputError(path, "the audio file holds no samples")
    if done < frames and damage is None:
        damage = cut_short(frames, done, rate) + (f" (decoding stopped: {stopped})" if stopped
                                                  else "")
        if not allow_damaged:
            raise DamagedAudioError(path, damage)
    if damage is not None:
        warn_file(log, path, "damaged audio read as it is",
                  f"{damage}; its {done / rate:.3f} s read as they are (--read-damaged-audio)")
    if channels > 1:
        warn_file(log, path, "channels mixed down to mono", f"{channels} channels mixed down to mono")
    samples = samples[:done]
    if not whole and not np.all(np.isfinite(samples)):
        raise InputError(path, "the audio holds NaN or infinite samples")
    return samples, rate


class DamagedAudioError(InputError):
    """An audio file whose header does not match its data (cut short, or fields that contradict
    each other): refused unless damaged audio is allowed (``--read-damaged-audio``)."""

    def __init__(self, path: str | os.PathLike[str] | None, problem: str):
        super().__init__(path, f"{problem}; {DAMAGED_HINT}")


#: what a refusal of a damaged file says the user can do
DAMAGED_HINT = "read what it holds anyway with --read-damaged-audio"


def _samples(f, frames: int, channels: int) -> tuple[np.ndarray, int, str]:
    """The mono samples of an open :class:`soundfile.SoundFile` (its first ``frames`` at most),
    how many it held, and why decoding stopped before them (``""``: it did not; a compressed
    file cut short loses its decoder's sync)."""
    samples = np.empty(frames)
    done = 0
    if channels == 1 and f.format not in _COMPRESSED:      # straight into place, one call
        return samples, len(f.read(frames, dtype="float64", out=samples)), ""
    step = max(1, _BLOCK_SAMPLES // channels) if f.format not in _COMPRESSED else 1 << 14
    try:
        for block in f.blocks(step, dtype="float64", always_2d=True, frames=frames):
            samples[done:done + len(block)] = block.mean(axis=1) if channels > 1 else block[:, 0]
            done += len(block)
    except Exception as exc:  # soundfile raises several types for corrupt data
        return samples, done, " ".join(str(exc).split()) or type(exc).__name__
    return samples, done, ""


def cut_short(declared: int, held: int, rate: int) -> str:
    """The problem of a file that holds fewer samples than its header says.

    >>> print(cut_short(62081, 1478, 16000))  # doctest: +NORMALIZE_WHITESPACE
    the audio file is cut short: its header says 3.880 s (62081 samples), the file holds 0.092 s
    (1478 samples)
    """
    return (f"the audio file is cut short: its header says {declared / rate:.3f} s ({declared} "
            f"samples), the file holds {held / rate:.3f} s ({held} samples)")


def _check_header(path: Path, container: str, subtype: str, rate: int, channels: int,
                  frames: int, allow_damaged: bool = False) -> int:
    """The header's rate and sample count, before the samples are allocated (a count the file
    cannot hold is damage: refused unless ``allow_damaged``, which reads what there is); the
    most samples to read."""
    if rate < MIN_SAMPLE_RATE:
        raise InputError(path, f"sample rate {rate} Hz is below the {MIN_SAMPLE_RATE} Hz minimum")
    if channels < 1:
        raise InputError(path, "the audio file has no channels")
    width = None if container in _COMPRESSED else _SAMPLE_BYTES.get(subtype)
    if width is not None and frames * channels * width > path.stat().st_size:
        if not allow_damaged:
            raise DamagedAudioError(path, f"the header says it holds {frames} samples of "
                                          f"{channels} channel(s), more than the file's "
                                          f"{path.stat().st_size} bytes hold (damaged or cut short)")
        frames = path.stat().st_size // (channels * width)      # what it can hold, at most
    if frames > MAX_AUDIO_FRAMES:
        raise InputError(path, f"the header says it holds {frames} samples "
                               f"({frames / rate / 60:.0f} minutes at {rate} Hz), more than "
                               f"facetraj reads from one file ({MAX_AUDIO_FRAMES} samples; a "
                               f"damaged header?)")
    return frames


# --------------------------------------------------------------------------- WAV headers
#: WAV format tags whose block size is ``channels x bytes per sample``: PCM, IEEE float, A-law,
#: mu-law, and WAVE_FORMAT_EXTENSIBLE (whose sub-format is one of them for what we read)
_BLOCK_FORMATS = {1: "PCM", 3: "float", 6: "A-law", 7: "mu-law", 0xFFFE: "extensible"}
#: a chunk or RIFF size that streaming writers put when they do not know it (0 or all ones)
_UNKNOWN_SIZES = (0, 0xFFFFFFFF)


def check_wav_header(path: Path) -> str | None:
    """What is wrong with a RIFF/WAVE file's header against its data, ``None`` when nothing is
    (or the file is no RIFF/WAVE file: the reader says what it is).

    The chunks are walked from the header to the end of the RIFF size: each must be a chunk
    (a four-letter name, a size that fits in the file); the ``data`` chunk must be all there (a
    file cut short says more samples than it holds) and hold whole sample frames; the ``fmt``
    chunk's block size and byte rate must agree with its channels, sample size and rate. Sizes
    that streaming writers leave unknown (0 or 0xFFFFFFFF) are taken as "to the end of the file".
    """
    import struct

    size = path.stat().st_size
    with open(path, "rb") as handle:
        head = handle.read(12)
        if len(head) < 12 or head[:4] != b"RIFF" or head[8:12] != b"WAVE":
            return None
        riff = struct.unpack("<I", head[4:8])[0]
        end = size if riff in _UNKNOWN_SIZES else 8 + riff
        fmt, data, pos = None, False, 12
        while pos + 8 <= min(end, size):
            handle.seek(pos)
            name, length = struct.unpack("<4sI", handle.read(8))
            if not all(32 <= c < 127 for c in name):
                if fmt is None:             # not a WAV header we can judge: the reader says
                    return None
                return (f"the audio file's header does not match its data: the bytes at offset "
                        f"{pos} are not a chunk ({name!r}; damaged header?)")
            if not data and pos + 8 + length > size and name != b"data":
                return None                 # a header in pieces: the reader says what it is
            if name == b"fmt ":
                fmt = handle.read(min(length, 16))
            if name == b"data" and not data:
                data = True
                problem = _data_chunk(fmt, pos, length, size)
                if problem is not None or length in _UNKNOWN_SIZES:
                    return problem
                if pos + 8 + length > end + 1:
                    return (f"the audio file's header does not match its data: its 'data' chunk "
                            f"ends at byte {pos + 8 + length}, after the {end} bytes its RIFF "
                            "header says the file has (damaged header?)")
            elif pos + 8 + length > size:
                return (f"the audio file is cut short after its samples: its {name.decode()!r} "
                        f"chunk at offset {pos} needs {length} bytes, the file ends "
                        f"{size - pos - 8} bytes after it")
            pos += 8 + length + (length & 1)
    if not data:
        return "the audio file's header does not match its data: no 'data' chunk in its RIFF size"
    if min(end, size) - pos > 1:           # more than a pad byte left, too little for a chunk
        return (f"the audio file's header does not match its data: {min(end, size) - pos} bytes "
                f"after its last chunk (damaged header?)")
    if end > size + 1:                     # a missing pad byte at the end is common, no more
        return (f"the audio file is cut short: its RIFF header says {end} bytes, the file has "
                f"{size}")
    return None


def _data_chunk(fmt: bytes | None, pos: int, length: int, size: int) -> str | None:
    """What is wrong with the ``data`` chunk at ``pos`` (``length`` bytes by its header) of a
    file of ``size`` bytes, given the ``fmt`` chunk's first 16 bytes."""
    import struct

    if fmt is None or len(fmt) < 16:
        return "the audio file's header does not match its data: no 'fmt ' chunk before 'data'"
    tag, channels, rate, byte_rate, block, bits = struct.unpack("<HHIIHH", fmt)
    held = size - pos - 8
    if tag not in _BLOCK_FORMATS:
        return (f"the audio file's header names WAV format {tag} (not PCM, float, A-law or "
                "mu-law): damaged, or an encoding facetraj does not read (convert it to PCM)")
    if channels == 0 or bits == 0:
        return (f"the audio file's header does not match its data: its 'fmt ' chunk says "
                f"{channels} channel(s) of {bits} bits")
    if tag in (1, 3) and bits % 8:
        # plain PCM and float name whole bytes; fewer valid bits need WAVE_FORMAT_EXTENSIBLE
        return (f"the audio file's header does not match its data: its 'fmt ' chunk says "
                f"{_BLOCK_FORMATS[tag]} of {bits} bits, which WAV stores in whole bytes")
    if tag in (6, 7) and bits != 8:
        return (f"the audio file's header does not match its data: its 'fmt ' chunk says "
                f"{_BLOCK_FORMATS[tag]} of {bits} bits (A-law and mu-law are 8-bit)")
    width = channels * ((bits + 7) // 8)
    if block != width or byte_rate != rate * block:
        return (f"the audio file's header does not match its data: its 'fmt ' chunk says "
                f"{channels} channel(s) of {bits} bits at {rate} Hz, but a block of {block} bytes "
                f"and {byte_rate} bytes per second (damaged header?)")
    if length in _UNKNOWN_SIZES:
        return None
    if length > held:
        declared, kept = length // block, held // block
        rate_ = max(rate, 1)
        return (f"the audio file is cut short: its header says {declared / rate_:.3f} s "
                f"({declared} samples), the file holds {kept / rate_:.3f} s ({kept} samples)")
    if length % block:
        return (f"the audio file's header does not match its data: its 'data' chunk of {length} "
                f"bytes is not a whole number of {block}-byte sample frames (damaged header?)")
    return None


def write_audio(path: str | os.PathLike[str], samples: np.ndarray, rate: int,
                overwrite: bool = True) -> None:
    """Write mono samples as WAV (16-bit) or FLAC (16-bit), chosen by the suffix."""
    import soundfile as sf

    path = Path(path)
    fmt = "FLAC" if path.suffix.lower() == ".flac" else "WAV"
    with atomic_write(path, overwrite) as tmp:
        sf.write(str(tmp), np.clip(samples, -1.0, 1.0), int(rate), subtype="PCM_16", format=fmt)
