"""A 54-marker face driven by VocalTractLab's articulators.

Coordinates are mm, x to the right as the face is seen from the front (the talker's left), y up,
z forward; the origin is the meeting point of the lips at rest. Marker names end in ``_R`` for the
talker's right side (x < 0) and ``_L`` for the talker's left side (x > 0).

The rig (all displacements from the rest face):

* jaw: rotation about the condyle axis (the line through both condyles, parallel to x) by the
  VTL jaw angle ``JA`` (relative to the rest posture, times ``jaw_gain``), with a small forward
  glide of the condyles as the jaw opens, plus VTL's forward shift ``JX``. Chin,
  jaw line and labiomental markers move rigidly with it, the cheeks in part (weights by height);
* upper lip: the VTL EMA point ``UL`` (vertical and forward motion);
* lower lip: its centre sits ``LD`` (VTL's lip distance) below the upper lip; it is the jaw-carried
  position plus the lip's own motion (the difference), which the lateral lower-lip points share;
* lip corners: drawn in by protrusion ``LP`` (rounding), spread for negative ``LP``, slightly in
  and down with the opening ``LD``; the lateral lip points blend centre and corner motion;
* rest: over pauses longer than ``rest_min_pause`` and at the start and end of each utterance the
  articulator tracks are blended (raised-cosine ramps) into a rest posture with closed lips and a
  settled jaw (VTL's own pause posture keeps the lips about 9 mm apart);
* a small smooth rigid head motion, white marker noise and rare short dropouts (NaN).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .vtl import EMA_RATE, TRACT_RATE, VtlOutput

# --------------------------------------------------------------------------- the marker set
_HALF = {  # name stem -> rest position of the talker's LEFT marker (x > 0); mirrored for _R
    "FH2": (45.0, 95.0, -25.0), "FH1": (22.0, 100.0, -12.0), "TMP": (62.0, 70.0, -55.0),
    "NS": (16.0, 24.0, 6.0),
    "CH1": (40.0, 45.0, -12.0), "CH2": (48.0, 20.0, -20.0), "CH3": (35.0, 5.0, -8.0),
    "CH4": (55.0, -5.0, -32.0), "NL": (25.0, 14.0, 0.0),
    "ULO": (12.0, 11.0, 2.0), "UL1": (9.0, 4.5, 3.5), "UL2": (18.0, 2.5, -2.0),
    "LC": (25.0, 0.0, -8.0),
    "LL1": (9.0, -5.5, 3.0), "LL2": (18.0, -3.5, -2.5), "LLO": (14.0, -15.0, -5.0),
    "CN": (16.0, -30.0, -4.0),
    "JL1": (30.0, -35.0, -18.0), "JL2": (45.0, -28.0, -35.0), "JL3": (55.0, -15.0, -55.0),
    "JL4": (60.0, 5.0, -75.0),
}
_MID = {  # midline markers
    "FH_C": (0.0, 102.0, -9.0), "NB_U": (0.0, 70.0, -6.0), "NB_M": (0.0, 55.0, 4.0),
    "NB_L": (0.0, 42.0, 12.0), "NS_TIP": (0.0, 30.0, 20.0), "NS_BASE": (0.0, 18.0, 6.0),
    "ULO_C": (0.0, 12.0, 5.0), "UL_C": (0.0, 5.0, 5.0), "LL_C": (0.0, -6.0, 4.0),
    "LLO_C": (0.0, -17.0, -2.0), "CN_C": (0.0, -33.0, 2.0), "CN_B": (0.0, -45.0, -12.0),
}
_ORDER = [
    "FH2_R", "FH1_R", "FH_C", "FH1_L", "FH2_L", "TMP_R", "TMP_L", "NB_U", "NB_M", "NB_L",
    "NS_TIP", "NS_R", "NS_L", "NS_BASE",
    "CH1_R", "CH2_R", "CH3_R", "CH4_R", "CH1_L", "CH2_L", "CH3_L", "CH4_L", "NL_R", "NL_L",
    "ULO_R", "ULO_C", "ULO_L", "UL2_R", "UL1_R", "UL_C", "UL1_L", "UL2_L", "LC_R", "LC_L",
    "LL2_R", "LL1_R", "LL_C", "LL1_L", "LL2_L", "LLO_R", "LLO_C", "LLO_L",
    "CN_R", "CN_C", "CN_L", "CN_B",
    "JL1_R", "JL2_R", "JL3_R", "JL4_R", "JL1_L", "JL2_L", "JL3_L", "JL4_L",
]


def _rest_position(name: str) -> tuple[float, float, float]:
    if name in _MID:
        return _MID[name]
    stem, side = name.rsplit("_", 1)
    x, y, z = _HALF[stem]
    return (x if side == "L" else -x, y, z)


MARKER_NAMES: list[str] = list(_ORDER)
REST_FACE: np.ndarray = np.array([_rest_position(n) for n in MARKER_NAMES])
FIXED_MARKERS: list[str] = ["FH2_R", "FH1_R", "FH_C", "FH1_L", "FH2_L", "TMP_R", "TMP_L",
                            "NB_U", "NB_M", "NB_L"]
UPPER_LIP, LOWER_LIP = "UL_C", "LL_C"
LIP_CORNERS = ["LC_R", "LC_L"]

#: marker groups (for the documentation, the figure and the tests)
GROUPS: dict[str, list[str]] = {
    "forehead & nose bridge (fixed)": FIXED_MARKERS,
    "nose": ["NS_TIP", "NS_R", "NS_L", "NS_BASE"],
    "cheeks": ["CH1_R", "CH2_R", "CH3_R", "CH4_R", "CH1_L", "CH2_L", "CH3_L", "CH4_L",
               "NL_R", "NL_L"],
    "upper lip": ["ULO_R", "ULO_C", "ULO_L", "UL2_R", "UL1_R", "UL_C", "UL1_L", "UL2_L"],
    "lip corners": LIP_CORNERS,
    "lower lip": ["LL2_R", "LL1_R", "LL_C", "LL1_L", "LL2_L", "LLO_R", "LLO_C", "LLO_L"],
    "chin & jaw line": ["CN_R", "CN_C", "CN_L", "CN_B", "JL1_R", "JL2_R", "JL3_R", "JL4_R",
                        "JL1_L", "JL2_L", "JL3_L", "JL4_L"],
}
assert len(MARKER_NAMES) == 54 and len(set(MARKER_NAMES)) == 54
assert sum(len(v) for v in GROUPS.values()) == 54


# --------------------------------------------------------------------------- configuration
@dataclass(frozen=True)
class FaceConfig:
    """Parameters of the face rig."""

    rate: float = 60.0
    condyle_y: float = 22.0          # condyle axis height (mm, relative to the lips at rest)
    condyle_z: float = -85.0         # and depth
    jaw_gain: float = 2.0            # face jaw degrees per VTL JA degree (JD3 moves little)
    condyle_glide: float = 0.3       # forward glide of the jaw (mm) per face jaw degree
    jx_gain: float = 10.0            # mm per cm of JX
    lip_gain: float = 10.0           # mm per cm of UL motion, LD and LP
    protrusion_gain: float = 0.5     # share of VTL's lip protrusion shown on the outer lips
    round_inward: float = 0.6        # corner moves in by this * LP change (each side)
    open_inward: float = 0.15        # and by this * LD change
    # the rest posture (VTL units) and its reference: lips together, jaw settled
    rest_ja: float = -2.4
    rest_jx: float = 0.0
    rest_lp: float = 0.05
    rest_ld: float = -0.05
    rest_ul_y: float = 0.30          # EMA UL height at rest (cm); VTL pause: about 0.47
    rest_ul_x: float = 6.95          # EMA UL forward position at rest (cm)
    rest_min_pause: float = 0.30     # pauses at least this long (s) bring the face to rest
    rest_ramp: float = 0.12          # ramp time (s) into and out of rest
    # nuisance
    head_rot_deg: float = 0.8        # rms of each head rotation angle
    head_shift_mm: float = 1.0       # rms of each head translation
    noise_mm: tuple[float, float] = (0.10, 0.25)   # per-marker noise sd range
    dropouts_per_minute: float = 2.0
    dropout_frames: tuple[int, int] = (2, 5)        # at 60 Hz: 33-83 ms


# --------------------------------------------------------------------------- helpers
def _interp(track: np.ndarray, rate: float, times: np.ndarray) -> np.ndarray:
    t = np.arange(len(track)) / rate
    return np.interp(times, t, track)


def rest_weight(times: np.ndarray, pauses: list[tuple[float, float]], duration: float,
                cfg: FaceConfig) -> np.ndarray:
    """1 where the face is at rest, 0 in speech, raised-cosine ramps between.

    ``pauses`` are (start, end) of the silent intervals; the first and last always rest (the
    utterance edges), inner ones only when at least ``rest_min_pause`` long. The ramp into rest
    starts at the pause start; the ramp out ends at the pause end (the lips part in time for the
    next sound).
    """
    w = np.zeros_like(times)
    ramp = cfg.rest_ramp
    for a, b in pauses:
        edge_start, edge_end = a <= 1e-9, b >= duration - 1e-9
        if not (edge_start or edge_end) and b - a < cfg.rest_min_pause:
            continue
        up = np.ones_like(times) if edge_start else np.clip((times - a) / ramp, 0, 1)
        down = np.ones_like(times) if edge_end else np.clip((b - times) / ramp, 0, 1)
        # a short pause: the ramps meet in the middle and the face gets only part-way to rest
        lin = np.minimum(up, down)
        w = np.maximum(w, 0.5 - 0.5 * np.cos(np.pi * lin))
    return w


def _rot_x(theta: np.ndarray, dy: np.ndarray, dz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c, s = np.cos(theta), np.sin(theta)
    return c * dy - s * dz, s * dy + c * dz


def _smooth_noise(rng: np.random.Generator, times: np.ndarray, rms: float,
                  n_sines: int = 4) -> np.ndarray:
    """A smooth random signal: a sum of slow sines (0.05-0.6 Hz) with the given rms."""
    f = rng.uniform(0.05, 0.6, n_sines)
    ph = rng.uniform(0, 2 * np.pi, n_sines)
    a = rng.normal(0, 1, n_sines)
    sig = (a[:, None] * np.sin(2 * np.pi * f[:, None] * times[None] + ph[:, None])).sum(0)
    return sig * rms / np.sqrt(0.5 * (a ** 2).sum() + 1e-12)


def _rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    cx, sx, cy, sy, cz, sz = np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry), np.cos(rz), np.sin(rz)
    mx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    my = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    mz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return mz @ my @ mx


# --------------------------------------------------------------------------- the rig
@dataclass
class Drivers:
    """The articulator tracks at the marker frames (VTL units), after blending into rest."""

    ja: np.ndarray
    jx: np.ndarray
    lp: np.ndarray
    ld: np.ndarray
    ul_y: np.ndarray
    ul_x: np.ndarray
    rest: np.ndarray


def drivers(vtl: VtlOutput, times: np.ndarray, pauses: list[tuple[float, float]],
            duration: float, cfg: FaceConfig) -> Drivers:
    """Sample VTL's jaw and lip tracks at ``times`` and blend them into the rest posture."""
    w = rest_weight(times, pauses, duration, cfg)

    def get(track: np.ndarray, rate: float, rest: float) -> np.ndarray:
        return (1 - w) * _interp(track, rate, times) + w * rest

    return Drivers(
        ja=get(vtl.param("JA"), TRACT_RATE, cfg.rest_ja),
        jx=get(vtl.param("JX"), TRACT_RATE, cfg.rest_jx),
        lp=get(vtl.param("LP"), TRACT_RATE, cfg.rest_lp),
        ld=get(vtl.param("LD"), TRACT_RATE, cfg.rest_ld),
        ul_y=get(vtl.point("UL")[:, 1], EMA_RATE, cfg.rest_ul_y),
        ul_x=get(vtl.point("UL")[:, 0], EMA_RATE, cfg.rest_ul_x),
        rest=w,
    )


def articulate(d: Drivers, cfg: FaceConfig) -> np.ndarray:
    """Marker positions ``(frames, 54, 3)`` mm from the drivers (no head motion or noise)."""
    n = len(d.ja)
    idx = {name: i for i, name in enumerate(MARKER_NAMES)}
    r = REST_FACE
    out = np.repeat(r[None], n, axis=0)

    # jaw rotation about the condyle axis (opening = JA more negative than at rest)
    theta = np.deg2rad(cfg.jaw_gain * (cfg.rest_ja - d.ja))
    jx = cfg.jx_gain * (d.jx - cfg.rest_jx) + cfg.condyle_glide * np.rad2deg(theta)

    def jaw_disp(i: int) -> np.ndarray:
        dy0, dz0 = r[i, 1] - cfg.condyle_y, r[i, 2] - cfg.condyle_z
        dy, dz = _rot_x(theta, dy0, dz0)
        return np.stack([np.zeros(n), dy - dy0, dz - dz0 + jx], axis=1)

    g = cfg.lip_gain
    ul = np.stack([np.zeros(n), g * (d.ul_y - cfg.rest_ul_y),
                   cfg.protrusion_gain * g * (d.ul_x - cfg.rest_ul_x)], 1)
    # lower lip centre: LD below the upper lip, same protrusion as the upper lip
    ll_total = ul + np.stack([np.zeros(n), -g * (d.ld - cfg.rest_ld), np.zeros(n)], 1)
    ll_own = ll_total - jaw_disp(idx["LL_C"])
    lp = g * (d.lp - cfg.rest_lp)
    ld = g * (d.ld - cfg.rest_ld)

    def corner_disp(side: float) -> np.ndarray:  # side +1 = left (x > 0), -1 = right
        i = idx["LC_L" if side > 0 else "LC_R"]
        inward = cfg.round_inward * lp + cfg.open_inward * ld
        dxyz = 0.35 * ul + 0.35 * ll_total + 0.25 * jaw_disp(i)
        dxyz[:, 0] = -side * inward
        dxyz[:, 2] = 0.5 * ul[:, 2] - 0.1 * np.abs(ld)
        return dxyz

    corner = {+1.0: corner_disp(+1.0), -1.0: corner_disp(-1.0)}

    def side_of(name: str) -> float:
        return 1.0 if name.endswith("_L") else -1.0

    # weights: (jaw, upper lip, lower lip own, corner)
    lateral_upper = {"UL1": 0.15, "UL2": 0.5}
    lateral_lower = {"LL1": 0.15, "LL2": 0.5}
    soft = {  # name stem -> (jaw, upper lip, lower-lip own, corner)
        "NS_TIP": (0.0, 0.05, 0.0, 0.0), "NS": (0.0, 0.1, 0.0, 0.1),
        "NS_BASE": (0.0, 0.3, 0.0, 0.0),
        "CH1": (0.05, 0.0, 0.0, 0.1), "CH2": (0.2, 0.0, 0.0, 0.25),
        "CH3": (0.4, 0.0, 0.0, 0.45), "CH4": (0.7, 0.0, 0.0, 0.1),
        "NL": (0.1, 0.3, 0.0, 0.4),
        "ULO_C": (0.0, 0.55, 0.0, 0.0), "ULO": (0.0, 0.45, 0.0, 0.2),
        "LLO_C": (1.0, 0.0, 0.45, 0.0), "LLO": (1.0, 0.0, 0.35, 0.1),
        "CN_C": (1.0, 0.0, 0.08, 0.0), "CN": (1.0, 0.0, 0.04, 0.0), "CN_B": (1.0, 0.0, 0.0, 0.0),
        "JL1": (1.0, 0.0, 0.0, 0.0), "JL2": (1.0, 0.0, 0.0, 0.0), "JL3": (1.0, 0.0, 0.0, 0.0),
        "JL4": (1.0, 0.0, 0.0, 0.0),
    }
    for name, i in idx.items():
        if name in FIXED_MARKERS:
            continue
        stem = name if name in soft or name in ("UL_C", "LL_C", "LC_R", "LC_L") \
            else name.rsplit("_", 1)[0]
        s = side_of(name)
        if name == "UL_C":
            disp = ul
        elif name == "LL_C":
            disp = ll_total
        elif name in LIP_CORNERS:
            disp = corner[s]
        elif stem in lateral_upper:
            a = lateral_upper[stem]
            disp = (1 - a) * ul + a * corner[s]
        elif stem in lateral_lower:
            a = lateral_lower[stem]
            disp = (1 - a) * (jaw_disp(i) + ll_own) + a * corner[s]
        else:
            wj, wu, wo, wc = soft[stem]
            disp = wj * jaw_disp(i) + wu * ul + wo * ll_own
            if wc:  # only lateral markers have a corner weight
                disp = disp + wc * corner[s]
        out[:, i] += disp
    return out


def add_nuisance(markers: np.ndarray, rng: np.random.Generator, cfg: FaceConfig
                 ) -> tuple[np.ndarray, list[tuple[str, int, int]]]:
    """Add rigid head motion, marker noise and dropouts; return the markers and the dropouts.

    Dropouts are ``(marker, first frame, n frames)``; the fixed markers never lose more than
    one at a time, so at least 3 of them are always seen.
    """
    n = markers.shape[0]
    times = np.arange(n) / cfg.rate
    rot = [np.deg2rad(_smooth_noise(rng, times, cfg.head_rot_deg)) for _ in range(3)]
    shift = np.stack([_smooth_noise(rng, times, cfg.head_shift_mm) for _ in range(3)], 1)
    pivot = np.array([0.0, -60.0, -90.0])  # about the top of the neck
    out = np.empty_like(markers)
    for k in range(n):
        m = _rotation(rot[0][k], rot[1][k], rot[2][k])
        out[k] = (markers[k] - pivot) @ m.T + pivot + shift[k]
    sd = rng.uniform(*cfg.noise_mm, size=markers.shape[1])
    out += rng.normal(0.0, 1.0, out.shape) * sd[None, :, None]
    drops: list[tuple[str, int, int]] = []
    n_drop = rng.poisson(cfg.dropouts_per_minute * n / cfg.rate / 60.0)
    fixed = {MARKER_NAMES.index(f) for f in FIXED_MARKERS}
    lost_fixed = np.zeros(n, dtype=bool)
    for _ in range(int(n_drop)):
        i = int(rng.integers(len(MARKER_NAMES)))
        length = int(rng.integers(cfg.dropout_frames[0], cfg.dropout_frames[1] + 1))
        start = int(rng.integers(0, max(1, n - length)))
        if i in fixed:
            if lost_fixed[start:start + length].any():
                continue
            lost_fixed[start:start + length] = True
        out[start:start + length, i] = np.nan
        drops.append((MARKER_NAMES[i], start, length))
    return out, drops
