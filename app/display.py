"""A display for Qt windows: whether there is one, a private Xvfb for screenshots without one,
and a clear error instead of Qt aborting the process."""

from __future__ import annotations

import logging
import os
import shutil
import subprocess

log = logging.getLogger(__name__)


def has_display() -> bool:
    """Whether Qt can open a window here: an X or Wayland display, or a Qt platform that needs
    no display server (``QT_QPA_PLATFORM`` offscreen, minimal or vnc)."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")) or \
        os.environ.get("QT_QPA_PLATFORM", "").split(":")[0] in ("offscreen", "minimal", "vnc")


def start_xvfb(size: str, terminate: bool) -> tuple[subprocess.Popen, str]:
    """An Xvfb of one screen ``size`` ("WxH", 24-bit) on a free display, in a session of its own;
    (the process, ":N"). ``terminate``: the server exits by itself when its last client
    disconnects. A :class:`RuntimeError` when it reports no display."""
    read, write = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", f"{size}x24", "-nolisten",
                             "tcp", *(["-terminate"] if terminate else [])], pass_fds=(write,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    os.close(write)
    with os.fdopen(read) as fh:
        number = fh.readline().strip()
    if not number:
        proc.kill()
        raise RuntimeError(f"Xvfb did not start a {size} screen")
    return proc, f":{number}"


def ensure_display() -> subprocess.Popen | None:
    """For a screenshot on a machine without a display: start a private Xvfb (None if not needed)."""
    if has_display():
        return None
    if shutil.which("Xvfb") is None:
        log.warning("no display and no Xvfb: the 3-D view needs an X display")
        return None
    # -terminate: the server exits by itself when its last client (this process) disconnects
    try:
        proc, display = start_xvfb("1600x1200", terminate=True)
    except RuntimeError as exc:
        log.warning("%s: the 3-D view needs an X display", exc)
        return None
    os.environ["DISPLAY"] = display
    log.info("started Xvfb on display %s for the screenshot", display)
    return proc


def require_display(what: str) -> None:
    """A window needs a display: a :class:`FacetrajError` (exit 2) naming what was asked for,
    instead of Qt aborting the process when it finds no platform to open windows on."""
    if has_display():
        return
    from facetraj_engine.errors import FacetrajError

    raise FacetrajError(f"{what} needs a display, and neither DISPLAY nor WAYLAND_DISPLAY is set: "
                        "run it in a desktop session or under xvfb-run")


#: Qt's sound back ends report what they do not find (PipeWire, PulseAudio, the FFmpeg version)
#: on every start; at the debug level of this logger they show with -vv only
QT_AUDIO_NOISE = ("qt.multimedia", "PulseAudioService", "qt.qpa.xcb")
QT_LOGGER = "facetraj_app.qt"


def route_qt_messages() -> None:
    """Qt's own messages go to Python's logging (logger ``facetraj_app.qt``) instead of straight
    to stderr: ``-q`` then shows none of them (``facetraj live -q`` without a microphone printed
    a dozen ``qt.multimedia`` lines before its one-line error); the sound back ends' start-up
    reports at debug level, other warnings as warnings, critical messages as errors. Call it
    before the QApplication is made."""
    os.environ.setdefault("QT_LOGGING_RULES", "qt.multimedia.*=false;qt.multimedia.ffmpeg=false")
    from PyQt6.QtCore import QtMsgType, qInstallMessageHandler

    qt_log = logging.getLogger(QT_LOGGER)
    levels = {QtMsgType.QtDebugMsg: logging.DEBUG, QtMsgType.QtInfoMsg: logging.INFO,
              QtMsgType.QtWarningMsg: logging.WARNING, QtMsgType.QtCriticalMsg: logging.ERROR,
              QtMsgType.QtFatalMsg: logging.CRITICAL}

    def handler(mode, context, message) -> None:
        try:
            category = context.category or ""
            noise = category.startswith(QT_AUDIO_NOISE) or message.startswith(QT_AUDIO_NOISE)
            level = logging.DEBUG if noise else levels.get(mode, logging.WARNING)
            qt_log.log(level, "%s%s", f"{category}: " if category and category != "default" else "",
                       message)
        except Exception:       # a message handler must never raise into Qt
            pass

    qInstallMessageHandler(handler)
