"""The visual phoneme similarity matrix (paper eqs 1-3, Table 1).

Three tabs over one nu: the K x K matrix as a sortable table with heat-coloured cells (phones in
hierarchical clustering order, so visemes group), the top-3 list in the layout of Table 1, and a
heat map with the dendrogram. Export CSV (the matrix) and PNG (the heat map).
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
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

from engine.analysis.similarity import (
    cluster_phones,
    dendrogram,
    similarity_in_order,
    write_similarity_csv,
)
from engine.evaluation.paper import paper_table1
from engine.method.model import Model
from engine.method.similarity import top_similar

from .common import Canvas, export_with_dialog, fill_table, heat_item, text_item

log = logging.getLogger(__name__)


class SimilarityView(QWidget):
    """The similarity matrix, Table 1 and the heat map with dendrogram for one model."""

    nuChanged = pyqtSignal(float)

    def __init__(self, model: Model, window=None, parent: QWidget | None = None):
        super().__init__(parent)
        self.model = model
        self.window_ = window
        self.clustering = cluster_phones(model)
        self.matrix = np.zeros((0, 0))
        self.table1 = []

        self.nu = QDoubleSpinBox()
        self.nu.setRange(0.1, 100.0)
        self.nu.setDecimals(1)
        self.nu.setSingleStep(0.5)
        self.nu.setValue(float(model.config.nu))
        self.nu.setToolTip("eq 3: S = exp(-nu D / scale)")
        self.nu.valueChanged.connect(self.refresh)
        csv_btn = QPushButton("Export CSV…")
        csv_btn.clicked.connect(self._export_csv)
        png_btn = QPushButton("Export PNG…")
        png_btn.clicked.connect(self._export_png)
        top = QHBoxLayout()
        top.addWidget(QLabel("nu (eq 3):"))
        top.addWidget(self.nu)
        top.addStretch(1)
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
        self.refresh()

    # ------------------------------------------------------------------ content
    @property
    def labels(self) -> list[str]:
        return self.clustering.labels

    def refresh(self) -> None:
        nu = float(self.nu.value())
        self.matrix = similarity_in_order(self.model, nu, self.clustering.order)
        self._fill_matrix()
        self.table1 = top_similar(self.model.similarity(nu), self.model.phones, 3)
        self._fill_table1()
        self._draw_heatmap()
        self.nuChanged.emit(nu)

    def _fill_matrix(self) -> None:
        labels = self.labels
        rows = [[text_item(p)] + [heat_item(float(v), 0.0, 1.0) for v in self.matrix[i]]
                for i, p in enumerate(labels)]
        fill_table(self.table, ["phone", *labels], rows)
        self.table.verticalHeader().setVisible(False)

    def _fill_table1(self) -> None:
        heads = ["Phoneme", "Closest", "S", "2nd", "S", "3rd", "S", "paper's top 3 (nu = 10)"]
        paper = paper_table1()
        rows = []
        for r in self.table1:
            row = [text_item(r.phone)]
            for p, v in r.neighbours:
                row += [text_item(p), heat_item(v, 0.0, 1.0)]
            ref = paper.get(r.phone)
            row.append(text_item("  ".join(f"{p} {v:.2f}" for p, v in ref) if ref else "-"))
            rows.append(row)
        fill_table(self.table1_table, heads, rows)
        self.table1_table.verticalHeader().setVisible(False)

    def _draw_heatmap(self) -> None:
        fig = self.canvas.figure
        fig.clear()
        labels = self.labels
        k = len(labels)
        gs = fig.add_gridspec(2, 2, height_ratios=[1, 5], width_ratios=[30, 1], hspace=0.02,
                              wspace=0.03, left=0.08, right=0.93, top=0.97, bottom=0.08)
        ax_d = fig.add_subplot(gs[0, 0])
        ax = fig.add_subplot(gs[1, 0])
        cax = fig.add_subplot(gs[1, 1])
        im = ax.imshow(self.matrix, cmap="YlOrRd", vmin=0, vmax=1, interpolation="nearest",
                       aspect="auto")
        ax.set_xticks(range(k), labels, rotation=90, fontsize=7)
        ax.set_yticks(range(k), labels, fontsize=7)
        fig.colorbar(im, cax=cax, label=f"similarity S (nu = {self.nu.value():g})")
        dg = dendrogram(self.clustering)
        for xs, ys in zip(dg.icoord, dg.dcoord, strict=True):
            # leaf j of the dendrogram sits at x = 10 j + 5; the heat map's column j at x = j
            ax_d.plot((np.asarray(xs) - 5) / 10, ys, color="#555555", lw=0.8)
        ax_d.set_xlim(-0.5, k - 0.5)
        ax_d.set_xticks([])
        ax_d.set_ylabel("D (eq 2)", fontsize=7)
        ax_d.tick_params(labelsize=6)
        for s in ("top", "right"):
            ax_d.spines[s].set_visible(False)
        self.canvas.draw_idle()

    # ------------------------------------------------------------------ export
    def export_csv(self, path: str | Path) -> Path:
        return write_similarity_csv(path, self.model, float(self.nu.value()), self.clustering.order)

    def export_png(self, path: str | Path) -> Path:
        self.canvas.draw()
        return self.canvas.save_png(path)

    def _export_csv(self) -> None:
        export_with_dialog(self, "Export similarity matrix", "similarity.csv", "CSV (*.csv)",
                           self.export_csv)

    def _export_png(self) -> None:
        export_with_dialog(self, "Export heat map", "similarity.png", "PNG image (*.png)",
                           self.export_png)
