"""NDI Wave / Vox exports of WaveFront: tab-separated text, one row per sample.

The header row names the columns: the time (s) first, measurement and wave ids, then per sensor
its ``Id``, its status (``Status`` or ``State``), its position ``Tx Ty Tz`` (or ``X Y Z``, mm) and
its orientation ``Q0 Qx Qy Qz`` -- in whichever order the export wrote them (WaveFront versions
differ: ``Id Status Tx Ty Tz Q0 Qx Qy Qz`` as OptiSpeech and ematoblender read it, or ``Id Frame
State Q0 ... Tz``); a sensor's columns run from its ``Id`` to the next. A sample whose status is
not ``OK`` (old exports: ``55``), or whose position is empty, is missing. Rows are placed on the
time grid of the median step, so a dropped row is a missing frame. Sensors are unnamed: ``Ch1``,
``Ch2``, ... in column order (their ids are logged); positions are in the system's axes.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

import numpy as np

from ...errors import InputError
from .common import check_rate, mark_missing, text_rows, whole
from .recording import MarkerRecording, unnamed
from .registry import MarkerFormat

log = logging.getLogger(__name__)

OK_STATUS = {"ok", "55"}
_AXES = {"tx": 0, "ty": 1, "tz": 2, "x": 0, "y": 1, "z": 2}


def _key(name: str) -> str:
    """A column name reduced for matching: ``'Sensor 1 Tx'`` -> ``'tx'``.

    >>> [_key(n) for n in ("Wav Time", "Sensor 2 Id", "Q0", "Tx", "State")]
    ['wavtime', 'id', 'q0', 'tx', 'state']
    """
    key = re.sub(r"[^a-z0-9]", "", name.lower())
    return re.sub(r"^sensor\d*", "", key) or key


def _is_id(key: str) -> bool:
    return key == "id" or (key.endswith("id") and key not in ("measid", "wavid", "measurementid"))


def sniff(head: bytes) -> bool:
    """Whether a file starts with a WaveFront header row (time, an id and position columns)."""
    first = head.split(b"\n", 1)[0].decode("latin-1")
    keys = {_key(k) for k in first.split("\t")}
    return "\t" in first and any(_is_id(k) for k in keys) and bool({"tx", "ty", "tz", "q0"} & keys)


def _sensors(path: Path, header: list[str]) -> list[tuple[int, int | None, list[int]]]:
    """Per sensor: its id column, status column and x, y, z columns."""
    keys = [_key(h) for h in header]
    starts = [i for i, k in enumerate(keys) if _is_id(k) and i > 0]
    if not starts:
        raise InputError(path, "no sensor 'Id' column in the WaveFront header")
    out = []
    for s, end in zip(starts, [*starts[1:], len(keys)], strict=True):
        group = {k: i for i, k in enumerate(keys[s:end], s)}
        status = next((group[k] for k in ("status", "state") if k in group), None)
        axes = [next((group[k] for k in group if _AXES.get(k) == a), None) for a in range(3)]
        if None in axes:
            raise InputError(path, f"sensor {len(out) + 1} (columns {s + 1}-{end}) has no "
                                   f"Tx Ty Tz columns")
        out.append((s, status, axes))
    return out


def _on_grid(path: Path, times: np.ndarray) -> tuple[np.ndarray, float]:
    """Each row's frame on the regular grid of the median time step, and the rate."""
    steps = np.diff(times)
    if len(times) < 2 or not np.isfinite(times).all() or (steps <= 0).any():
        where = int(np.argmax(~(steps > 0))) + 3 if len(steps) else 2
        raise InputError(path, f"its times do not increase (line {where})")
    rate = check_rate(path, whole(1.0 / float(np.median(steps))), " (from the time column)")
    frame = np.round((times - times[0]) * rate).astype(np.int64)
    if frame[-1] > 10 * len(times):
        raise InputError(path, f"its times span {frame[-1]} frames for {len(times)} rows")
    return frame, rate


def read_ndi(path: Path) -> MarkerRecording:
    """Read a WaveFront TSV export (see the module's description)."""
    rows = text_rows(path, "NDI Wave file", sep="\t")
    header, rows = rows[0], rows[1:]
    if not rows:
        raise InputError(path, "the NDI Wave file has a header but no rows")
    sensors = _sensors(path, header)
    width = max(len(header), *(len(r) for r in rows))
    rows = [r + [""] * (width - len(r)) for r in rows]
    try:
        times = np.array([float(r[0]) for r in rows])
        values = np.array([[[float(r[c]) if r[c].strip() else np.nan for c in axes]
                            for _, _, axes in sensors] for r in rows])
    except ValueError as exc:
        raise InputError(path, f"a time or position is not a number ({exc})") from None
    ok = np.array([[st is None or r[st].strip().lower() in OK_STATUS for _, st, _ in sensors]
                   for r in rows])
    frame, rate = _on_grid(path, times)
    markers = np.full((frame[-1] + 1, len(sensors), 3), np.nan)
    markers[frame] = values
    bad = np.zeros(markers.shape[:2], bool)
    bad[frame] = ~ok
    bad |= ~np.isfinite(markers).all(axis=2)
    rec = MarkerRecording(markers, rate, unnamed(len(sensors)))
    rec.missing = mark_missing(path, markers, bad, "status not OK, empty, or a row not written")
    log.info("%s: sensor ids %s", path.name, ", ".join(
        f"{n} = {rows[0][s].strip() or '?'}" for n, (s, _, _) in zip(rec.names, sensors, strict=True)))
    return rec


FORMATS = (MarkerFormat("NDI Wave TSV", (".tsv",), read_ndi, sniff=sniff,
                        signature="a WaveFront header: time, Id, Status, Tx Ty Tz, Q0-Qz", order=45),)
