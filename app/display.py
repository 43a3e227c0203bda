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


def ensure_display() -> subprocess.Popen | None:
    """For a screenshot on a machine without a display: start a private Xvfb (None if not needed)."""
    if has_display():
        return None
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        log.warning("no display and no Xvfb: the 3-D view needs an X display")
        return None
    read, write = os.pipe()
    # -terminate: the server exits by itself when its last client (this process) disconnects
    proc = subprocess.Popen([xvfb, "-displayfd", str(write), "-screen", "0", "1600x1200x24", "-nolisten",
                             "tcp", "-terminate"], pass_fds=(write,), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    os.close(write)
    with os.fdopen(read) as fh:
        number = fh.readline().strip()
    os.environ["DISPLAY"] = f":{number}"
    log.info("started Xvfb on display :%s for the screenshot", number)
    return proc


def require_display(what: str) -> None:
    """A window needs a display: a :class:`FacetrajError` (exit 2) naming what was asked for,
    instead of Qt aborting the process when it finds no platform to open windows on."""
    if has_display():
        return
    from facetraj_engine.errors import FacetrajError

    raise FacetrajError(f"{what} needs a display, and neither DISPLAY nor WAYLAND_DISPLAY is set: "
                        "run it in a desktop session or under xvfb-run")
