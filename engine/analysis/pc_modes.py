"""The PC mode explorer's numbers (the paper's Figure 2): how each principal component moves the
face, its standard deviation and share of the variance, and which markers it moves most."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..method.model import Model
from .apertures import aperture


def mode_sd(model: Model) -> np.ndarray:
    """Standard deviation of each PC's coefficient, ``(K,)`` (the slider spans +-3 of these)."""
    return np.sqrt(np.asarray(model.pca.variances, dtype=np.float64))


def variance_shares(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Share of the total variance of each PC and the cumulative share, both ``(K,)`` in %.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> m = SimpleNamespace(pca=SimpleNamespace(explained_ratio=np.array([0.5, 0.3, 0.1])))
    >>> [a.round(1).tolist() for a in variance_shares(m)]
    [[50.0, 30.0, 10.0], [50.0, 80.0, 90.0]]
    """
    share = 100.0 * np.asarray(model.pca.explained_ratio, dtype=np.float64)
    return share, np.cumsum(share)


def mode_displacement(model: Model, component: int, value: float) -> np.ndarray:
    """Displacement of every marker from the neutral face when PC ``component`` is ``value``:
    ``value`` times the eigenvector, ``(M, 3)`` mm."""
    return model.mode_shape(component, value) - model.neutral_face()


def mode_aperture(model: Model, component: int, sds: np.ndarray) -> np.ndarray:
    """The lip aperture (mm: upper to lower lip centre marker) of the face with PC ``component``
    at each of ``sds`` standard deviations: which way of the slider opens the mouth, and where it
    passes the talker's closed aperture (``facetraj_engine.analysis.lips.closed_lips``)."""
    sd = float(mode_sd(model)[component])
    faces = np.stack([model.mode_shape(component, float(s) * sd) for s in np.atleast_1d(sds)])
    return aperture(faces, model.upper_lip, model.lower_lip)


def opening_direction(apertures_at_minus_plus: tuple[float, float], least_mm: float = 1.0) -> int:
    """+1 when the mode opens the mouth towards +SD (the aperture grows by ``least_mm`` or more),
    -1 towards -SD, 0 when it hardly changes the aperture.

    >>> opening_direction((8.0, 30.0)), opening_direction((20.0, 12.0)), opening_direction((15.0, 15.4))
    (1, -1, 0)
    """
    lo, hi = apertures_at_minus_plus
    return 0 if abs(hi - lo) < least_mm else (1 if hi > lo else -1)


@dataclass
class ModeSummary:
    """How one PC moves the face."""

    component: int
    variance_share: float
    sd: float
    markers: list[tuple[str, float]]   # the markers it moves most, with their share of the motion
    axis: str                          # the dominant direction: "vertical", "lateral", "forward"

    def text(self) -> str:
        names = ", ".join(n for n, _ in self.markers)
        return (f"PC{self.component + 1}: {100 * self.variance_share:.1f} % of the variance, "
                f"mostly {self.axis} motion of {names}")


def describe_mode(model: Model, component: int, count: int = 4) -> ModeSummary:
    """Which markers PC ``component`` moves most and in which direction (x lateral, y vertical,
    z forward); PC1 of a talking face should be the jaw: chin and lower lip, vertical."""
    vec = np.asarray(model.pca.components[component]).reshape(-1, 3)
    mag = np.linalg.norm(vec, axis=1)
    share = mag**2 / max(float((mag**2).sum()), 1e-12)
    top = np.argsort(-mag)[:count]
    axis_energy = (vec**2).sum(axis=0)
    axis = ("lateral", "vertical", "forward")[int(np.argmax(axis_energy))]
    return ModeSummary(component, float(model.pca.explained_ratio[component]),
                       float(mode_sd(model)[component]),
                       [(model.marker_names[i], float(share[i])) for i in top], axis)


__all__ = ["ModeSummary", "describe_mode", "mode_aperture", "mode_displacement", "mode_sd",
           "opening_direction", "variance_shares"]
