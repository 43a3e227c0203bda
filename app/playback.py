"""The playback scheduler: which frame to show while the sound plays, and when.

:class:`PlaybackScheduler` shows one update per marker frame, each timed to reach the screen when
the audio clock (``app/transport.py``) is at that frame's time: a precise single-shot timer fires
when the clock plus the running estimate of one update's latency (tick to the window's flush)
reaches the next frame's time, so the frame lands on its time, never before it. An update that
took too long makes the next one skip frames rather than drift, and at most one frame is asked for
per flush (``frameDue``). Its :attr:`idle` gate is open while no sound plays: background work that must
not disturb playback waits on it (:meth:`app.workers.Progress.wait_open`) instead of polling the
clock.
"""

from __future__ import annotations

import math
import time

from PyQt6.QtCore import QObject, Qt, QTimer, pyqtSignal

from .state import frame_index
from .transport import PlaybackClock
from .workers import Gate

FLUSH_TIMEOUT = 0.25     # s without a flush (window hidden?) before the next frame is sent anyway
MAX_LATENCY = 0.08       # s: the lookahead never exceeds this
MAX_WAIT = 0.1           # s: the clock is polled at least this often (loop and end of the sound)
EARLY = 0.001            # s: a frame may land this much before its time rather than wait again


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
        self._timer.setSingleShot(True)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
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

    def plan(self, t: float) -> tuple[float | None, float]:
        """At clock time ``t`` while playing: the clock time of the frame to show now (None:
        the frame on screen is still the right one), and the wall-clock seconds until the next
        update should start (when ``t`` plus the latency reaches the next frame's time).

        An update started now lands at ``t`` plus the latency and shows the frame nearest to that
        time; the next frame is not started before it would land on its own time (with a latency
        over half a frame, starting as soon as the nearest frame changes would put every frame on
        screen up to half a frame early)."""
        clock = self.clock
        end = clock.loop[1] if (clock.looping and clock.loop) else clock.duration
        lead = self.latency * clock.speed
        target = min(t + lead, end)
        k = self.frame_at(target)
        following = self.displayed_frame + 1
        start = following / self.rate - lead  # when the following frame's update should start
        if k != following - 1 and not (k == following and t < start - EARLY * clock.speed):
            return target, 0.0                # the next frame on time or late, frames skipped, a jump back
        if following > self.n_frames - 1 or start + lead > end:
            start = end                       # no next frame before the end (or the loop's)
        return None, min(max((start - t) / clock.speed, 0.0), MAX_WAIT)

    def _on_playing_changed(self, playing: bool) -> None:
        self.idle.set_open(not playing)
        if playing:
            self._timer.start(0)
        else:
            self._timer.stop()

    def _start_timer(self, wait: float) -> None:
        """The next tick in ``wait`` seconds (whole milliseconds, never early)."""
        self._timer.start(max(0, math.ceil(wait * 1000.0)))

    def _tick(self) -> None:
        """One timer tick: the frame at the audio clock (skip frames, never drift)."""
        if self.n_frames == 0:
            return
        clock = self.clock
        t = clock.poll()
        if not clock.playing:
            self.frameDue.emit(t)
            return
        if self._pending is not None:
            waited = time.perf_counter() - self._pending[0]
            if waited < FLUSH_TIMEOUT:
                self._start_timer(FLUSH_TIMEOUT - waited)    # flushed() starts the next one
                return
            self._pending = None    # no flush came: do not stall
        target, wait = self.plan(t)
        if target is None:
            self._start_timer(wait)
            return
        self._pending = (time.perf_counter(), self.frame_at(target))
        self._start_timer(FLUSH_TIMEOUT)
        self.frameDue.emit(target)

    def flushed(self) -> None:
        """The window's flush (UpdateRequest) put the pending frame on screen: time it, and
        time the next update."""
        if self._pending is None:
            return
        start, k = self._pending
        self._pending = None
        spent = time.perf_counter() - start
        self.latency = min(0.8 * self.latency + 0.2 * spent, MAX_LATENCY) if self.latency else spent
        if self.stats is not None:
            self.stats.append((start, k, spent, self.clock.time()))
        if self.clock.playing:
            self._start_timer(self.plan(self.clock.time())[1])
