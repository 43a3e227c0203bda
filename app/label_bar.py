"""The label editor's row over the panels: the segment selected (its phone, times, where its label
came from and how sure its maker was), a field to rename it with the model's phones offered as
one types, the edits as buttons with their keys, and why the last edit was refused."""

from __future__ import annotations

from collections.abc import Sequence

from PyQt6.QtCore import QStringListModel, Qt, pyqtSignal
from PyQt6.QtWidgets import (
    QCompleter,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QSizePolicy,
    QToolButton,
    QWidget,
)

#: the edits the row offers: (key of the signal ``edit``, the button's text, its key, tooltip)
BUTTONS = (
    ("split", "Split", "S", "split the segment selected at the cursor (S)"),
    ("merge", "Merge", "M", "merge the segment selected with the next one (M)"),
    ("delete", "Delete", "Del", "delete the segment selected: the phone before takes its time "
                                "(Delete); a word leaves a gap"),
    ("silence", "Silence", "0", "mark the phone selected as silence (0)"),
)
REFUSED_STYLE = "color: #c92a2a;"


class LabelBar(QWidget):
    """One row: the selection (:meth:`show_selection`), the rename field (``renamed(text)`` on
    Enter; Esc gives the focus back: ``cancelled``), the edits' buttons (``edit(name)``) and a
    message (:meth:`refuse`, :meth:`say`)."""

    renamed = pyqtSignal(str)
    cancelled = pyqtSignal()
    edit = pyqtSignal(str)

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(6, 1, 6, 1)
        lay.setSpacing(4)
        self.info = QLabel("")
        self.info.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Fixed)
        self.info.setMinimumWidth(60)
        self.field = QLineEdit()
        self.field.setPlaceholderText("label (F2)")
        self.field.setToolTip("rename the segment selected (F2, or Enter on the panels): a phone "
                              "of the model (offered as you type), or a word's text; Enter "
                              "applies it, Esc leaves it")
        self.field.setMaximumWidth(80)
        self.field.setEnabled(False)
        self.phones = QStringListModel([])
        self.completer = QCompleter(self.phones, self.field)
        self.completer.setCaseSensitivity(Qt.CaseSensitivity.CaseInsensitive)
        self.completer.setCompletionMode(QCompleter.CompletionMode.PopupCompletion)
        self.field.setCompleter(self.completer)
        self.field.returnPressed.connect(lambda: self.renamed.emit(self.field.text()))
        lay.addWidget(self.info)
        lay.addWidget(self.field)
        self.buttons: dict[str, QToolButton] = {}
        for name, text, _key, tip in BUTTONS:
            b = QToolButton()
            b.setText(text)
            b.setToolTip(tip)
            b.setEnabled(False)
            b.clicked.connect(lambda _c=False, n=name: self.edit.emit(n))
            self.buttons[name] = b
            lay.addWidget(b)
        self.message = QLabel("")
        self.message.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        lay.addWidget(self.message, 1)
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)

    def keyPressEvent(self, event) -> None:
        if event.key() == Qt.Key.Key_Escape and self.field.hasFocus():
            self.cancelled.emit()
            return
        super().keyPressEvent(event)

    def set_phones(self, phones: Sequence[str]) -> None:
        """The phones offered in the rename field (the model's, and silence)."""
        self.phones.setStringList(sorted(set(phones)))

    def show_selection(self, text: str, label: str | None, tier: str = "phones") -> None:
        """The segment selected in words (``label`` None: nothing selected)."""
        self.info.setText(text)
        on = label is not None
        self.field.setEnabled(on)
        self.completer.setModel(self.phones if tier == "phones" else QStringListModel([]))
        if not self.field.hasFocus():
            self.field.setText(label or "")
        for name, b in self.buttons.items():
            b.setEnabled(on and (tier == "phones" or name != "silence"))

    def start_rename(self) -> None:
        """Put the focus in the rename field, its text selected (F2)."""
        self.field.setFocus(Qt.FocusReason.ShortcutFocusReason)
        self.field.selectAll()

    @property
    def refusing(self) -> bool:
        """Whether the message shown is a refusal."""
        return self.message.styleSheet() == REFUSED_STYLE and bool(self.message.text())

    def refuse(self, why: str) -> None:
        """Why the last edit was refused (one line, in red)."""
        self.setVisible(True)
        self.message.setStyleSheet(REFUSED_STYLE)
        self.message.setText(why)
        self.message.setToolTip(why)

    def say(self, text: str) -> None:
        self.message.setStyleSheet("")
        self.message.setText(text)
        self.message.setToolTip(text)
