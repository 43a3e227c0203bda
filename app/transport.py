"""The playback clock: sound through QtMultimedia, and the time every view follows.

:class:`PlaybackClock` plays a temporary WAV with ``QMediaPlayer`` + ``QAudioOutput`` and reports
the audio position, interpolated between the player's coarse ``positionChanged`` updates with a
monotonic timer (never going backwards while playing). Without an audio output device (a headless
machine) it is a silent monotonic clock. Speed 0.25x-1x and a loop range apply to both.
"""

from __future__ import annotations

import logging
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from PyQt6.QtCore import QObject, QUrl, pyqtSignal

from facetraj_engine.io.audio import write_audio

log = logging.getLogger(__name__)


def audio_device_available() -> bool:
    """Whether Qt sees an audio output device (False on a headless machine)."""
    try:
        from PyQt6.QtMultimedia import QMediaDevices
    except ImportError:  # no libpulse / no QtMultimedia
        return False
    return len(QMediaDevices.audioOutputs()) > 0


class PlaybackClock(QObject):
    """Play/pause/seek/speed/loop over one audio signal; :meth:`time` is the audio clock.

    Call :meth:`poll` once per displayed frame: it returns the current time and applies the loop
    range and the end of the signal.
    """

    playingChanged = pyqtSignal(bool)

    def __init__(self, parent: QObject | None = None, use_audio: bool | None = None):
        super().__init__(parent)
        self.use_audio = audio_device_available() if use_audio is None else use_audio
        self.duration = 0.0
        self.speed = 1.0
        self.loop: tuple[float, float] | None = None
        self.looping = False
        self._playing = False
        self._anchor_t = 0.0          # clock time at the anchor
        self._anchor_mono = time.monotonic()
        self._last = 0.0              # last value returned while playing (monotonic output)
        self._wav: Path | None = None
        self._player = None
        self._output = None
        if self.use_audio:
            self._make_player()
        log.info("playback clock: %s", "audio (QMediaPlayer)" if self.use_audio else
                 "silent monotonic clock (no audio device)")

    # ------------------------------------------------------------------ audio backend
    def _make_player(self) -> None:
        from PyQt6.QtMultimedia import QAudioOutput, QMediaPlayer

        self._player = QMediaPlayer(self)
        self._output = QAudioOutput(self)
        self._player.setAudioOutput(self._output)
        self._player.positionChanged.connect(self._on_position)
        self._player.errorOccurred.connect(self._on_error)

    def _on_position(self, ms: int) -> None:
        if self._playing:
            self._anchor_t = ms / 1000.0
            self._anchor_mono = time.monotonic()

    def _on_error(self, error, message: str = "") -> None:
        log.warning("audio playback failed (%s); using the silent clock", message or error)
        t = self.time()
        self._drop_player()
        self._anchor_t, self._anchor_mono = t, time.monotonic()

    def _drop_player(self) -> None:
        if self._player is not None:
            try:
                self._player.positionChanged.disconnect(self._on_position)
                self._player.errorOccurred.disconnect(self._on_error)
            except TypeError:
                pass
            self._player.stop()
            self._player.setSource(QUrl())
        self._player = None
        self.use_audio = False

    def close(self) -> None:
        """Stop and release the player and the temporary file (call before the window closes)."""
        self._playing = False
        self._drop_player()
        self._remove_wav()

    def _remove_wav(self) -> None:
        if self._wav is not None:
            try:
                self._wav.unlink()
            except OSError:
                pass
            self._wav = None

    # ------------------------------------------------------------------ API
    def load(self, audio: np.ndarray, rate: int) -> None:
        """Use a new signal; stops and rewinds."""
        self.pause()
        self.duration = len(audio) / float(rate)
        self.loop = None
        self._anchor_t = self._last = 0.0
        if self._player is not None:
            self._player.setSource(QUrl())
            self._remove_wav()
            fd, name = tempfile.mkstemp(prefix="facetraj-", suffix=".wav")
            os.close(fd)
            self._wav = Path(name)
            write_audio(self._wav, audio, rate)
            self._player.setSource(QUrl.fromLocalFile(str(self._wav)))

    @property
    def playing(self) -> bool:
        return self._playing

    def time(self) -> float:
        """The audio clock in seconds."""
        if not self._playing:
            return self._anchor_t
        t = self._anchor_t + (time.monotonic() - self._anchor_mono) * self.speed
        t = max(t, self._last)
        self._last = t
        return min(t, self.duration)

    def poll(self) -> float:
        """The current time, after wrapping at the loop end or stopping at the end of the signal."""
        t = self.time()
        if self._playing:
            if self.looping and self.loop is not None and t >= self.loop[1]:
                self.seek(self.loop[0])
                return self.loop[0]
            if t >= self.duration:
                if self.looping:
                    self.seek(self.loop[0] if self.loop else 0.0)
                    return self.time()
                self.pause()
                self._anchor_t = self.duration
                return self.duration
        return t

    def play(self) -> None:
        if self._playing or self.duration <= 0:
            return
        start = self._anchor_t
        if start >= self.duration - 1e-6:
            start = self.loop[0] if (self.looping and self.loop) else 0.0
        if self.looping and self.loop and not (self.loop[0] <= start < self.loop[1]):
            start = self.loop[0]
        self._anchor_t = self._last = start
        self._anchor_mono = time.monotonic()
        self._playing = True
        if self._player is not None:
            self._player.setPlaybackRate(self.speed)
            self._player.setPosition(int(round(start * 1000)))
            self._player.play()
        self.playingChanged.emit(True)

    def pause(self) -> None:
        if not self._playing:
            return
        t = self.time()
        self._playing = False
        self._anchor_t = self._last = t
        if self._player is not None:
            self._player.pause()
        self.playingChanged.emit(False)

    def toggle(self) -> None:
        self.pause() if self._playing else self.play()

    def stop(self) -> None:
        """Pause and rewind to the start (of the loop range when looping)."""
        self.pause()
        self.seek(self.loop[0] if (self.looping and self.loop) else 0.0)

    def seek(self, t: float) -> None:
        t = float(np.clip(t, 0.0, self.duration))
        self._anchor_t = self._last = t
        self._anchor_mono = time.monotonic()
        if self._player is not None:
            self._player.setPosition(int(round(t * 1000)))

    def set_speed(self, speed: float) -> None:
        t = self.time()
        self.speed = float(speed)
        self._anchor_t, self._anchor_mono, self._last = t, time.monotonic(), t
        if self._player is not None:
            self._player.setPlaybackRate(self.speed)

    def set_loop(self, start: float | None, end: float | None = None) -> None:
        """Set (or clear, with ``None``) the loop range."""
        if start is None or end is None or end - start < 1e-3:
            self.loop = None
        else:
            self.loop = (max(0.0, min(start, end)), min(self.duration, max(start, end)))
