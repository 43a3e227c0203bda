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
    from .markerformats import format_for, read_recording

    try:
        fmt = format_for(path)
    except InputError:
        return None
    if not fmt.carries_audio:
        return None
    rec = read_recording(path)
    if rec.audio is None:
        raise InputError(path, f"the {fmt.name} file holds no audio channel")
    return rec.audio, rec.audio_rate


def read_audio(path: str | os.PathLike[str]) -> tuple[np.ndarray, int]:
    """Read a WAV or FLAC file as mono float64 samples and its rate (or the speech a marker file
    holds: an MVIEW ``.mat``).

    Stereo and multi-channel files are mixed down (a note is logged), block by block, so that
    only the mono samples are held. The header's sample count is checked against the file's
    length (uncompressed encodings) and :data:`MAX_AUDIO_FRAMES` before anything is allocated.
    Raises :class:`InputError` for a missing, unreadable, empty file or a rate below 8 kHz.
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
    try:
        with sf.SoundFile(str(path)) as f:
            rate, channels, frames = int(f.samplerate), int(f.channels), int(f.frames)
            whole = f.subtype in _INTEGER_SUBTYPES
            _check_header(path, f.format, f.subtype, rate, channels, frames)
            samples = np.empty(frames)
            done = 0
            if channels == 1:                           # straight into place, one call
                done = len(f.read(frames, dtype="float64", out=samples))
            else:
                for block in f.blocks(max(1, _BLOCK_SAMPLES // channels), dtype="float64",
                                      always_2d=True, frames=frames):
                    samples[done:done + len(block)] = block.mean(axis=1)
                    done += len(block)
    except InputError:
        raise
    except Exception as exc:  # soundfile raises several types for corrupt data
        raise InputError(path, f"cannot read audio ({exc})") from exc
    if done == 0:
        raise InputError(path, "the audio file holds no samples")
    if channels > 1:
        warn_file(log, path, "channels mixed down to mono", f"{channels} channels mixed down to mono")
    samples = samples[:done]
    if not whole and not np.all(np.isfinite(samples)):
        raise InputError(path, "the audio holds NaN or infinite samples")
    return samples, rate


def _check_header(path: Path, container: str, subtype: str, rate: int, channels: int,
                  frames: int) -> None:
    """The header's rate and sample count, before the samples are allocated."""
    if rate < MIN_SAMPLE_RATE:
        raise InputError(path, f"sample rate {rate} Hz is below the {MIN_SAMPLE_RATE} Hz minimum")
    if channels < 1:
        raise InputError(path, "the audio file has no channels")
    width = None if container in _COMPRESSED else _SAMPLE_BYTES.get(subtype)
    if width is not None and frames * channels * width > path.stat().st_size:
        raise InputError(path, f"the header says it holds {frames} samples of {channels} "
                               f"channel(s), more than the file's {path.stat().st_size} bytes "
                               f"hold (damaged or truncated?)")
    if frames > MAX_AUDIO_FRAMES:
        raise InputError(path, f"the header says it holds {frames} samples "
                               f"({frames / rate / 60:.0f} minutes at {rate} Hz), more than "
                               f"facetraj reads from one file ({MAX_AUDIO_FRAMES} samples; a "
                               f"damaged header?)")


def write_audio(path: str | os.PathLike[str], samples: np.ndarray, rate: int,
                overwrite: bool = True) -> None:
    """Write mono samples as WAV (16-bit) or FLAC (16-bit), chosen by the suffix."""
    import soundfile as sf

    path = Path(path)
    fmt = "FLAC" if path.suffix.lower() == ".flac" else "WAV"
    with atomic_write(path, overwrite) as tmp:
        sf.write(str(tmp), np.clip(samples, -1.0, 1.0), int(rate), subtype="PCM_16", format=fmt)
