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


def read_audio(path: str | os.PathLike[str]) -> tuple[np.ndarray, int]:
    """Read a WAV or FLAC file as mono float64 samples and its rate.

    Stereo and multi-channel files are mixed down (a note is logged). Raises
    :class:`InputError` for a missing, unreadable, empty file or a rate below 8 kHz.
    """
    import soundfile as sf

    path = Path(path)
    if not path.exists():
        raise InputError(path, "no such audio file")
    if path.stat().st_size == 0:
        raise InputError(path, "the audio file is empty (0 bytes)")
    try:
        data, rate = sf.read(str(path), dtype="float64", always_2d=True)
    except Exception as exc:  # soundfile raises several types for corrupt data
        raise InputError(path, f"cannot read audio ({exc})") from exc
    if data.shape[0] == 0:
        raise InputError(path, "the audio file holds no samples")
    if rate < MIN_SAMPLE_RATE:
        raise InputError(path, f"sample rate {rate} Hz is below the {MIN_SAMPLE_RATE} Hz minimum")
    if data.shape[1] > 1:
        warn_file(log, path, "channels mixed down to mono",
                  f"{data.shape[1]} channels mixed down to mono")
    samples = data.mean(axis=1)
    if not np.all(np.isfinite(samples)):
        raise InputError(path, "the audio holds NaN or infinite samples")
    return samples, int(rate)


def write_audio(path: str | os.PathLike[str], samples: np.ndarray, rate: int,
                overwrite: bool = True) -> None:
    """Write mono samples as WAV (16-bit) or FLAC (16-bit), chosen by the suffix."""
    import soundfile as sf

    path = Path(path)
    fmt = "FLAC" if path.suffix.lower() == ".flac" else "WAV"
    with atomic_write(path, overwrite) as tmp:
        sf.write(str(tmp), np.clip(samples, -1.0, 1.0), int(rate), subtype="PCM_16", format=fmt)
