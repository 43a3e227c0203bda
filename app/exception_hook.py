"""The app's Qt exception hook: an unexpected exception in a slot never ends the app.

PyQt6 calls ``sys.excepthook`` for an exception that escapes a slot or a virtual method (a click,
a key, a paint); with Python's own hook it then aborts the process (SIGABRT), and everything on
screen is lost -- as the Measure view's CSV export did (issue 54). :class:`ExceptionHook`, installed
by ``facetraj_app.main.run_app``, instead logs the exception with its traceback and shows it in a
dialog that says what the user was doing (:class:`ActionTrail`: the last menu entry, button or key),
after the slot has returned; the window stays usable. A burst of the same failure (a paint that
fails on every frame) gives one dialog; later repeats go to the log and the status bar.
"""

from __future__ import annotations

import logging
import sys
import traceback
from collections.abc import Callable
from types import TracebackType

from PyQt6.QtCore import QEvent, QObject, QTimer
from PyQt6.QtGui import QKeySequence
from PyQt6.QtWidgets import QAbstractButton, QApplication, QMenu

log = logging.getLogger(__name__)

#: keys that are not actions of their own (held for a shortcut)
_MODIFIER_KEYS = {0x01000020, 0x01000021, 0x01000022, 0x01000023}   # Shift, Control, Meta, Alt


class ActionTrail(QObject):
    """What the user did last, in words: ``menu "File > Export a video…"``, ``button "Run"``,
    ``key "Ctrl+P"``. Menus report their entries (:meth:`watch_menu`), and an event filter on the
    application sees button clicks and key presses."""

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent)
        self.last = "starting"

    def watch_menu(self, menu: QMenu) -> None:
        """Record the entries of ``menu`` (and its submenus) when they are triggered, by mouse or
        shortcut."""
        menu.triggered.connect(lambda action, m=menu: self.note(
            f'menu "{m.title().replace("&", "")} > {action.text().replace("&", "")}"'))

    def note(self, what: str) -> None:
        self.last = what

    def eventFilter(self, obj, event) -> bool:
        kind = event.type()
        if kind == QEvent.Type.MouseButtonRelease and isinstance(obj, QAbstractButton):
            text = obj.text().replace("&", "") or obj.toolTip() or obj.objectName() or type(obj).__name__
            self.note(f'button "{text}"')
        elif kind in (QEvent.Type.ShortcutOverride, QEvent.Type.KeyPress) \
                and event.key() not in _MODIFIER_KEYS and not event.isAutoRepeat():
            # (a key bound to a shortcut never arrives as a KeyPress: its ShortcutOverride does)
            combo = QKeySequence(event.keyCombination()).toString()
            if combo:
                self.note(f'key "{combo}"')
        return False


def describe(exc_type: type[BaseException], exc: BaseException, doing: str) -> str:
    """The dialog's text for an unexpected exception.

    >>> describe(ValueError, ValueError("no frames"), 'button "Export CSV…"')
    'internal error after button "Export CSV…": ValueError: no frames (the window keeps ...)'
    """
    return (f"internal error after {doing}: {exc_type.__name__}: {exc} "
            "(the window keeps running; the traceback is in the log)")


class ExceptionHook:
    """``sys.excepthook`` while the app runs: log, then ``show(message)`` once the slot has
    returned (the window's error dialog); ``restore()`` puts the previous hook back."""

    def __init__(self, show: Callable[[str], None], trail: ActionTrail):
        self.show, self.trail = show, trail
        self.seen: set[tuple[str, str]] = set()
        self.count = 0
        self._previous = sys.excepthook

    def install(self) -> ExceptionHook:
        sys.excepthook = self
        return self

    def restore(self) -> None:
        if sys.excepthook is self:
            sys.excepthook = self._previous

    def __call__(self, exc_type: type[BaseException], exc: BaseException,
                 tb: TracebackType | None) -> None:
        if issubclass(exc_type, KeyboardInterrupt):
            self._previous(exc_type, exc, tb)
            return
        self.count += 1
        doing = self.trail.last
        try:
            log.error("unexpected error after %s", doing, exc_info=(exc_type, exc, tb))
        except Exception:           # a hook must never raise into Qt
            sys.stderr.write("".join(traceback.format_exception(exc_type, exc, tb)))
        where = traceback.extract_tb(tb)[-1] if tb is not None else None
        key = (exc_type.__name__, f"{where.filename}:{where.lineno}" if where else str(exc))
        first = key not in self.seen
        self.seen.add(key)
        message = describe(exc_type, exc, doing)
        if first:
            QTimer.singleShot(0, lambda: self.show(message))


def install_exception_hook(window) -> ExceptionHook:
    """The hook for ``window`` (its ``show_error``: a dialog, or the handler the window was given),
    with an :class:`ActionTrail` over its menus and the application's buttons and keys."""
    app = QApplication.instance()
    trail = ActionTrail(window)
    window.menus.watch(trail.watch_menu)
    if app is not None:
        app.installEventFilter(trail)
    return ExceptionHook(window.show_error, trail).install()


__all__ = ["ActionTrail", "ExceptionHook", "describe", "install_exception_hook"]
