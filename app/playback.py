"""The playback scheduler: which frame to show while the sound plays, and when.

:class:`PlaybackScheduler` runs a precise 5 ms timer while the clock (``app/transport.py``) plays.
Each tick it aims at the clock time when the update will reach the screen (the clock time plus a
running estimate of one frame's latency, measured from the window's flushes), skips frames rather
than drifting, and asks for at most one frame per flush (``frameDue``). Its :attr:`idle` gate is
open while no sound plays: background work that must not disturb playback waits on it
(:meth:`app.workers.Progress.wait_open`) instead of polling the clock.
"""

from __future__ import annotations

import time

from PyQt6.QtCore import QObject, Qt, QTimer, pyqtSignal

from .state import frame_index
from .transport import PlaybackClock
from .workers import Gate

TICK_MS = 5
FLUSH_TIMEOUT = 0.25     # s without a flush (window hidden?) before the next frame is sent anyway
MAX_LATENCY = 0.08       # s: the lookahead never exceeds this


class PlaybackScheduler(QObject):
    """Frame lookahead and pacing for one :class:`PlaybackClock`.

    ``frameDue(t)`` asks the window to show the frame at ``t`` seconds; the window reports back
    with :meth:`shown` and calls :meth:`flushed` when its next paint reaches the screen.
    ``stats``, when set to a list, receives ``(start, frame, latency, clock time)`` per flush
    (the playback benchmark's hook).
    """

    frameDue = pyqtSignal(float)

    def __init__(self, clock: PlaybackClock, parent: QObject | None = None):
        super().__init__(parent)
        self.clock = clock
        self.idle = Gate(is_open=not clock.playing)
        self.n_frames = 0
        self.rate = 60.0
        self.displayed_frame = -1
        self.latency = 0.0            # running estimate of one frame update (s)
        self.stats: list[tuple[float, int, float, float]] | None = None
        self._pending: tuple[float, int] | None = None   # (tick time, frame) until flushed
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.setInterval(TICK_MS)
        self._timer.timeout.connect(self._tick)
        clock.playingChanged.connect(self._on_playing_changed)

    def set_frames(self, n_frames: int, rate: float) -> None:
        """The frames of the utterance now shown."""
        self.n_frames, self.rate = int(n_frames), float(rate)

    def frame_at(self, t: float) -> int:
        return frame_index(t, self.rate, self.n_frames)

    def shown(self, frame: int) -> None:
        self.displayed_frame = int(frame)

    @property
    def pending(self) -> bool:
        """Whether a frame was sent and its flush has not come yet."""
        return self._pending is not None

    def stop(self) -> None:
        self._timer.stop()
        self.idle.set_open(True)

    def _on_playing_changed(self, playing: bool) -> None:
        self.idle.set_open(not playing)
        if playing:
            self._timer.start()
        else:
            self._timer.stop()

    def _tick(self) -> None:
        """One timer tick: the frame at the audio clock (skip frames, never drift)."""
        if self.n_frames == 0:
            return
        clock = self.clock
        t = clock.poll()
        if not clock.playing:
            self.frameDue.emit(t)
            return
        # aim at the clock time when this update reaches the screen
        end = clock.loop[1] if (clock.looping and clock.loop) else clock.duration
        target = min(t + self.latency * clock.speed, end)
        k = self.frame_at(target)
        if self._pending is not None:
            if time.perf_counter() - self._pending[0] < FLUSH_TIMEOUT:
                return
            self._pending = None    # no flush came: do not stall
        if k == self.displayed_frame:
            return
        self._pending = (time.perf_counter(), k)
        self.frameDue.emit(target)

    def flushed(self) -> None:
        """The window's flush (UpdateRequest) put the pending frame on screen: time it."""
        if self._pending is None:
            return
        start, k = self._pending
        self._pending = None
        spent = time.perf_counter() - start
        self.latency = min(0.8 * self.latency + 0.2 * spent, MAX_LATENCY) if self.latency else spent
        if self.stats is not None:
            self.stats.append((start, k, spent, self.clock.time()))
