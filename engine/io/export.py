"""Writing trajectories: synthesized or original face points as C3D, TSV/CSV or NPZ."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import InputError
from .c3d_layout import C3dExtras
from .files import atomic_write, write_npz
from .markerfiles import write_c3d, write_marker_tsv

#: The suffixes a trajectory file may have (:func:`write_trajectories`; ``.txt`` is a TSV).
TRAJECTORY_SUFFIXES = (".c3d", ".tsv", ".csv", ".npz", ".txt")


def write_trajectories(path: str | os.PathLike[str], markers: np.ndarray, rate: float,
                       names: Sequence[str], arrays: Mapping[str, np.ndarray] | None = None,
                       overwrite: bool = True, which: str = "synthesized",
                       compress: bool = False,
                       audio: tuple[np.ndarray, int] | None = None,
                       labels: Mapping[str, Sequence[str]] | None = None) -> Path:
    """Write ``(T, M, 3)`` trajectories (``rate`` frames per second, marker ``names``, head frame)
    as C3D, TSV/CSV or NPZ (by the suffix). The NPZ also holds ``arrays`` (for a synthesis, its
    :meth:`~facetraj_engine.method.pipeline.Synthesis.arrays`: times, smoothed and raw PCs, gamma, input LSF
    and settings), and says ``which`` trajectories it holds (synthesized or original). A TSV/CSV
    carries ``labels`` (``{"phone": [...], "word": [...]}``, one per frame) as text columns after
    the coordinates (:func:`~facetraj_engine.io.markerfiles.write_marker_tsv`).

    A C3D declares its axes (POINT:X_SCREEN ``+X``, POINT:Y_SCREEN ``+Y``: a viewer that honours
    them shows the face upright) and carries ``audio`` (samples, rate; the speech the face was
    made from) as its analog channel ``SPEECH`` (:func:`speech_channel`).

    The NPZ is stored uncompressed unless ``compress``: the coordinates are 64-bit floats whose
    low bits do not compress, so deflate saves little and takes longer than the synthesis
    (docs/benchmarks.md)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        write_c3d(path, markers, rate, list(names), overwrite,
                  extras=speech_channel(audio, rate, len(markers)))
    elif suffix in (".tsv", ".txt", ".csv"):
        write_marker_tsv(path, markers, rate, list(names), overwrite, labels)
    elif suffix == ".npz":
        out = {"markers": markers, "marker_names": np.array(list(names)), "which": np.array(which)}
        out.update(arrays or {})
        with atomic_write(path, overwrite) as tmp, open(tmp, "wb") as handle:
            if compress:
                np.savez_compressed(handle, **out)
            else:
                write_npz(handle, out)
    else:
        raise InputError(path, "unknown format (use .c3d, .tsv, .csv or .npz)")
    return path


#: what the analog channel of a C3D output says it holds
SPEECH_DESCRIPTION = "speech, scaled to a peak of 1"


def band_limited(x: np.ndarray, ratio: float) -> np.ndarray:
    """``x`` resampled by ``ratio`` (``round(len(x) ratio)`` samples) in the frequency domain:
    its spectrum cut or padded with zeros, so nothing above the lower Nyquist frequency is
    aliased (numpy's FFT: a C3D's speech channel does not wait for ``scipy.signal``'s import).

    >>> t = np.arange(1600)
    >>> y = band_limited(np.sin(2 * np.pi * 50 * t / 1600), 1.5)     # 50 cycles either way
    >>> len(y), round(float(np.abs(np.fft.rfft(y)).argmax()))
    (2400, 50)
    """
    x = np.asarray(x, dtype=np.float64)
    n, m = len(x), int(round(len(x) * ratio))
    if m == n or n == 0:
        return x
    spectrum = np.fft.rfft(x)
    keep = min(len(spectrum), m // 2 + 1)
    out = np.zeros(m // 2 + 1, dtype=complex)
    out[:keep] = spectrum[:keep]
    return np.fft.irfft(out, m) * (m / n)


def speech_channel(audio: tuple[np.ndarray, int] | None, marker_rate: float, n_frames: int
                   ) -> C3dExtras:
    """A C3D output's extras: its axes, and the speech (``audio``: samples and rate; ``None``: no
    analog data) as one analog channel, resampled (:func:`band_limited`) to the whole number of
    samples per marker frame nearest its rate (C3D's analog rate is a multiple of the point
    rate: 16 kHz speech at 60 Hz is 267 samples a frame, 16,020 Hz), one frame's worth per
    marker frame (cut at the last, or silence after the speech), scaled to a peak of 1 (the
    level of a recording is its maker's choice, not a measurement; scaled, the channel is the
    same whatever the recording's gain).

    >>> e = speech_channel((np.sin(np.arange(16000) / 9.0), 16000), 60.0, 61)
    >>> e.analog.shape, e.analog_rate, round(float(np.abs(e.analog).max()), 6)
    ((61, 267), 16020.0, 1.0)
    """
    if audio is None:
        return C3dExtras()
    from ..level import to_full_scale

    samples, rate = np.asarray(audio[0], dtype=np.float64), int(audio[1])
    per_frame = max(1, int(round(rate / marker_rate)))
    x = to_full_scale(band_limited(samples, per_frame * marker_rate / rate))
    n = n_frames * per_frame
    x = np.concatenate([x[:n], np.zeros(max(0, n - len(x)))])
    return C3dExtras(analog=x.reshape(n_frames, per_frame), analog_rate=per_frame * marker_rate,
                     analog_description=SPEECH_DESCRIPTION)
