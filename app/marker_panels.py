"""Time-aligned panels of single marker coordinates (e.g. the jaw of midsagittal EMA data).

:class:`MarkerPanels` keeps the panels the user added (View menu) and, for a planar model
(:attr:`facetraj_engine.method.model.Model.is_planar`: midsagittal 2-D data) or articulograph sensors
(:attr:`facetraj_engine.method.model.Model.roles`), puts the jaw beside the lips.
"""

from __future__ import annotations

from PyQt6.QtWidgets import QComboBox, QDialog, QDialogButtonBox, QFormLayout, QWidget

from facetraj_engine.errors import FacetrajError
from facetraj_engine.method.model import Model

from .style import ORIGINAL_COLOR, SPLINE_COLOR, TRIANGULAR_COLOR, fit_ylabel
from .timeline import Timeline

#: a face's chin markers, the jaw's stand-in where no sensor is the jaw's
CHIN_NAMES = ("JAW_C", "CN_C", "CHIN", "CN")


class MarkerPanel:
    """A time-aligned panel of one marker coordinate: original (dashed) and the triangular and
    spline syntheses, like the lip panels (e.g. the jaw of MOCHA-TIMIT's lower incisor coil)."""

    height = 1.0

    def __init__(self, marker: str, axis: str = "y"):
        self.marker = marker
        self.axis = axis
        self.title = f"{marker} {axis}"

    def draw(self, ax, view) -> None:
        names = view.utterance.marker_names or []
        if self.marker not in names:
            ax.text(0.5, 0.5, f"no marker {self.marker}", transform=ax.transAxes, ha="center")
            return
        k, a = names.index(self.marker), "xyz".index(self.axis)
        t = view.times
        ax.plot(t, view.triangular[:, k, a], color=TRIANGULAR_COLOR, lw=1.6,
                label="synthesized, triangular")
        ax.plot(t, view.spline[:, k, a], color=SPLINE_COLOR, lw=1.3, label="synthesized, spline")
        if view.original is not None:
            ax.plot(t, view.original[:, k, a], color=ORIGINAL_COLOR, lw=1.5, ls=(0, (2, 1.5)),
                    label="original")
        fit_ylabel(ax, f"{self.marker}\n{self.axis} (mm)")

def jaw_marker(model: Model) -> str | None:
    """The jaw marker of ``model`` (its jaw sensor, e.g. MOCHA's lower incisor LI: ``roles.jaw``,
    else a chin marker), if any."""
    roles = model.roles
    if roles.jaw:
        return roles.names[roles.jaw[0]]
    upper = [n.upper() for n in roles.names]
    return next((roles.names[upper.index(c)] for c in CHIN_NAMES if c in upper), None)

class MarkerPanelDialog(QDialog):
    """Choose a marker and an axis for a new time-aligned panel."""

    def __init__(self, model: Model, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("Add a marker trajectory panel")
        form = QFormLayout(self)
        self.marker = QComboBox()
        self.marker.addItems(list(model.marker_names))
        jaw = jaw_marker(model)
        if jaw:
            self.marker.setCurrentText(jaw)
        self.axis = QComboBox()
        self.axis.addItems(["y (up)", "z (forward)", "x (right)"])
        form.addRow("Marker", self.marker)
        form.addRow("Coordinate", self.axis)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                   | QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def panel(self) -> MarkerPanel:
        return MarkerPanel(self.marker.currentText(), self.axis.currentText()[0])



class MarkerPanels:
    """The marker panels shown on one timeline."""

    def __init__(self, timeline: Timeline):
        self.timeline = timeline
        self.panels: list[MarkerPanel] = []

    def __len__(self) -> int:
        return len(self.panels)

    def __getitem__(self, i: int) -> MarkerPanel:
        return self.panels[i]

    def add(self, panel: MarkerPanel) -> None:
        self.panels.append(panel)
        self.timeline.add_panel(panel)

    def clear(self) -> None:
        for panel in self.panels:
            self.timeline.remove_panel(panel)
        self.panels.clear()

    def ask(self, model: Model | None, parent: QWidget | None = None) -> None:
        """Let the user choose a marker and a coordinate; add that panel."""
        if model is None:
            raise FacetrajError("no model yet")
        dlg = MarkerPanelDialog(model, parent)
        if dlg.exec() == QDialog.DialogCode.Accepted:
            self.add(dlg.panel())

    def set_model(self, model: Model) -> None:
        """A new model: no panels, except the jaw's for midsagittal (planar) data and
        articulograph sensors (more, e.g. the tongue tip's height: View > Add a marker
        trajectory panel; each panel takes height from the articulator view)."""
        self.clear()
        roles = model.roles
        if model.is_planar or roles.articulograph:
            jaw = jaw_marker(model)             # midsagittal EMA: the jaw beside the lips
            if jaw:
                self.add(MarkerPanel(jaw, "y"))

