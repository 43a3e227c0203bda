"""The visual phoneme similarity matrix (paper eqs 1-3, Table 1).

Three tabs over one nu: the K x K matrix as a sortable table with heat-coloured cells (phones in
hierarchical clustering order, so visemes group), the top-3 list in the layout of Table 1, and a
heat map with the dendrogram. Export CSV (the matrix) and PNG (the heat map).

The clustering (and scipy's clustering module, 0.5-1.7 s to import) is computed in the background
when the view opens; the view says so until it is there (``ready``).
"""

from __future__ import annotations

import logging
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure
from PyQt6.QtCore import pyqtSignal
from PyQt6.QtWidgets import (
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QTableWidget,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.evaluation.paper import paper_table1
from facetraj_engine.method.model import Model
from facetraj_engine.method.similarity import top_similar

from .common import (
    Canvas,
    export_with_dialog,
    fill_table,
    heat_items,
    stop_own_tasks,
    task_runner,
    text_item,
)

if TYPE_CHECKING:
    from facetraj_engine.analysis.similarity import Dendrogram, PhoneClustering

log = logging.getLogger(__name__)


def clustering_of(model: Model) -> tuple[PhoneClustering, Dendrogram]:
    """The phones' clustering and its dendrogram (slow the first time: scipy's clustering is
    imported; run in a worker)."""
    from facetraj_engine.analysis.similarity import cluster_phones, dendrogram

    clustering = cluster_phones(model)
    return clustering, dendrogram(clustering)


def draw_heatmap(fig: Figure, matrix: np.ndarray, labels: list[str], tree: Dendrogram,
                 nu: float) -> None:
    """The similarity matrix as a heat map under its dendrogram (run in the drawing thread:
    ``BackgroundCanvas.rebuild``)."""
    fig.clear()
    k = len(labels)
    gs = fig.add_gridspec(2, 2, height_ratios=[1, 5], width_ratios=[30, 1], hspace=0.02,
                          wspace=0.03, left=0.08, right=0.93, top=0.97, bottom=0.08)
    ax_d = fig.add_subplot(gs[0, 0])
    ax = fig.add_subplot(gs[1, 0])
    cax = fig.add_subplot(gs[1, 1])
    im = ax.imshow(matrix, cmap="YlOrRd", vmin=0, vmax=1, interpolation="nearest", aspect="auto")
    ax.set_xticks(range(k), labels, rotation=90, fontsize=7)
    ax.set_yticks(range(k), labels, fontsize=7)
    fig.colorbar(im, cax=cax, label=f"similarity S (ν = {nu:g})")
    for xs, ys in zip(tree.icoord, tree.dcoord, strict=True):
        # leaf j of the dendrogram sits at x = 10 j + 5; the heat map's column j at x = j
        ax_d.plot((np.asarray(xs) - 5) / 10, ys, color="#555555", lw=0.8)
    ax_d.set_xlim(-0.5, k - 0.5)
    ax_d.set_xticks([])
    ax_d.set_ylabel("D (eq 2)", fontsize=7)
    ax_d.tick_params(labelsize=6)
    for side in ("top", "right"):
        ax_d.spines[side].set_visible(False)


class SimilarityView(QWidget):
    """The similarity matrix, Table 1 and the heat map with dendrogram for one model."""

    nuChanged = pyqtSignal(float)
    ready = pyqtSignal()

    def __init__(self, model: Model, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.model = model
        self.window_ = window
        self.clustering: PhoneClustering | None = None
        self.tree: Dendrogram | None = None
        self.matrix = np.zeros((0, 0))
        self.table1 = []

        self.nu = QDoubleSpinBox()
        self.nu.setRange(0.1, 100.0)
        self.nu.setDecimals(1)
        self.nu.setSingleStep(0.5)
        self.nu.setValue(float(model.config.nu))
        self.nu.setToolTip("eq 3: S = exp(-nu D / scale)")
        self.nu.setEnabled(False)
        self.nu.valueChanged.connect(self.refresh)
        self.csv_button = csv_btn = QPushButton("Export CSV…")
        csv_btn.clicked.connect(self._export_csv)
        self.png_button = png_btn = QPushButton("Export PNG…")
        png_btn.clicked.connect(self._export_png)
        for b in (csv_btn, png_btn):
            b.setEnabled(False)                 # until the clustering is there
        self.status = QLabel("clustering the phones (eq 2 distances) …")
        top = QHBoxLayout()
        top.addWidget(QLabel("ν (eq 3):"))
        top.addWidget(self.nu)
        top.addWidget(self.status, 1)
        top.addWidget(csv_btn)
        top.addWidget(png_btn)

        self.table = QTableWidget()
        self.table.setSortingEnabled(True)
        self.table1_table = QTableWidget()
        self.table1_table.setSortingEnabled(True)
        self.canvas = Canvas(7, 7)
        self.tabs = QTabWidget()
        self.tabs.addTab(self.table, "Matrix")
        self.tabs.addTab(self.table1_table, "Top 3 (Table 1)")
        self.tabs.addTab(self.canvas, "Heat map")
        lay = QVBoxLayout(self)
        lay.addLayout(top)
        lay.addWidget(self.tabs)
        self.tasks = task_runner(self, window)
        self.tasks.run(lambda _p: clustering_of(model), self._clustered, "clustering the phones")

    def _clustered(self, result: tuple[PhoneClustering, Dendrogram]) -> None:
        self.clustering, self.tree = result
        self.status.setText("")
        for w in (self.nu, self.csv_button, self.png_button):
            w.setEnabled(True)
        self.refresh()
        self.ready.emit()

    # ------------------------------------------------------------------ content
    @property
    def labels(self) -> list[str]:
        return self.clustering.labels if self.clustering is not None else []

    def refresh(self) -> None:
        if self.clustering is None:
            return
        from facetraj_engine.analysis.similarity import similarity_in_order

        nu = float(self.nu.value())
        self.matrix = similarity_in_order(self.model, nu, self.clustering.order)
        self._fill_matrix()
        self.table1 = top_similar(self.model.similarity(nu), self.model.phones, 3)
        self._fill_table1()
        self.canvas.rebuild(partial(draw_heatmap, matrix=self.matrix, labels=list(self.labels),
                                    tree=self.tree, nu=nu))
        self.nuChanged.emit(nu)

    def _fill_matrix(self) -> None:
        labels = self.labels
        cells = heat_items(self.matrix, 0.0, 1.0)
        rows = [[text_item(p)] + cells[i] for i, p in enumerate(labels)]
        fill_table(self.table, ["phone", *labels], rows)
        self.table.verticalHeader().setVisible(False)

    def _fill_table1(self) -> None:
        heads = ["Phoneme", "Closest", "S", "2nd", "S", "3rd", "S", "paper's top 3 (ν = 10)"]
        paper = paper_table1()
        rows = []
        for r in self.table1:
            row = [text_item(r.phone)]
            cells = heat_items(np.array([[v for _p, v in r.neighbours]]), 0.0, 1.0)[0]
            for (p, _v), cell in zip(r.neighbours, cells, strict=True):
                row += [text_item(p), cell]
            ref = paper.get(r.phone)
            row.append(text_item("  ".join(f"{p} {v:.2f}" for p, v in ref) if ref else "-"))
            rows.append(row)
        fill_table(self.table1_table, heads, rows)
        self.table1_table.verticalHeader().setVisible(False)

    def closeEvent(self, event) -> None:
        stop_own_tasks(self, self.tasks)
        super().closeEvent(event)

    # ------------------------------------------------------------------ export
    def export_csv(self, path: str | Path) -> Path:
        from facetraj_engine.analysis.similarity import write_similarity_csv

        if self.clustering is None:
            raise ValueError("the phones are still being clustered")
        return write_similarity_csv(path, self.model, float(self.nu.value()), self.clustering.order)

    def export_png(self, path: str | Path) -> Path:
        if self.clustering is None:
            raise ValueError("the phones are still being clustered")
        return self.canvas.save_png(path)

    def _export_csv(self) -> None:
        export_with_dialog(self, "Export similarity matrix", "similarity.csv", "CSV (*.csv)",
                           self.export_csv)

    def _export_png(self) -> None:
        export_with_dialog(self, "Export heat map", "similarity.png", "PNG image (*.png)",
                           self.export_png)
