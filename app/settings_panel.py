"""The synthesis settings side panel (paper section 2.3): N, C, xi, nu, the search mode (robust,
phonetic or acoustic-only, each explained in one line), smoothing, and the robust mode's settings
cross-validated at training. A change is announced once the user pauses (debounced).

The search selector shows the search the synthesis on screen *used* (``show_used``: the labels
may have made the engine choose another than the settings ask for; the line under it says why);
choosing one in it is the user's explicit choice (``searchChosen``), which the labels' rule then
leaves alone."""

from __future__ import annotations

from PyQt6.QtCore import QTimer, pyqtSignal
from PyQt6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from facetraj_engine.config import SynthConfig
from facetraj_engine.method.modes import MODES, SEARCHES, TUNED_FIELDS

from .provenance import MODE_NOTES, mode_reason, search_key

__all__ = ["MODE_NOTES", "SynthSettingsPanel"]

#: the settings the panel has a control for (a model's cross-validated values of these show in
#: their controls, editable; the others apply as they are)
PANEL_FIELDS = ("n_context_phones", "context", "xi", "nu", "smoothing")

class SynthSettingsPanel(QWidget):
    """Edits a :class:`SynthConfig`; emits ``configChanged`` after a short pause in editing."""

    configChanged = pyqtSignal(object)
    searchChosen = pyqtSignal(object)      # the settings with the search the user picked

    def __init__(self, config: SynthConfig | None = None, parent: QWidget | None = None,
                 debounce_ms: int = 300):
        super().__init__(parent)
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(debounce_ms)
        self._timer.timeout.connect(lambda: self.configChanged.emit(self.config()))
        self._base = config or SynthConfig()
        self._requested = search_key(self._base)     # the search the settings ask for
        self._tuned: dict = {}
        self._build_inputs()
        self._build_layout()
        self.set_config(self._base)
        self._connect()

    def _build_inputs(self) -> None:
        self.n = QSpinBox()
        self.n.setRange(1, 50)
        self.n.setToolTip("N: the number of visually most similar context-phones searched (eq 4-5)")
        self.c = QSpinBox()
        self.c.setRange(0, 10)
        self.c.setToolTip("C: phones of context on each side used in eq 4 (at most the trained C)")
        self.xi = QDoubleSpinBox()
        self.xi.setRange(0.0, 1000.0)
        self.xi.setDecimals(1)
        self.xi.setSingleStep(1.0)
        self.xi.setToolTip("ξ: eq 4 constant weighting the centre phone (> 10 lets it dominate)")
        self.nu_default = QCheckBox("model's")
        self.nu = QDoubleSpinBox()
        self.nu.setRange(0.01, 1000.0)
        self.nu.setDecimals(2)
        self.nu.setToolTip("ν: eq 3 constant of the visual phoneme similarity")
        self.mode = QComboBox()
        # short: the line under the box explains the search (the box fits a narrow dock)
        for search in SEARCHES.values():
            self.mode.addItem(search.label, search.key)
        self.mode.setToolTip("\n".join(search.note for search in SEARCHES.values()))
        self.mode_note = QLabel("")
        self.mode_note.setWordWrap(True)
        self.mode_reason = QLabel("")
        self.mode_reason.setWordWrap(True)
        self.mode_reason.setStyleSheet("color: #a34700;")
        self.mode_reason.hide()
        self.tuned_label = QLabel("")
        self.tuned_label.setWordWrap(True)
        self.smoothing = QComboBox()
        for label, value in (("triangular, 100 ms", "triangular"), ("spline", "spline"),
                             ("none", "none")):
            self.smoothing.addItem(label, value)
        self.smoothing.setToolTip("smoothing of the synthesized markers shown in 3-D")
        for combo in (self.mode, self.smoothing):      # the panel fits a narrow left dock
            combo.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
            combo.setMinimumContentsLength(16)
        # the closure step, beyond the paper (issue 46): each part on or off, as the command's
        # --no-closure-labels, --no-rest and --closure-detector
        self.closure_labels = QCheckBox("lips close at /p b m/")
        self.closure_labels.setToolTip(
            "close the lips at the labelled /p b m/, trusting each label as its source says "
            "(--no-closure-labels turns it off; docs/algorithm.md, the closure step)")
        self.rest = QCheckBox("rest in pauses")
        rest = SynthConfig()
        self.rest.setToolTip(
            f"the face rests in silences longer than a stop closure's "
            f"({1000 * rest.rest_pause_s:.0f} ms), at the rest face "
            f"{1000 * (rest.rest_pause_s + rest.rest_taper_s - rest.rest_lookahead_s):.0f} ms "
            f"into them, the one a recording ends in too, and in the one it begins with from its "
            f"first frame (--no-rest turns it off)")
        self.closure_detector = QCheckBox("detector (no labels)")
        self.closure_detector.setToolTip(
            "without phone labels, close the lips where the bilabial-closure detector finds a "
            "closure (--closure-detector). Off by default: on real lips its closures lowered "
            "the lip correlation (issue 46, docs/algorithm.md)")
        self.reset = QPushButton("Paper defaults")

    def _build_layout(self) -> None:
        """The settings in two forms with the search's notes between them, in the panel's own
        column: a form's rows of wrapped text were laid out for a wider panel after the dock
        narrowed (the notes cut to three lines of four, run into the rows around them). Both
        forms' labels are as wide as the widest, so that their fields line up."""
        names = ("N (context-phones)", "C (context)", "ξ (eq 4)", "ν (eq 3)", "search", "smoothing",
                 "closure step")
        width = max(self.fontMetrics().horizontalAdvance(n) for n in names)
        labels = {}
        for n in names:
            labels[n] = QLabel(n)
            labels[n].setMinimumWidth(width)
        top, bottom = QFormLayout(), QFormLayout()
        top.addRow(labels["N (context-phones)"], self.n)
        top.addRow(labels["C (context)"], self.c)
        top.addRow(labels["ξ (eq 4)"], self.xi)
        nu_row = QHBoxLayout()
        nu_row.addWidget(self.nu, 1)
        nu_row.addWidget(self.nu_default)
        top.addRow(labels["ν (eq 3)"], nu_row)
        top.addRow(labels["search"], self.mode)
        bottom.addRow(labels["smoothing"], self.smoothing)
        lips = QVBoxLayout()
        lips.setSpacing(0)
        for box in (self.closure_labels, self.rest, self.closure_detector):
            lips.addWidget(box)
        bottom.addRow(labels["closure step"], lips)
        lay = QVBoxLayout(self)
        self._layout = lay
        lay.addLayout(top)
        lay.addWidget(self.mode_note)
        lay.addWidget(self.mode_reason)
        lay.addLayout(bottom)
        lay.addWidget(self.reset)
        lay.addWidget(self.tuned_label)
        lay.addStretch(1)

    def _connect(self) -> None:
        for w in (self.n, self.c):
            w.valueChanged.connect(self._changed)
        self.xi.valueChanged.connect(self._changed)
        self.nu.valueChanged.connect(self._changed)
        self.nu_default.toggled.connect(self._on_nu_default)
        self.mode.activated.connect(self._search_chosen)      # the user's choice, not set_config's
        self.mode.currentIndexChanged.connect(self._show_mode_note)
        self._show_mode_note()
        self.smoothing.currentIndexChanged.connect(self._changed)
        for box in (self.closure_labels, self.rest, self.closure_detector):
            box.toggled.connect(self._changed)
        self.reset.clicked.connect(lambda: (self.set_config(SynthConfig()), self._changed()))

    def add_widget(self, widget: QWidget) -> None:
        """Add a widget over the settings (the labels box: what the face is synthesized from,
        first; under the robust search's long note it was scrolled out of a laptop's dock)."""
        self._layout.insertWidget(0, widget)

    def _show_mode_note(self, *_args) -> None:
        """The line under the selector explains the search shown; the robust mode's settings
        show with the robust search only."""
        key = self.mode.currentData()
        self.mode_note.setText(MODE_NOTES.get(key, ""))
        self.tuned_label.setVisible(MODES[SEARCHES[key].mode].tuned)

    def _search_chosen(self, index: int) -> None:
        """The user picked a search (also the one shown): that is what the settings ask for now,
        and the labels' rule leaves it alone (``searchChosen``)."""
        self._timer.stop()
        self._requested = self.mode.itemData(index)
        n = self._tuned.get("settings", {}).get("n_context_phones")
        if MODES[SEARCHES[self._requested].mode].tuned and n is not None:
            self.n.blockSignals(True)
            self.n.setValue(int(n))                  # the cross-validated N, still editable
            self.n.blockSignals(False)
        self.mode_reason.hide()
        self.searchChosen.emit(self.config())

    def show_used(self, used: SynthConfig, requested: SynthConfig, reason: str) -> None:
        """Show the search the synthesis on screen used (its ``Synthesis.config``) and, when it
        is not the one ``requested``, why (the engine's ``reason``, ``mode_reason``)."""
        self.mode.blockSignals(True)
        self.mode.setCurrentIndex(max(0, self.mode.findData(search_key(used))))
        self.mode.blockSignals(False)
        self._show_mode_note()
        reason = mode_reason(requested, used, reason)
        self.mode_reason.setText(reason)
        self.mode_reason.setVisible(bool(reason))

    def shown_search(self) -> str:
        """The search the selector shows (``robust``, ``phonetic``, ``acoustic``, ``acoustic-full``)."""
        return self.mode.currentData()

    def set_limits(self, max_context: int, default_nu: float, tuned: dict | None = None) -> None:
        """Fit the controls to a model: C up to its trained context, ν's default, and the robust
        mode's cross-validated settings (``Model.tuned``) shown."""
        self.set_tuned(tuned or {})
        self.c.setMaximum(max_context)
        self._model_nu = default_nu
        if self.nu_default.isChecked():
            self.nu.blockSignals(True)
            self.nu.setValue(default_nu)
            self.nu.blockSignals(False)

    def set_tuned(self, tuned: dict) -> None:
        """Show the model's cross-validated robust-mode settings (or that it has none)."""
        settings = tuned.get("settings") if tuned else None
        self._tuned = tuned or {}
        if not settings:
            self.tuned_label.setText("robust mode: default settings (the model was trained "
                                     "without cross-validation; “facetraj train --tune” "
                                     "tunes them)")
            return
        names = {"n_context_phones": "N", "xi": "ξ", "label_weight": "κ (label weight)",
                 "context_weight": "ρ (context weight)", "gamma_max": "γ max",
                 "robust_candidates": "acoustic candidates",
                 "triangle_s": "smoothing (s)"}
        text = ", ".join(f"{names.get(k, k)} = {v:g}" for k, v in settings.items())
        self.tuned_label.setText(f"robust mode, cross-validated on the training split "
                                 f"({tuned.get('folds', '?')} folds): {text}")

    def set_config(self, cfg: SynthConfig) -> None:
        """Show ``cfg`` without emitting a change."""
        self._base = cfg
        widgets = (self.n, self.c, self.xi, self.nu, self.nu_default, self.mode, self.smoothing,
                   self.closure_labels, self.rest, self.closure_detector)
        for w in widgets:
            w.blockSignals(True)
        self.n.setValue(cfg.n_context_phones)
        self.c.setValue(cfg.context)
        self.xi.setValue(cfg.xi)
        self.nu_default.setChecked(cfg.nu is None)
        self.nu.setEnabled(cfg.nu is not None)
        if cfg.nu is not None:
            self.nu.setValue(cfg.nu)
        self._requested = search_key(cfg)
        self.mode.setCurrentIndex(max(0, self.mode.findData(self._requested)))
        self.smoothing.setCurrentIndex(max(0, self.smoothing.findData(cfg.smoothing)))
        self.closure_labels.setChecked(cfg.closure and cfg.closure_labels)
        self.rest.setChecked(cfg.closure and cfg.rest)
        self.closure_detector.setChecked(cfg.closure and cfg.closure_detector)
        for w in widgets:
            w.blockSignals(False)
        self._show_mode_note()

    def config(self) -> SynthConfig:
        """The settings as edited, with the search they ask for (not necessarily the one shown:
        see ``show_used``)."""
        search = SEARCHES[self._requested]
        default, changes = SynthConfig(), {}
        for other in SEARCHES.values():      # back from another search's settings: the defaults
            changes.update({k: getattr(default, k) for k, v in other.settings.items()
                            if getattr(self._base, k) == v})
        changes.update(search.settings)
        if MODES[search.mode].tuned:   # the cross-validated settings the panel has no control for
            changes.update({k: v for k, v in self._tuned.get("settings", {}).items()
                            if k in TUNED_FIELDS and k not in PANEL_FIELDS})
        return self._base.with_(
            n_context_phones=self.n.value(), context=self.c.value(), xi=self.xi.value(),
            nu=None if self.nu_default.isChecked() else self.nu.value(), mode=search.mode,
            smoothing=self.smoothing.currentData(), **changes, **self._closure_parts())

    def _closure_parts(self) -> dict:
        """The closure step's parts as the boxes say; the step is off when every part is."""
        parts = {"closure_labels": self.closure_labels.isChecked(), "rest": self.rest.isChecked(),
                 "closure_detector": self.closure_detector.isChecked()}
        return {"closure": any(parts.values()), **parts}

    def _on_nu_default(self, checked: bool) -> None:
        self.nu.setEnabled(not checked)
        self._changed()

    def _changed(self, *_args) -> None:
        self._timer.start()
