"""Where a Live take's audio comes from: a microphone (QtMultimedia ``QAudioSource``, in whatever
format the device gives) or a file played on the audio clock.

A feeder's ``poll()`` returns the samples that arrived since the last poll (mono floats in
[-1, 1]), ``None`` once a file has been played, and raises :class:`InputLost` when the device
stops delivering (unplugged, or its sound server gone): the window then keeps the take so far
and says so. A device that cannot record 16 kHz mono 16-bit records in its preferred format, at
its own rate: the stream resamples (``facetraj_engine.streaming``).
"""

from __future__ import annotations

import time

import numpy as np

#: the rate asked of a microphone first (the model's analysis rate: no resampling)
MIC_RATE = 16000


class InputLost(Exception):
    """The input device stopped delivering audio."""


def input_devices() -> list:
    """The audio input devices QtMultimedia sees (``QAudioDevice``), default first."""
    from PyQt6.QtMultimedia import QMediaDevices

    devices = list(QMediaDevices.audioInputs())
    default = QMediaDevices.defaultAudioInput()
    devices.sort(key=lambda d: d.id() != default.id())
    return devices


class FileFeeder:
    """Blocks of a file as the audio clock reaches them (``fast``: the next block every poll)."""

    def __init__(self, audio: np.ndarray, rate: int, block_s: float, fast: bool = False):
        self.audio, self.rate, self.fast = audio, rate, fast
        self.block = max(1, int(round(block_s * rate)))
        self.pos = 0
        self.t0 = time.perf_counter()

    def poll(self) -> np.ndarray | None:
        """The samples due now (possibly none); ``None`` once the file has been played."""
        if self.pos >= len(self.audio):
            return None
        due = self.pos + self.block if self.fast else \
            int((time.perf_counter() - self.t0) * self.rate) // self.block * self.block
        due = min(max(due, self.pos), len(self.audio))
        out, self.pos = self.audio[self.pos:due], due
        return out

    def stop(self) -> None:
        self.pos = len(self.audio)


def decode_pcm(data: bytes, sample_format: str, channels: int) -> np.ndarray:
    """Interleaved PCM bytes as mono floats in [-1, 1] (channels averaged); a partial last
    frame is dropped.

    >>> decode_pcm(np.array([16384, -16384, 0, 32767], "<i2").tobytes(), "Int16", 2).round(3).tolist()
    [0.0, 0.5]
    >>> decode_pcm(np.array([0.25], "<f4").tobytes(), "Float", 1).tolist()
    [0.25]
    >>> decode_pcm(bytes([128, 255]), "UInt8", 1).round(3).tolist()
    [0.0, 0.992]
    """
    dtype, scale, offset = {"UInt8": ("u1", 128.0, 128.0), "Int16": ("<i2", 32768.0, 0.0),
                            "Int32": ("<i4", 2147483648.0, 0.0), "Float": ("<f4", 1.0, 0.0)}[sample_format]
    width = np.dtype(dtype).itemsize * max(1, channels)
    x = np.frombuffer(data[: len(data) // width * width], dtype=dtype).astype(np.float64)
    x = (x - offset) / scale
    if channels > 1:
        x = x.reshape(-1, channels).mean(axis=1)
    return np.nan_to_num(np.clip(x, -1.0, 1.0))


def capture_format(device):
    """The format to record ``device`` in: 16 kHz mono 16-bit when it can, else its own
    preferred format (any rate, channels and sample type)."""
    from PyQt6.QtMultimedia import QAudioFormat

    fmt = QAudioFormat()
    fmt.setSampleRate(MIC_RATE)
    fmt.setChannelCount(1)
    fmt.setSampleFormat(QAudioFormat.SampleFormat.Int16)
    if device.isFormatSupported(fmt):
        return fmt
    preferred = device.preferredFormat()
    if preferred.sampleFormat() == QAudioFormat.SampleFormat.Unknown or preferred.sampleRate() <= 0:
        return fmt                                    # nothing better known: ask, and see
    return preferred


class MicFeeder:
    """Blocks from a ``QAudioSource`` (pull mode: read what has arrived). :attr:`rate` is the
    device's; :meth:`poll` raises :class:`InputLost` once the source has stopped with an error or
    the device is gone."""

    def __init__(self, device):
        from PyQt6.QtMultimedia import QAudioSource

        self.device = device
        self.format = capture_format(device)
        self.rate = int(self.format.sampleRate())
        self.channels = max(1, int(self.format.channelCount()))
        self.sample_format = self.format.sampleFormat().name
        self.source = QAudioSource(device, self.format)
        self.io = self.source.start()
        self._quiet_polls = 0

    def poll(self) -> np.ndarray | None:
        from PyQt6.QtMultimedia import QtAudio

        if self.io is None:
            raise InputLost(f"{self.device.description()} could not be opened")
        data = bytes(self.io.readAll())
        if self.source.error() not in (QtAudio.Error.NoError, QtAudio.Error.UnderrunError):
            raise InputLost(f"{self.device.description()} stopped delivering audio "
                            f"({self.source.error().name})")
        if self.source.state() == QtAudio.State.StoppedState:
            raise InputLost(f"{self.device.description()} stopped")
        if not data:
            self._quiet_polls += 1
            if self._quiet_polls % 64 == 0 and not self._present():
                raise InputLost(f"{self.device.description()} was disconnected")
        else:
            self._quiet_polls = 0
        return decode_pcm(data, self.sample_format, self.channels)

    def _present(self) -> bool:
        from PyQt6.QtMultimedia import QMediaDevices

        return any(d.id() == self.device.id() for d in QMediaDevices.audioInputs())

    def stop(self) -> None:
        self.source.stop()


class InputHealth:
    """What is wrong with the input, if anything, over the last ``window_s``: clipping (more than
    ``clip_share`` of the samples at full scale) or silence (nothing above ``silent_level`` for
    ``silent_s``): the window says so and the take goes on.

    >>> h = InputHealth(16000)
    >>> h.add(np.ones(1600)); h.message
    'the input is clipping (100 % of samples at full scale): lower its level'
    >>> h = InputHealth(16000, silent_s=0.5)
    >>> for _ in range(6): h.add(np.zeros(1600))
    >>> h.message
    'no sound for 0.6 s: is the microphone muted?'
    """

    def __init__(self, rate: int, window_s: float = 2.0, clip_share: float = 0.01,
                 silent_s: float = 5.0, silent_level: float = 1e-4):
        self.rate, self.window_s = rate, window_s
        self.clip_share, self.silent_s, self.silent_level = clip_share, silent_s, silent_level
        self._recent: list[tuple[int, int]] = []            # (samples, clipped) per block
        self._silent = 0                                     # samples since the last sound

    def add(self, block: np.ndarray) -> None:
        x = np.abs(np.asarray(block, dtype=np.float64))
        self._recent.append((len(x), int((x >= 0.999).sum())))
        while sum(n for n, _ in self._recent) > self.window_s * self.rate and len(self._recent) > 1:
            self._recent.pop(0)
        self._silent = 0 if (len(x) and x.max() > self.silent_level) else self._silent + len(x)

    @property
    def message(self) -> str:
        n = sum(k for k, _ in self._recent)
        clipped = sum(c for _, c in self._recent)
        if n and clipped > self.clip_share * n:
            return (f"the input is clipping ({100 * clipped / n:.0f} % of samples at full scale): "
                    "lower its level")
        if self._silent >= self.silent_s * self.rate:
            return f"no sound for {self._silent / self.rate:.1f} s: is the microphone muted?"
        return ""
