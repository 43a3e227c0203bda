"""The articulators of articulograph data, as the app draws and measures them: the tongue as a
smooth curve through its sensors (tip to rear), and at the cursor the tongue tip's height, the
lip aperture and the jaw opening (the Measure readout of an articulograph model).

* :func:`tongue_curve`: a centripetal Catmull-Rom curve through the tongue sensors, in order
  (it passes through every sensor and does not overshoot between unevenly spaced ones); the
  sensors' positions only, nothing extrapolated past the tip or the rearmost sensor.
* **tongue tip height**: the tip sensor's y (mm, the recording's head frame, y up).
* **lip aperture**: upper to lower lip sensor (:func:`facetraj_engine.analysis.apertures.aperture`).
* **jaw opening**: how far (mm) the jaw sensor (the lower incisor) is below the talker's highest
  jaw position, the 95th percentile of its height over the model's codewords
  (:func:`jaw_top`): about 0 with the teeth together, larger as the jaw lowers.

The sensors' roles come from :attr:`facetraj_engine.method.model.Model.roles`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..data import PhoneSegment
from ..io.sensor_roles import SensorRoles
from ..method.model import Model
from .apertures import aperture, label_at

NAN = float("nan")
#: the share of the codewords whose jaw is lower than the talker's "highest" jaw position
JAW_TOP_PERCENTILE = 95.0
#: curve points between two tongue sensors
CURVE_STEPS = 12


def tongue_curve(points: np.ndarray, steps: int = CURVE_STEPS) -> np.ndarray:
    """Points of a smooth curve through ``points`` ``(k, 3)`` in order (centripetal
    Catmull-Rom, the ends' tangents by reflection): ``(steps * (k - 1) + 1, 3)``, passing through
    every one of them; two points give their segment, one point itself.

    >>> p = np.array([[0.0, 0, 0], [0, 10, 10], [0, 0, 20]])
    >>> c = tongue_curve(p, 4)
    >>> c.shape, c[0].tolist(), c[4].tolist(), c[-1].tolist()
    ((9, 3), [0.0, 0.0, 0.0], [0.0, 10.0, 10.0], [0.0, 0.0, 20.0])
    >>> bool(c[:, 1].max() <= 10.5)                  # no overshoot above the middle sensor
    True
    """
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 2:
        return p.copy()
    if len(p) == 2:
        return p[0] + np.linspace(0, 1, steps + 1)[:, None] * (p[1] - p[0])
    ext = np.vstack([2 * p[0] - p[1], p, 2 * p[-1] - p[-2]])
    knots = np.concatenate([[0.0], np.cumsum(np.sqrt(np.maximum(
        np.linalg.norm(np.diff(ext, axis=0), axis=1), 1e-9)))])
    out = [p[:1]]
    u = np.linspace(0, 1, steps + 1)[1:, None]
    for i in range(1, len(ext) - 2):
        t0, t1, t2, t3 = knots[i - 1:i + 3]
        t = t1 + u * (t2 - t1)
        a1 = ((t1 - t) * ext[i - 1] + (t - t0) * ext[i]) / (t1 - t0)
        a2 = ((t2 - t) * ext[i] + (t - t1) * ext[i + 1]) / (t2 - t1)
        a3 = ((t3 - t) * ext[i + 1] + (t - t2) * ext[i + 2]) / (t3 - t2)
        b1 = ((t2 - t) * a1 + (t - t0) * a2) / (t2 - t0)
        b2 = ((t3 - t) * a2 + (t - t1) * a3) / (t3 - t1)
        seg = ((t2 - t) * b1 + (t - t1) * b2) / (t2 - t1)
        seg[-1] = ext[i + 1]                 # exactly through the sensor (not to rounding)
        out.append(seg)
    return np.vstack(out)


def jaw_top(model: Model) -> float:
    """The talker's highest jaw position (mm, y): the :data:`JAW_TOP_PERCENTILE` percentile of the
    jaw sensor's height over the model's codewords; NaN without a jaw sensor."""
    roles = model.roles
    if not roles.jaw:
        return NAN
    faces = model.to_markers(model.codebook.pcs)
    return float(np.percentile(faces[:, roles.jaw[0], 1], JAW_TOP_PERCENTILE))


@dataclass(frozen=True)
class Articulators:
    """Tongue tip height, lip aperture and jaw opening (mm) of one frame; NaN for an articulator
    the set does not have."""

    tongue_tip: float
    aperture: float
    jaw_opening: float


def measure(markers: np.ndarray, roles: SensorRoles, top: float) -> Articulators:
    """The :class:`Articulators` of one frame's markers ``(M, 3)`` (``top``: :func:`jaw_top`).

    >>> from facetraj_engine.io.sensor_roles import sensor_roles
    >>> r = sensor_roles(["TT", "UL", "LL", "JAW"], 1, 2)
    >>> m = np.array([[0, 5.0, 50], [0, 10, 80], [0, -2, 78], [0, -15, 70]])
    >>> a = measure(m, r, -12.0); (a.tongue_tip, round(a.aperture, 2), a.jaw_opening)
    (5.0, 12.17, 3.0)
    """
    m = np.asarray(markers, dtype=np.float64)
    tip = float(m[roles.tongue[0], 1]) if roles.tongue else NAN
    jaw = top - float(m[roles.jaw[0], 1]) if roles.jaw else NAN
    return Articulators(tip, float(aperture(m[None], roles.upper_lip, roles.lower_lip)[0]), jaw)


@dataclass(frozen=True)
class ArticulatorReadout:
    """The articulators at one time: the synthesis's, the original's (None without one), and
    the phone and word there."""

    time: float
    frame: int
    phone: str
    word: str
    synthesized: Articulators
    original: Articulators | None = None


def readout_at(t: float, times: np.ndarray, synthesized: np.ndarray, roles: SensorRoles, top: float,
               original: np.ndarray | None = None, phones: Sequence[PhoneSegment] = (),
               words: Sequence[PhoneSegment] = ()) -> ArticulatorReadout:
    """The :class:`ArticulatorReadout` at ``t`` seconds: the frame nearest ``t`` of
    ``synthesized`` (and ``original``) ``(T, M, 3)`` with frame times ``times``."""
    times = np.asarray(times, dtype=np.float64)
    k = int(np.clip(np.argmin(np.abs(times - t)), 0, len(times) - 1)) if len(times) else 0
    org = None
    if original is not None and k < len(original):
        org = measure(original[k], roles, top)
    return ArticulatorReadout(float(t), k, label_at(phones, t), label_at(words, t),
                              measure(synthesized[k], roles, top), org)


__all__ = ["ArticulatorReadout", "Articulators", "jaw_top", "measure", "readout_at", "tongue_curve"]
