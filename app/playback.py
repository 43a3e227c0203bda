"""The playback scheduler: which frame to show while the sound plays, and when.

:class:`PlaybackScheduler` shows one update per marker frame, each timed to reach the screen when
the audio clock (``app/transport.py``) is at that frame's time: a precise single-shot timer fires
when the clock plus the running estimate of one update's latency (tick to the window's flush)
reaches the next frame's time, so the frame lands on its time, never before it. The next frame is
rendered ahead right after a flush (``prepareDue``), so that the update at its time only puts it on
screen: its latency, and the uncertainty of that latency, are a fraction of a render's. An update
that took too long makes the next one skip frames rather than drift, and at most one frame is asked
for per flush (``frameDue``). Its :attr:`idle` gate is open while no sound plays: background work that must
not disturb playback waits on it (:meth:`facetraj_app.workers.Progress.wait_open`) instead of polling the
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
MAX_WAKE = 0.004         # s: the most a tick is timed early for its usual lateness


class PlaybackScheduler(QObject):
    """Frame lookahead and pacing for one :class:`PlaybackClock`.

    ``frameDue(t)`` asks the window to show the frame at ``t`` seconds; the window reports back
    with :meth:`shown` and calls :meth:`flushed` when its next paint reaches the screen.
    ``prepareDue(t)`` (while playing, after a flush) asks it to render the frame at ``t`` ahead,
    off screen, at once: a later ``frameDue`` for that frame then only puts it on screen.
    ``stats``, when set to a list, receives ``(start, frame, work, clock time)`` per flush (the
    playback benchmark's hook): the tick's time, the frame shown, the seconds its update took
    (rendering it ahead plus tick to flush) and the clock at the flush.
    """

    frameDue = pyqtSignal(float)
    prepareDue = pyqtSignal(float)

    def __init__(self, clock: PlaybackClock, parent: QObject | None = None):
        super().__init__(parent)
        self.clock = clock
        self.idle = Gate(is_open=not clock.playing)
        self.n_frames = 0
        self.rate = 60.0
        self.displayed_frame = -1
        self.latency = 0.0            # running estimate of one frame update, tick to flush (s)
        self.prepare_time = 0.0       # running estimate of rendering a frame ahead (s)
        self.wake = 0.0               # running estimate of how late a timed tick comes (s)
        self.stats: list[tuple[float, int, float, float]] | None = None
        self._pending: tuple[float, int, float] | None = None   # (tick time, frame, ahead s) until flushed
        self._ahead: tuple[int, float] | None = None    # (frame, seconds) rendered ahead, not shown
        self._due: float | None = None    # when the pacing timer should fire (perf_counter s)
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
        """The window shows ``frame``; any frame rendered ahead is used or stale now."""
        self.displayed_frame = int(frame)
        self._ahead = None

    @property
    def ahead(self) -> int | None:
        """The frame rendered ahead and not shown yet (None: none)."""
        return None if self._ahead is None else self._ahead[0]

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
        end = self._end()
        lead = self.latency * clock.speed
        target = min(t + lead, end)
        k = self.frame_at(target)
        shown = self.displayed_frame
        following = shown + 1 if self._ahead is None else self._ahead[0]
        # when the following frame's update should start, and its timer fire (a tick comes late)
        start = following / self.rate - lead - self.wake * clock.speed
        if not shown <= k <= following:
            return target, 0.0                # late (frames skipped) or a jump back
        if k != shown and t >= start - EARLY * clock.speed:
            return target, 0.0                # the following frame, landing on its time
        if following > self.n_frames - 1 or start + lead > end:
            start = end                       # no next frame before the end (or the loop's)
        return None, min(max((start - t) / clock.speed, 0.0), MAX_WAIT)

    def prepare_next(self, t: float) -> int | None:
        """At clock time ``t`` while playing, after a flush: have the frame that follows the one on
        screen rendered ahead (``prepareDue``; a later one if it could not be shown by its time).
        Returns that frame (None: no frame follows before the end)."""
        clock = self.clock
        end = self._end()
        lead = (self.latency + self.prepare_time) * clock.speed
        k = max(self.displayed_frame + 1, self.frame_at(min(t + lead, end)))
        if k > self.n_frames - 1 or k / self.rate > end:
            return None
        t0 = time.perf_counter()
        self.prepareDue.emit(k / self.rate)
        took = time.perf_counter() - t0
        self.prepare_time = _running(self.prepare_time, took)
        self._ahead = (k, took)
        return k

    def _end(self) -> float:
        """The clock time playback wraps or stops at."""
        clock = self.clock
        return clock.loop[1] if (clock.looping and clock.loop) else clock.duration

    def _on_playing_changed(self, playing: bool) -> None:
        self.idle.set_open(not playing)
        self._ahead = self._due = None
        if playing:
            self._timer.start(0)
        else:
            self._timer.stop()

    def _start_timer(self, wait: float, paced: bool = True) -> None:
        """The next tick in ``wait`` seconds (whole milliseconds, never early); a ``paced`` one
        (the start of an update, not a flush timeout) is timed for :attr:`wake`."""
        self._due = time.perf_counter() + wait if paced else None
        self._timer.start(max(0, math.ceil(wait * 1000.0)))

    def _tick(self) -> None:
        """One timer tick: the frame at the audio clock (skip frames, never drift)."""
        if self._due is not None:
            self.wake = min(_running(self.wake, max(time.perf_counter() - self._due, 0.0)), MAX_WAKE)
            self._due = None
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
                self._start_timer(FLUSH_TIMEOUT - waited, paced=False)   # flushed() starts the next
                return
            self._pending = None    # no flush came: do not stall
        target, wait = self.plan(t)
        if target is None:
            self._start_timer(wait)
            return
        k = self.frame_at(target)
        ahead = self._ahead[1] if self._ahead is not None and self._ahead[0] == k else 0.0
        self._pending = (time.perf_counter(), k, ahead)
        self._start_timer(FLUSH_TIMEOUT, paced=False)
        self.frameDue.emit(target)

    def flushed(self) -> None:
        """The window's flush (UpdateRequest) put the pending frame on screen: time it, and
        time the next update."""
        if self._pending is None:
            return
        start, k, ahead = self._pending
        self._pending = None
        spent = time.perf_counter() - start
        self.latency = _running(self.latency, spent)
        if self.stats is not None:
            self.stats.append((start, k, ahead + spent, self.clock.time()))
        if self.clock.playing:
            self.prepare_next(self.clock.time())
            self._start_timer(self.plan(self.clock.time())[1])


def _running(estimate: float, seconds: float) -> float:
    """A running estimate of a duration (the first value as it is), at most MAX_LATENCY."""
    return min(0.8 * estimate + 0.2 * seconds, MAX_LATENCY) if estimate else min(seconds, MAX_LATENCY)
