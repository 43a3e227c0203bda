"""The corrected labels on disk: File → Save labels (Ctrl+S) and Save labels as… (Ctrl+Shift+S)
write a TextGrid (``facetraj_engine.io.labelling.write_labels``: atomic, words, phones and the
provenance record, the phones changed counting as checked by hand), never over an existing file
before the user agrees; File → Open in Praat (where Praat is installed) opens the sound and the
labels in Praat's editor; and the TextGrid is watched: changed on disk (saved from Praat), it is
read again and the face synthesized again, the window saying so (asking first when edits of its
own are not saved)."""

from __future__ import annotations

import logging
import shutil
import subprocess
import tempfile
from pathlib import Path

from PyQt6.QtCore import QFileSystemWatcher, QObject, QTimer, pyqtSignal
from PyQt6.QtGui import QKeySequence
from PyQt6.QtWidgets import QFileDialog, QMessageBox

from facetraj_engine.errors import FacetrajError

from .label_session import LabelSession, save_path, stamp

log = logging.getLogger(__name__)

#: a watched file is looked at this long after its last change (a writer's several changes: one)
SETTLE_MS = 150


def praat_script(audio: Path, labels: Path) -> str:
    """A Praat script that opens ``audio`` and ``labels`` together in Praat's TextGrid editor.

    >>> print(praat_script(Path("/d/a.wav"), Path('/d/"b".TextGrid')))
    sound = Read from file: "/d/a.wav"
    grid = Read from file: "/d/""b"".TextGrid"
    selectObject: sound, grid
    View & Edit
    <BLANKLINE>
    """
    def quoted(p: Path) -> str:
        return '"' + str(p).replace('"', '""') + '"'

    return (f"sound = Read from file: {quoted(audio)}\ngrid = Read from file: {quoted(labels)}\n"
            "selectObject: sound, grid\nView & Edit\n")


class LabelFiles(QObject):
    """Saving, Praat and the watched TextGrid for the label editor ``editor``
    (``app/label_editing.py``). ``reloaded(path)`` after the labels were read again from disk."""

    reloaded = pyqtSignal(str)

    def __init__(self, window, editor):
        super().__init__(window)
        self.window, self.editor = window, editor
        self.praat = shutil.which("praat")
        self.watcher = QFileSystemWatcher(self)
        self.watcher.fileChanged.connect(self._poke)
        self.watcher.directoryChanged.connect(self._poke)     # a file replaced (Praat, an editor)
        self._settle = QTimer(self)     # a writer's several changes in a row read once, after them
        self._settle.setSingleShot(True)
        self._settle.setInterval(SETTLE_MS)
        self._settle.timeout.connect(self._check)
        self._path: Path | None = None
        self._seen: tuple[int, int] | None = None    # the stamp of the file last looked at
        self._asking = False
        menu, before = window.menu("File"), window.action_screenshot
        self.save_action = _action(window, menu, before, "Save &labels", self.save, "Ctrl+S")
        self.save_as_action = _action(window, menu, before, "Save labels &as…", self.save_as,
                                      "Ctrl+Shift+S")
        self.praat_action = _action(window, menu, before, "Open in &Praat", self.open_in_praat)
        self.praat_action.setEnabled(self.praat is not None)
        self.praat_action.setToolTip("the sound and its labels in Praat's TextGrid editor; saved "
                                     "there, the labels are read again here" if self.praat else
                                     "Praat is not installed (praat is not on the PATH)")
        menu.insertSeparator(before)
        window.synthesisChanged.connect(self._watch)
        editor.sessionChanged.connect(self._watch)

    # ------------------------------------------------------------------ saving
    def save(self, path: Path | None = None) -> bool:
        """Save the labels on screen (to ``path``, else where they were saved or belong:
        beside the audio, or the corpus's label file); False when nothing was written."""
        s = self.editor.ensure()
        if s is None:
            self.window.show_status("no labels to save (a recording without phone labels)", 6000)
            return False
        path = Path(path) if path is not None else s.path
        if path is None:
            return self.save_as()
        if path.exists() and path not in s.replace_ok and not self._agree_replace(path):
            return False
        from facetraj_engine.io.labelling import write_labels  # not for the first frame

        labels = s.doc.labels_now()
        try:
            write_labels(path, labels, s.base.duration, overwrite=True)
        except FacetrajError as exc:
            self.window.report_error(exc)
            return False
        s.path, s.on_disk = path, stamp(path)
        s.replace_ok.add(path)
        s.doc.mark_saved()
        self._adopt(s, path)
        hand = int(labels.hand_checked.sum())
        self.window.show_status(f"wrote {path}: {len(labels.phones)} phones, {hand} checked by "
                                f"hand; every command reads them from there", 10000)
        log.info("%s: labels saved, %d of %d phones checked by hand", path, hand,
                 len(labels.phones))
        self.editor.refresh()
        self._watch()
        return True

    def save_as(self) -> bool:
        s = self.editor.ensure()
        if s is None:
            self.window.show_status("no labels to save", 6000)
            return False
        start = str(s.path) if s.path is not None else f"{s.name}.TextGrid"
        name, _ = QFileDialog.getSaveFileName(self.window, "Save labels as", start,
                                              "TextGrid (*.TextGrid);;All files (*)")
        if not name:
            return False
        path = Path(name)
        if path.exists():               # the dialog asked already (its own overwrite question)
            s.replace_ok.add(path)
        return self.save(path)

    def _agree_replace(self, path: Path) -> bool:
        answer = QMessageBox.question(
            self.window, "Replace the label file?",
            f"{path} exists. Replace it with the labels on screen?",
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.No)
        return answer == QMessageBox.StandardButton.Yes

    def _adopt(self, s: LabelSession, path: Path) -> None:
        """After a save: the recording's label file is the one written (the labels box's *from
        the label file*), its origin says so, and the window's title too."""
        sources = self.window.audio_opener.current()
        utt = s.utterance()
        if sources is not None and sources.name == s.name:
            if s.split == "external":
                sources.label_file = path
                sources.labels["file"] = s.doc.labels_now()
            else:                       # a corpus utterance: its own labels are these now
                sources.base = utt
            sources.shown = "file"
        self.editor.request(utt, s.origin_now())

    # ------------------------------------------------------------------ Praat
    def open_in_praat(self) -> bool:
        """The recording and its labels in Praat's TextGrid editor (saved first when they have
        no file or unsaved edits); False when nothing was opened."""
        if self.praat is None:
            self.window.show_error("Praat is not installed here (no praat on the PATH)")
            return False
        s = self.editor.ensure()
        audio = self.window.audio_opener.current()
        if s is None or audio is None:
            self.window.show_status("no labels to open in Praat", 6000)
            return False
        if (s.doc.dirty or s.path is None or not s.path.exists()) and not self.save():
            return False
        script = Path(tempfile.mkdtemp(prefix="facetraj-praat-")) / "open.praat"
        script.write_text(praat_script(audio.path, s.path), encoding="utf-8")
        subprocess.Popen([self.praat, "--send", str(script)], stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True)
        self.window.show_status(f"{s.path.name} opened in Praat; saved there, it is read again "
                                "here", 10000)
        return True

    # ------------------------------------------------------------------ the watched file
    def watched_path(self) -> Path | None:
        """The label file of the labels on screen (the session's, else where it would be)."""
        s = self.editor.session
        if s is not None and s.path is not None:
            return s.path
        view = self.window.view
        if view is None:
            return None
        sources = self.window.audio_opener.current()
        corpus = self.window.corpus
        return save_path(view, sources.path if sources is not None else None,
                         corpus.data_root if corpus is not None and view.split != "external" else None)

    def _watch(self) -> None:
        """Watch the label file of the labels on screen (and its folder: a file replaced by
        another is seen too)."""
        path = self.watched_path()
        if path != self._path:
            self._path, self._seen = path, (stamp(path) if path is not None else None)
        wanted = [] if path is None else [str(p) for p in (path, path.parent) if p.exists()]
        have = self.watcher.files() + self.watcher.directories()
        if sorted(have) != sorted(wanted):
            if have:
                self.watcher.removePaths(have)
            if wanted:
                self.watcher.addPaths(wanted)

    def _poke(self, _name: str = "") -> None:
        self._settle.start()

    def _check(self) -> None:
        """The watched file as it is now: changed since it was last looked at, and not by this
        window's own save, it is read again."""
        path = self._path
        self._watch()
        if path is None or self._asking:
            return
        now = stamp(path)
        if now is None or now == self._seen:
            return
        self._seen = now
        s = self.editor.session
        if s is not None and s.path == path and s.on_disk == now:
            return                               # what this window wrote
        self.reload(path)

    def reload(self, path: Path) -> bool:
        """Read the labels of ``path`` again and synthesize them (asking first over unsaved
        edits); False when they were kept."""
        editor = self.editor
        s = editor.ensure()
        if s is None or self.watched_path() != path:
            return False
        if s.doc.dirty:
            self._asking = True
            try:
                answer = QMessageBox.question(
                    self.window, "Labels changed on disk",
                    f"{path.name} was changed outside facetraj (in Praat?). Read it again? The "
                    f"edits made here and not saved ({s.doc.undo_text}) would be lost.",
                    QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
                    QMessageBox.StandardButton.No)
            finally:
                self._asking = False
            if answer != QMessageBox.StandardButton.Yes:
                self.window.show_status(f"{path.name} changed on disk; the edits here were kept "
                                        "(Save overwrites it)", 10000)
                return False
        from facetraj_engine.io.labelfiles import read_label_file

        try:
            labels = read_label_file(path, s.base.sample_rate, s.base.duration)
        except FacetrajError as exc:
            self.window.report_error(exc)
            return False
        fresh = editor.restart(labels, path, stamp(path))
        self.window.show_status(f"{path.name} changed on disk: read again ("
                                f"{labels.provenance.describe()}), the face synthesized again", 12000)
        self.reloaded.emit(str(path))
        return fresh is not None


def _action(window, menu, before, text: str, slot, key: str = ""):
    from PyQt6.QtGui import QAction

    action = QAction(text, window)
    if key:
        action.setShortcut(QKeySequence(key))

    def run(_checked: bool = False) -> None:
        try:
            slot()
        except FacetrajError as exc:
            window.report_error(exc)

    action.triggered.connect(run)
    menu.insertAction(before, action)
    return action


def install(window) -> LabelFiles:
    """Saving, Praat and the watched file; after ``label_editing.install``. Also
    ``window.extension("label_files")``."""
    files = LabelFiles(window, window.extension("labels"))
    window.add_extension("label_files", files)
    return files
