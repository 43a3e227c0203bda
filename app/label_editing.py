"""The timeline as a label editor (an extension of the main window): the phones and words of the
recording on screen corrected with the mouse and the keyboard, each edit synthesized at once
(off the GUI thread, the window's request and stale-result logic: ``MainWindow.show_labels``),
undone and redone from the Edit menu that names it, and saved as a TextGrid that every command
then reads by the one label rule (``app/label_files.py``).

Keys (window-wide but in a text box): F2 (or Enter on the panels) rename, S split at the cursor,
M merge with the next, Delete / Backspace delete, 0 silence, Ctrl+Z undo, Ctrl+Shift+Z redo,
Ctrl+← / Ctrl+→ the previous / next segment; Ctrl+S save, Ctrl+Shift+S save as. The label
document itself is Qt-free (``facetraj_engine.labels.editing``), as is the session around it
(``app/label_session.py``).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import replace

from PyQt6.QtCore import QEvent, QObject, Qt, pyqtSignal
from PyQt6.QtGui import QAction, QKeySequence, QShortcut
from PyQt6.QtWidgets import QMenu, QMessageBox

from facetraj_engine.labels.editing import (
    PHONES,
    WORDS,
    Edit,
    EditRefused,
    LabelDocument,
    is_silence,
    shown,
)

from .label_bar import LabelBar
from .label_session import LabelSession, labels_of_view, save_path
from .provenance import LabelOrigin
from .state import UtteranceView
from .tier_edit import EditableTierPanel
from .timeline import PhoneTierPanel

log = logging.getLogger(__name__)

#: the editor's keys: (action, its text in the Edit menu, its keys)
EDIT_KEYS = (
    ("rename", "Rename the segment…", ("F2",)),
    ("split", "Split at the cursor", ("S",)),
    ("merge", "Merge with the next", ("M",)),
    ("delete", "Delete (the phone before takes its time)", ("Delete", "Backspace")),
    ("silence", "Mark as silence", ("0",)),
    ("previous", "Select the previous segment", ("Ctrl+Left",)),
    ("next", "Select the next segment", ("Ctrl+Right",)),
    ("word", "Add a word over the loop range or the phone selected…", ("W",)),
)


class LabelEditing(QObject):
    """The label editor of ``window``: a :class:`~facetraj_app.label_session.LabelSession` for
    the utterance on screen (made at its first edit or selection), its row over the panels
    (:class:`~facetraj_app.label_bar.LabelBar`), the editable tier
    (:class:`~facetraj_app.tier_edit.EditableTierPanel`), the Edit menu and the keys.

    ``edited(description)`` after each edit, undo or redo is applied (its synthesis asked for);
    ``followed(seconds)`` when the synthesis of the labels on screen is shown, with the time
    since the edit (the benchmark's figure); ``sessionChanged`` when the labels edited change
    (another utterance, a save, a reload)."""

    edited = pyqtSignal(str)
    followed = pyqtSignal(float)
    sessionChanged = pyqtSignal()

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.session: LabelSession | None = None
        self._asked_at: float | None = None         # when the last edit asked for its face
        self.base_title = window.windowTitle()
        self.panel = _editable_panel(window, self)
        self.bar = LabelBar()
        self.bar.renamed.connect(self.rename)
        self.bar.cancelled.connect(self._focus_panels)
        self.bar.edit.connect(lambda name: self.do(name))
        _place_over_panels(window, self.bar)
        self.bar.hide()                 # until labels are edited (``refresh``)
        self.actions = _edit_menu(window, self)
        self._shortcuts = _keys(window, self)
        window.synthesisChanged.connect(self._on_result)
        window.cursorMoved.connect(self._on_frame)     # the first frame of a result: its faces
        window.leave_checks.append(self.may_leave)
        window.installEventFilter(self)         # quitting with unsaved edits asks

    def eventFilter(self, obj, event) -> bool:
        if obj is self.window and event.type() == QEvent.Type.Close and \
                not self.window.may_leave("quitting"):
            event.ignore()
            return True
        return False

    # ------------------------------------------------------------------ the session
    def editable(self, view: UtteranceView | None) -> bool:
        """Whether ``view``'s labels can be edited (it has phones; a model to check them)."""
        return view is not None and bool(view.utterance.phones) and self.window.model is not None

    def ensure(self) -> LabelSession | None:
        """The session of the utterance on screen (begun now if need be; None: no labels)."""
        view = self.window.view
        if self.session is not None and self.session.same_place(view):
            return self.session         # (its labels may be an edit ahead of the view)
        if not self.editable(view):
            return None
        self.session = self._begin(view)
        self.sessionChanged.emit()
        return self.session

    def _begin(self, view: UtteranceView) -> LabelSession:
        w = self.window
        sources = w.audio_opener.current()
        made = sources.labels.get(sources.shown) if sources is not None else None
        corpus = w.corpus if view.split != "external" else None
        label_file = None
        if corpus is not None and not w.state.relabelled:
            from facetraj_engine.errors import FacetrajError
            from facetraj_engine.io.corpus import label_source

            try:
                label_file = label_source(corpus.data_root, view.utterance.name)
            except FacetrajError:
                label_file = None
        labels = labels_of_view(view, made, label_file,
                                corpus.info.label_provenance or None if corpus else None)
        path = save_path(view, sources.path if sources is not None else None,
                         corpus.data_root if corpus is not None else None)
        return LabelSession.of_view(view, labels, w.model.marker_rate, list(w.model.phones), path)

    def tier_view(self, view: UtteranceView) -> UtteranceView:
        """``view`` with the labels being edited (a step ahead of its synthesis), for the tier."""
        s = self.session
        if s is None or view.utterance.name != s.name or view.utterance.audio is not s.base.audio \
                or tuple(view.utterance.phones) == s.doc.phones:
            return view
        return replace(view, utterance=replace(view.utterance, phones=list(s.doc.phones),
                                               words=list(s.doc.words)))

    def _on_frame(self, _t: float) -> None:
        """A frame on screen: the first of the edit's result is its faces (``followed``)."""
        s = self.session
        if self._asked_at is not None and s is not None and s.matches(self.window.view):
            self.followed.emit(time.perf_counter() - self._asked_at)
            self._asked_at = None

    def _on_result(self) -> None:
        """A new result on screen: the session goes when it is of other labels (another
        utterance or label source: stale results never arrive, ``ViewerModel.accept``); the
        time since the edit is told when it is the edit's."""
        s, view = self.session, self.window.view
        if s is not None and not (s.same_place(view) and (s.matches(view) or self._asked_at)):
            self.session = None
            self.bar.say("")
            self.sessionChanged.emit()
        elif s is not None and self._asked_at is not None and s.matches(view):
            self.followed.emit(time.perf_counter() - self._asked_at)
            self._asked_at = None
        self.refresh()

    # ------------------------------------------------------------------ selection
    def boundaries(self, tier: str) -> list[tuple[float, int, str]]:
        """The boundaries of ``tier`` a drag may take: (time, index, side)."""
        s = self.ensure()
        if s is None:
            return []
        if tier == PHONES:
            return [(p.start, i, "start") for i, p in enumerate(s.doc.phones) if i > 0]
        return [(t, i, side) for i, w in enumerate(s.doc.words) for t, side in
                ((w.start, "start"), (w.end, "end"))]

    def selected_span(self) -> tuple[str, float, float] | None:
        s = self.session
        if s is None or s.doc.selection is None:
            return None
        sel = s.doc.selection
        seg = s.doc.segments(sel.tier)[sel.index]
        return sel.tier, seg.start, seg.end

    def select_at(self, tier: str, t: float) -> None:
        s = self.ensure()
        if s is not None:
            s.doc.select_at(tier, t)
            self.refresh(redraw=True)

    def select(self, tier: str, index: int) -> None:
        """Select segment ``index`` of ``tier`` (the review list, tests)."""
        s = self.ensure()
        if s is not None:
            s.doc.select(tier, index)
            self.refresh(redraw=True)

    def step(self, direction: int) -> None:
        s = self.ensure()
        if s is None:
            return
        sel = s.doc.step_selection(direction)
        if sel is not None:
            self.window.seek(s.doc.segments(sel.tier)[sel.index].start)
        self.refresh(redraw=True)

    def seek(self, t: float) -> None:
        self.window.seek(t)

    def redraw(self) -> None:
        self.window.timeline.redraw()

    # ------------------------------------------------------------------ edits
    def do(self, name: str) -> None:
        """The edit ``name`` on the selection: ``split`` (at the cursor), ``merge``, ``delete``,
        ``silence``, ``rename`` (the field), ``undo``, ``redo``, ``previous``, ``next``."""
        if name == "rename":
            if self.ensure() is not None and self.session.doc.selection is not None:
                self.bar.start_rename()
            else:
                self.bar.refuse("select a segment first (click it on the phones or words row)")
            return
        if name in ("previous", "next"):
            self.step(-1 if name == "previous" else 1)
            return
        if name == "word":
            self.add_word()
            return
        s = self.ensure()
        if s is None:
            self.bar.refuse("no labels to edit here")
            return
        ops: dict[str, Callable[[], Edit]] = {
            "split": lambda: s.doc.split(self.window.current_time()),
            "merge": s.doc.merge_next, "delete": s.doc.delete, "silence": s.doc.mark_silence,
            "undo": s.doc.undo, "redo": s.doc.redo}
        self._run(ops[name], undoing=name in ("undo", "redo"), verb=name)

    def rename(self, text: str) -> None:
        s = self.ensure()
        if s is None:
            return
        sel = s.doc.selection
        if sel is not None and " ".join(text.split()).lower() == \
                s.doc.segments(sel.tier)[sel.index].label.lower():
            self._focus_panels()        # as it is (the completer's Enter, then the field's)
            return
        if self._run(lambda: s.doc.rename(text)):
            self._focus_panels()

    def add_word(self, text: str | None = None) -> None:
        """A word over the loop range (a drag on the panels), else over the phone selected
        (recognized labels have no words); its text asked for when not given."""
        s = self.ensure()
        if s is None:
            return
        span = self.window.timeline.loop
        sel = s.doc.selection
        if span is None and sel is not None and sel.tier == PHONES:
            seg = s.doc.phones[sel.index]
            span = (seg.start, seg.end)
        if span is None:
            self.bar.refuse("select a phone, or drag over the phones of the word, first")
            return
        if text is None:
            from PyQt6.QtWidgets import QInputDialog

            text, ok = QInputDialog.getText(self.window, "Add a word",
                                            f"The word spoken {span[0]:.3f}-{span[1]:.3f} s:")
            if not ok:
                return
        self._run(lambda: s.doc.add_word(span[0], span[1], text))

    def drag_boundary(self, tier: str, index: int, side: str, t: float) -> None:
        s = self.ensure()
        if s is None:
            return
        if tier == PHONES:
            self._run(lambda: s.doc.move_boundary(index, t))
        else:
            self._run(lambda: s.doc.move_word_edge(index, side, t))

    def _run(self, edit: Callable[[], Edit], undoing: bool = False, verb: str = "") -> bool:
        """Make an edit: refused, say why (nothing changed); made, synthesize the labels."""
        try:
            done = edit()
        except EditRefused as why:
            self.bar.refuse(str(why))
            self.window.show_status(f"not done: {why}", 10000)
            self.refresh(redraw=False)
            return False
        text = f"{'undone' if verb == 'undo' else 'redone' if verb == 'redo' else ''}"
        said = f"{text}: {done.description}" if undoing else done.description
        self.bar.say(said)
        self._synthesize()
        self.edited.emit(said)
        self.refresh()            # the panels are drawn again with the edit's result (no draw
        return True               # now: it would compete with the synthesis for the CPU)

    def _synthesize(self) -> None:
        """The face of the labels on screen: a new request (a stale one is dropped)."""
        s = self.session
        self.request(s.utterance(), s.origin_now())

    def request(self, utt, origin) -> None:
        """Synthesize the utterance on screen with ``utt``'s labels (``origin``: where from)."""
        self._asked_at = time.perf_counter()
        self.window.show_labels(utt, origin)

    def restart(self, labels, path, on_disk) -> LabelSession | None:
        """Begin again from ``labels`` read from ``path`` (changed on disk; its stamp
        ``on_disk``), the edits here let go, and synthesize them."""
        s = self.session
        if s is None:
            return None
        doc = LabelDocument(labels, s.base.duration, s.doc.frame_rate, s.doc.phone_set, s.name)
        self.session = LabelSession(doc, s.base, LabelOrigin(s.origin.source, path.name,
                                                              s.origin.transcript),
                                    s.split, path, {path}, on_disk)
        self.sessionChanged.emit()
        self._synthesize()
        self.refresh(redraw=True)
        return self.session

    # ------------------------------------------------------------------ what is shown
    def refresh(self, redraw: bool = False) -> None:
        """The row over the panels, the Edit menu's undo and redo, the window's title and the
        selection's box."""
        s = self.session
        doc = s.doc if s is not None else None
        sel = doc.selection if doc is not None else None
        # the row over the panels only while labels are being edited (a laptop's panels keep
        # their height until then)
        self.bar.setVisible(sel is not None or bool(doc and doc.dirty) or self.bar.refusing)
        if sel is None:
            self.bar.show_selection("click a phone or a word to correct it" if
                                    self.editable(self.window.view) else "", None)
        else:
            self.bar.show_selection(self._describe(s), doc.segments(sel.tier)[sel.index].label,
                                    sel.tier)
        if self.window.model is not None:
            self.bar.set_phones(self.window.model.phones)
        undo, redo = self.actions["undo"], self.actions["redo"]
        undo.setEnabled(bool(doc and doc.undo_text))
        redo.setEnabled(bool(doc and doc.redo_text))
        undo.setText(f"&Undo {doc.undo_text}" if doc and doc.undo_text else "&Undo")
        redo.setText(f"&Redo {doc.redo_text}" if doc and doc.redo_text else "&Redo")
        self.window.setWindowTitle(f"{self.base_title} — {s.name}: labels edited, not saved[*]"
                                   if doc is not None and doc.dirty else self.base_title)
        self.window.setWindowModified(bool(doc and doc.dirty))
        self.panel.show_selection()
        if redraw:
            self.redraw()

    def _describe(self, s: LabelSession) -> str:
        """The segment selected in words: ``/n/ 1.100-1.240 s, recognized 0.16`` (its maker and
        confidence; the tooltip says which phone of how many)."""
        doc, sel = s.doc, s.doc.selection
        seg = doc.segments(sel.tier)[sel.index]
        n = len(doc.segments(sel.tier))
        self.bar.info.setToolTip(f"{sel.tier[:-1]} {sel.index + 1} of {n}")
        if sel.tier == WORDS:
            return f"“{seg.label}” {seg.start:.3f}-{seg.end:.3f} s"
        labels = doc.labels_now()
        if labels.provenance.hand_checked or labels.hand_checked[sel.index]:
            how = "checked by hand"
        else:
            c = float(labels.confidence[sel.index])
            how = f"{labels.provenance.kind}" + (f" {c:.2f}" if c == c else "")
        name = "silence" if is_silence(seg.label) else shown(seg.label)
        return f"{name} {seg.start:.3f}-{seg.end:.3f} s, {how}"

    def _focus_panels(self) -> None:
        self.window.timeline.canvas.setFocus(Qt.FocusReason.OtherFocusReason)

    # ------------------------------------------------------------------ leaving
    def may_leave(self, what: str) -> bool:
        """Asked before the labels on screen are left (``what``: another recording, quitting,
        another corpus): with unsaved edits, Save, Discard or Cancel."""
        s = self.session
        if s is None or not s.doc.dirty:
            return True
        box = QMessageBox(QMessageBox.Icon.Question, "Unsaved label edits",
                          f"The labels of {s.name} have edits that are not saved "
                          f"({s.doc.undo_text or 'edits undone'}).\nSave them before {what}?",
                          QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
                          | QMessageBox.StandardButton.Cancel, self.window)
        box.setDefaultButton(QMessageBox.StandardButton.Save)
        answer = box.exec()
        if answer == QMessageBox.StandardButton.Save:
            return self.window.extension("label_files").save()
        if answer == QMessageBox.StandardButton.Discard:
            self.discard()
            return True
        return False

    def discard(self) -> None:
        """Let the edits go: a recording opened from a file is its labels as they were made."""
        s, self.session = self.session, None
        if s is not None and s.split == "external":
            self.window.state.external[s.name] = s.base
        self.sessionChanged.emit()
        self.refresh(redraw=True)


def _editable_panel(window, editor: LabelEditing) -> EditableTierPanel:
    """The window's phone tier, made editable (in its place among the panels)."""
    panels = window.timeline.panels
    k = next(i for i, p in enumerate(panels) if isinstance(p, PhoneTierPanel))
    panels[k] = EditableTierPanel(window, editor)
    return panels[k]


def _place_over_panels(window, bar: LabelBar) -> None:
    """The editor's row between the title and the panels."""
    column = window.title.parentWidget().layout()
    column.insertWidget(column.indexOf(window.title) + 1, bar)


def _edit_menu(window, editor: LabelEditing) -> dict[str, QAction]:
    """The Edit menu (after File): undo and redo naming what they undo, and every edit."""
    menu = QMenu("&Edit", window)
    window.menuBar().insertMenu(window.menu("View").menuAction(), menu)
    actions: dict[str, QAction] = {}
    for name, keys in (("undo", ("Ctrl+Z",)), ("redo", ("Ctrl+Shift+Z", "Ctrl+Y"))):
        a = menu.addAction(f"&{name.title()}", lambda n=name: editor.do(n))
        a.setShortcuts([QKeySequence(k) for k in keys])
        a.setEnabled(False)
        actions[name] = a
    menu.addSeparator()
    for name, text, keys in EDIT_KEYS:
        a = menu.addAction(text, lambda n=name: editor.do(n))
        a.setShortcuts([QKeySequence(k) for k in keys])
        actions[name] = a
    editor.menu = menu
    return actions


def _keys(window, editor: LabelEditing) -> list[QShortcut]:
    """Enter on the panels renames (elsewhere Enter is the focused widget's own)."""
    keys = []
    for key in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
        sc = QShortcut(QKeySequence(key), window.timeline.canvas)
        sc.setContext(Qt.ShortcutContext.WidgetShortcut)
        sc.activated.connect(lambda: editor.do("rename"))
        keys.append(sc)
    return keys


def install(window) -> LabelEditing:
    """Make ``window``'s timeline a label editor; also ``window.extension("labels")``."""
    editor = LabelEditing(window)
    window.add_extension("labels", editor)
    return editor
