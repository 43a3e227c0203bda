"""Bringing one's own data in and getting results out (File menu).

In: a dialog that describes a folder of recordings (audio + labels + markers in any format of
:mod:`facetraj_engine.io.markerformats`) as a corpus: the channels' names, which markers are the fixed head
references (none for head-corrected data) and which are the lip centres, and an editable table
that maps the folder's labels onto ARPAbet (a MOCHA-TIMIT preset is provided). The description is
written by the engine (:func:`facetraj_engine.io.corpus.init_corpus`) and opened like any corpus.

Out: the current synthesized or original trajectories (C3D, TSV, NPZ), the time-aligned panels as
a figure (PNG, SVG, PDF), the model file, and a video (MP4) with a progress bar. Every file is
written under a temporary name and renamed into place; Qt's save dialog asks before an existing
file is replaced.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from PyQt6.QtCore import Qt
from PyQt6.QtGui import QAction
from PyQt6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QMessageBox,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from facetraj_app.analysis.common import ask_save_path
from facetraj_app.measure_model import view_frame_labels
from facetraj_engine.errors import FacetrajError
from facetraj_engine.io.corpus import FolderScan, init_corpus, scan_folder
from facetraj_engine.io.export import write_trajectories
from facetraj_engine.io.files import atomic_write
from facetraj_engine.io.labelfiles import write_label_map
from facetraj_engine.io.markerformats import formats
from facetraj_engine.labels.labelmap import MOCHA_TO_ARPABET, read_label_map
from facetraj_engine.labels.phoneset import ARPABET, SILENCE, SILENCE_LABELS, normalise_label

log = logging.getLogger(__name__)

#: an exported figure is at least this wide (px at 100 dpi; written at 150 dpi)
EXPORT_MIN_WIDTH = 900

FIXED_HINTS = ("FH", "FOREHEAD", "NB", "NOSE_BRIDGE", "BN", "UI", "HEAD", "REF")
UPPER_HINTS = ("UL_C", "UL", "ULC", "UPPER_LIP")
LOWER_HINTS = ("LL_C", "LL", "LLC", "LOWER_LIP")


def guess_roles(names: list[str]) -> tuple[list[str], str, str]:
    """Likely fixed markers and lip centres from the names (the user confirms in the dialog)."""
    upper_names = [n.upper() for n in names]
    fixed = [n for n, u in zip(names, upper_names, strict=True) if u.startswith(FIXED_HINTS)]

    def first(hints: tuple[str, ...]) -> str:
        for h in hints:
            for n, u in zip(names, upper_names, strict=True):
                if u == h:
                    return n
        for h in hints:
            for n, u in zip(names, upper_names, strict=True):
                if u.startswith(h):
                    return n
        return names[0]

    return fixed, first(UPPER_HINTS), first(LOWER_HINTS)


def default_label_map(labels: list[str], preset: str = "") -> dict[str, str]:
    """A starting label map: the preset's entry, or the label itself when it is ARPAbet."""
    table = MOCHA_TO_ARPABET if preset == "mocha" else {}
    out = {}
    for lab in labels:
        norm = normalise_label(lab)
        if lab in table:
            out[lab] = table[lab]
        elif lab.lower() in SILENCE_LABELS or norm == SILENCE:
            out[lab] = SILENCE
        elif norm in ARPABET:
            out[lab] = norm
        else:
            out[lab] = ""
    return out


class ImportDialog(QDialog):
    """Describe a folder of one's own recordings as a corpus."""

    def __init__(self, parent: QWidget | None = None, folder: Path | None = None):
        super().__init__(parent)
        self.setWindowTitle("Import your own recordings")
        self.resize(720, 640)
        self.scan: FolderScan | None = None
        self.result_path: Path | None = None
        lay = QVBoxLayout(self)
        intro = QLabel("A folder with one audio file (WAV/FLAC), one label file (TextGrid, .lab, "
                       ".phn) and one marker file per utterance, sharing the file name (an MVIEW "
                       "file may hold the audio and labels itself). Marker files: "
                       + ", ".join(f"{f.name} ({', '.join(f.suffixes)})" for f in formats()) + ".")
        intro.setWordWrap(True)
        lay.addWidget(intro)
        form = QFormLayout()
        row = QHBoxLayout()
        self.folder_edit = QLineEdit()
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row.addWidget(self.folder_edit)
        row.addWidget(browse)
        form.addRow("Folder", row)
        self.summary = QLabel("")
        self.summary.setWordWrap(True)
        form.addRow("", self.summary)
        self._channel_rows(form)
        self.fixed_list = QListWidget()
        self.fixed_list.setSelectionMode(QAbstractItemView.SelectionMode.NoSelection)
        self.fixed_list.setMaximumHeight(130)
        form.addRow("Fixed (head) markers", self.fixed_list)
        self.upper_lip = QComboBox()
        self.lower_lip = QComboBox()
        form.addRow("Upper lip centre", self.upper_lip)
        form.addRow("Lower lip centre", self.lower_lip)
        self.rate = QDoubleSpinBox()
        self.rate.setRange(10, 1000)
        self.rate.setValue(60)
        self.rate.setSuffix(" Hz")
        form.addRow("Marker rate (resampled to)", self.rate)
        self.test_fraction = QDoubleSpinBox()
        self.test_fraction.setRange(0, 0.9)
        self.test_fraction.setSingleStep(0.05)
        self.test_fraction.setValue(1 / 3)
        form.addRow("Test fraction", self.test_fraction)
        self.output_edit = QLineEdit()
        form.addRow("Description file", self.output_edit)
        lay.addLayout(form)
        map_row = QHBoxLayout()
        map_row.addWidget(QLabel("Label map onto ARPAbet (empty cells: the label is unknown)"))
        self.preset = QComboBox()
        self.preset.addItems(["labels as they are", "MOCHA-TIMIT"])
        self.preset.currentIndexChanged.connect(self._fill_map)
        map_row.addWidget(self.preset)
        load = QPushButton("Load…")
        load.clicked.connect(self._load_map)
        save = QPushButton("Save…")
        save.clicked.connect(self._save_map)
        map_row.addWidget(load)
        map_row.addWidget(save)
        lay.addLayout(map_row)
        self.map_table = QTableWidget(0, 2)
        self.map_table.setHorizontalHeaderLabels(["label", "ARPAbet"])
        self.map_table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Stretch)
        lay.addWidget(self.map_table, 1)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                   | QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self._accept)
        buttons.rejected.connect(self.reject)
        self.ok_button = buttons.button(QDialogButtonBox.StandardButton.Ok)
        self.ok_button.setEnabled(False)
        lay.addWidget(buttons)
        self.folder_edit.editingFinished.connect(lambda: self.set_folder(Path(self.folder_edit.text())))
        if folder is not None:
            self.set_folder(folder)

    def _channel_rows(self, form: QFormLayout) -> None:
        """The channels' names (the folder scanned again with them) and the head-correction box."""
        self.channel_names = QLineEdit()
        self.channel_names.setPlaceholderText("the files' own names (e.g. Ch1=UL Ch2=LL, or one "
                                              "name per channel)")
        self.channel_names.editingFinished.connect(
            lambda: self.set_folder(Path(self.folder_edit.text())))
        form.addRow("Channel names", self.channel_names)
        self.head_corrected = QCheckBox("already corrected for head motion (no fixed markers "
                                        "needed)")
        form.addRow("", self.head_corrected)

    # ------------------------------------------------------------------ folder
    def _browse(self) -> None:
        path = QFileDialog.getExistingDirectory(self, "A folder of recordings")
        if path:
            self.set_folder(Path(path))

    def set_folder(self, folder: Path) -> None:
        """Scan ``folder`` and fill the marker roles and the label map."""
        self.folder_edit.setText(str(folder))
        try:
            scan = scan_folder(folder, channel_names=self.channel_names.text().split() or None)
        except FacetrajError as exc:
            self.scan = None
            self.summary.setText(str(exc))
            self.ok_button.setEnabled(False)
            return
        self.scan = scan
        dims = "midsagittal (2-D)" if scan.dimensions == 2 else "3-D"
        self.summary.setText(f"{len(scan.ids)} utterances, {len(scan.marker_names)} {dims} markers at "
                             f"{scan.marker_rate:g} Hz, {len(scan.labels)} distinct labels"
                             + (f"; {len(scan.left_out)} files without labels or markers left out"
                                if scan.left_out else "")
                             + (f"; {scan.format} files: head-corrected" if scan.head_corrected
                                else ""))
        if not self.channel_names.text() and scan.channel_names:
            self.channel_names.setText(" ".join(scan.channel_names))
        self.head_corrected.setChecked(bool(scan.head_corrected))
        fixed, upper, lower = guess_roles(scan.marker_names)
        self.fixed_list.clear()
        for name in scan.marker_names:
            item = QListWidgetItem(name)
            item.setFlags(item.flags() | Qt.ItemFlag.ItemIsUserCheckable)
            item.setCheckState(Qt.CheckState.Checked if name in fixed else Qt.CheckState.Unchecked)
            self.fixed_list.addItem(item)
        for combo, pick in ((self.upper_lip, upper), (self.lower_lip, lower)):
            combo.clear()
            combo.addItems(scan.marker_names)
            combo.setCurrentText(pick)
        mocha = any(lab in ("@", "ii", "uu", "@@", "breath") for lab in scan.labels)
        self.preset.blockSignals(True)
        self.preset.setCurrentIndex(1 if mocha else 0)
        self.preset.blockSignals(False)
        self._fill_map()
        out = folder / "corpus.json"
        if not os.access(folder, os.W_OK):
            from platformdirs import user_data_dir

            out = Path(user_data_dir("facetraj")) / "corpora" / f"{folder.name}.json"
        self.output_edit.setText(str(out))
        self.ok_button.setEnabled(True)

    # ------------------------------------------------------------------ label map
    def _fill_map(self) -> None:
        if self.scan is None:
            return
        preset = "mocha" if self.preset.currentIndex() == 1 else ""
        self.set_label_map(default_label_map(self.scan.labels, preset))

    def set_label_map(self, table: dict[str, str]) -> None:
        self.map_table.setRowCount(0)
        for lab, arpa in table.items():
            r = self.map_table.rowCount()
            self.map_table.insertRow(r)
            item = QTableWidgetItem(lab)
            item.setFlags(item.flags() & ~Qt.ItemFlag.ItemIsEditable)
            self.map_table.setItem(r, 0, item)
            self.map_table.setItem(r, 1, QTableWidgetItem(arpa))

    def label_map(self) -> dict[str, str]:
        """The table as a dict (rows with an empty ARPAbet cell left out)."""
        out = {}
        for r in range(self.map_table.rowCount()):
            lab = self.map_table.item(r, 0).text()
            cell = self.map_table.item(r, 1)
            arpa = cell.text().strip() if cell else ""
            if arpa:
                out[lab] = arpa
        return out

    def _load_map(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Load a label map", "", "Label map (*.tsv *.txt)")
        if not path:
            return
        try:
            loaded = read_label_map(path)
        except FacetrajError as exc:
            QMessageBox.critical(self, "facetraj", str(exc))
            return
        current = {self.map_table.item(r, 0).text(): "" for r in range(self.map_table.rowCount())}
        self.set_label_map({**current, **loaded})

    def _save_map(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save the label map", "labels.tsv", "TSV (*.tsv)")
        if path:
            write_label_map(path, self.label_map())

    # ------------------------------------------------------------------ accept
    def fixed_markers(self) -> list[str]:
        return [self.fixed_list.item(i).text() for i in range(self.fixed_list.count())
                if self.fixed_list.item(i).checkState() == Qt.CheckState.Checked]

    def write_description(self) -> Path:
        """Write the label map and the corpus description; return the description's path."""
        if self.scan is None:
            raise FacetrajError("choose a folder of recordings first")
        folder = Path(self.folder_edit.text())
        out = Path(self.output_edit.text())
        out.parent.mkdir(parents=True, exist_ok=True)
        table = self.label_map()
        unknown = [r for r in self.scan.labels if r not in table]
        if unknown:
            raise FacetrajError(f"{folder}: labels without an ARPAbet entry: {' '.join(unknown)}")
        identity = all(normalise_label(k) == normalise_label(v) for k, v in table.items())
        label_map = ""
        if not identity:
            map_path = out.with_name(out.stem + ".labelmap.tsv")
            write_label_map(map_path, table)
            label_map = map_path.name
        path, _ = init_corpus(folder, out, self.fixed_markers(), self.upper_lip.currentText(),
                              self.lower_lip.currentText(), label_map=label_map,
                              marker_rate=self.rate.value(), test_fraction=self.test_fraction.value(),
                              name=folder.name, channel_names=self.channel_names.text().split() or None,
                              head_corrected=self.head_corrected.isChecked())
        return path

    def _accept(self) -> None:
        try:
            self.result_path = self.write_description()
        except FacetrajError as exc:
            QMessageBox.critical(self, "facetraj", str(exc))
            return
        self.accept()


# ---------------------------------------------------------------------- exports
def export_trajectories(window, path: Path, which: str = "synthesized") -> Path:
    """Write the current utterance's ``synthesized`` or ``original`` markers (C3D, TSV or NPZ);
    a TSV or CSV carries the phone and the word of each frame in two more columns."""
    view, model = window.view, window.model
    if view is None:
        raise FacetrajError("no utterance is shown")
    markers = view.shown if which == "synthesized" else view.original
    if markers is None:
        raise FacetrajError(f"{view.utterance.name} has no original markers")
    times = view.times[:len(markers)]
    return write_trajectories(path, markers, model.marker_rate, model.marker_names,
                              view.synthesis.arrays() if view.synthesis is not None else None,
                              which=which, labels=view_frame_labels(view, times))


def export_figure(window, path: Path) -> Path:
    """Save the time-aligned panels as PNG, SVG or PDF (by the suffix): the window's panels drawn
    again as on screen (the same curves, closed lines, speech dots, phones and pins, over the
    time range shown, the cursor where it is), every one of them (also those the window has no
    room for), with a caption naming the utterance, its labels and how it was synthesized, and
    the legend above them."""
    from .screen_export import panels_figure

    suffix = path.suffix.lower().lstrip(".")
    if suffix not in ("png", "svg", "pdf"):
        raise FacetrajError(f"{path}: unknown figure format (use .png, .svg or .pdf)")
    view, tl = window.view, window.timeline
    if view is None:
        raise FacetrajError("no utterance is shown")
    tl.ensure_drawn()      # panels being built finished, a background draw waited for
    size = (max(tl.width(), EXPORT_MIN_WIDTH), int(max(tl.height(), tl.needed_height()) + 160))
    fig, _layout = panels_figure(list(tl.panels), view, size, xlim=tl.xlim(),
                                 cursor=window.current_time(),
                                 caption=window_caption(window))
    with atomic_write(path) as tmp:
        fig.savefig(tmp, format=suffix, dpi=150, facecolor="white")
    return path


def window_caption(window) -> str:
    """The caption of what the window shows: the utterance, how it was synthesized, and the
    pins shown with it by what tells them apart (as the toolbar names them)."""
    from .screen_export import caption_text

    return caption_text(window.view, [text for _pin, text in window.pins.named(window.view)])


def screen_of(window) -> tuple[str, object]:
    """What the window shows, for a video of it: the caption (with the pins, and the time range
    when zoomed) and a ``video.Screen`` (copies of its panels shown, its 3-D scene's options and
    camera, the time range shown)."""
    import copy

    from .video import Screen

    view, tl = window.view, window.timeline
    tl.ensure_drawn()      # panels being built finished: the ones shown are known
    span = tl.xlim()
    caption = window_caption(window)
    if span[0] > 0.0 or span[1] < view.times[-1]:
        caption += f"  ·  {span[0]:.2f}–{span[1]:.2f} s"
    return caption, Screen(tuple(copy.copy(p) for p in tl.shown), window.face.options(),
                           window.face.camera_state(), span)


def export_video(window, path: Path) -> None:
    """Render what the window shows (:func:`screen_of`: its 3-D scene, its panels over the time
    range shown, the sound of that range) to an MP4 in the background, with a progress bar."""
    from .video import render_video

    view, model = window.view, window.model
    if view is None:
        raise FacetrajError("no utterance is shown")
    utt, pins = view.utterance, window.pins
    caption, screen = screen_of(window)

    def work(progress):
        return render_video(model, view.synthesis, utt.audio, utt.sample_rate, path,
                            original=view.original, overwrite=True, progress=progress,
                            title=utt.text or utt.name, phones=utt.phones, view=view, pins=pins,
                            caption=caption, screen=screen)

    window.run_task(work, lambda p: window.show_status(f"wrote {p}"), f"rendering {path.name}")


class OwnData:
    """The File-menu entries to bring one's own recordings in and to export results (an extension:
    it uses only the window contract of ``app/main_window.py``)."""

    ENTRIES = (
        ("&Import your own recordings…", "do_import"),
        ("Export &synthesized trajectories…", "export_synthesized"),
        ("Export &original trajectories…", "export_original"),
        ("Export the panels as a &figure…", "do_figure"),
        ("Save the &model…", "do_model"),
        ("Export a &video…", "do_video"),
    )

    def __init__(self, window):
        self.window = window
        self.actions: dict[str, QAction] = {}
        file_menu = window.menu("File")
        for text, method in self.ENTRIES:
            action = QAction(text, window)
            action.triggered.connect(self._guarded(getattr(self, method)))
            file_menu.insertAction(window.action_screenshot, action)
            self.actions[text.replace("&", "").rstrip("…")] = action

    def _guarded(self, fn):
        """A menu slot: a bad file or an engine error is reported, never raised."""
        def run(*_):
            try:
                fn()
            except (FacetrajError, OSError) as exc:
                self.window.report_error(exc if isinstance(exc, FacetrajError) else FacetrajError(str(exc)))
        return run

    def _wrote(self, path: Path) -> None:
        self.window.show_status(f"wrote {path}")

    def do_import(self, folder: Path | None = None) -> None:
        dlg = ImportDialog(self.window, folder)
        if dlg.exec() == QDialog.DialogCode.Accepted and dlg.result_path:
            self.window.open_corpus(dlg.result_path)

    def export_synthesized(self) -> None:
        self._export_trajectories("synthesized")

    def export_original(self) -> None:
        self._export_trajectories("original")

    def _export_trajectories(self, which: str) -> None:
        w = self.window
        name = w.view.utterance.name if w.view else "trajectories"
        p = ask_save_path(w, f"Export {which} trajectories", f"{name}_{which}.c3d",
                          "C3D (*.c3d);;TSV (*.tsv);;NumPy (*.npz)")
        if p:
            self._wrote(export_trajectories(w, p, which))

    def do_figure(self) -> None:
        p = ask_save_path(self.window, "Export the panels as a figure", "panels.png",
                          "PNG (*.png);;SVG (*.svg);;PDF (*.pdf)")
        if p:
            self._wrote(export_figure(self.window, p))

    def do_model(self) -> None:
        model = self.window.model
        if model is None:
            raise FacetrajError("no model yet")
        p = ask_save_path(self.window, "Save the model", "model.npz", "facetraj model (*.npz)")
        if p:
            model.save(p)
            self._wrote(p)

    def do_video(self) -> None:
        w = self.window
        name = w.view.utterance.name if w.view else "facetraj"
        p = ask_save_path(w, "Export a video", f"{name}.mp4", "MP4 (*.mp4)")
        if p:
            export_video(w, p)


def install(window) -> OwnData:
    """Add the import and export entries to ``window``; also ``window.extension("own_data")``."""
    own = OwnData(window)
    window.add_extension("own_data", own)
    return own
