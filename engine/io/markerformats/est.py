"""Edinburgh Speech Tools track files (``EST_File Track``): mngu0's and MOCHA-TIMIT's EMA.

The header (``key value`` lines up to ``EST_Header_End``) gives ``NumFrames``, ``NumChannels``,
``DataType`` (``ascii`` or ``binary``), ``ByteOrder`` (``10``: big-endian, ``01``: little-endian)
and ``Channel_N name``. Each frame is its time (s), a break flag when ``BreaksPresent`` (0: no
data in that frame) and one float32 per channel -- the layout the Speech Tools write
(``EST_TrackFile::save_est_binary_ts``).

Channels named ``<sensor>_x``, ``_y`` (``_z``) or ``_px``, ``_py``, ``_pz`` (mngu0) make one marker
per sensor; other channels (orientations, rms) are left out, named in the log. A file whose
sensors are MOCHA-TIMIT's coils is read as MOCHA (1/100 mm, x toward the back); other files in
mm, 3-D sensors in the file's axes and 2-D ones (x, y) as x forward, y up. Channels are never
matched by position, with one exception, said in a warning: a file of exactly MOCHA's 20
channels with no names is read in the MOCHAtools order.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

import numpy as np

from ...errors import InputError, warn_file
from .common import mark_missing, rate_of_times, read_binary
from .mocha import MOCHA_COILS, MOCHA_RATE, mocha_recording
from .recording import MarkerRecording, midsagittal
from .registry import MarkerFormat

log = logging.getLogger(__name__)

MAGIC = b"EST_File Track"
END = b"EST_Header_End"
_AXIS = re.compile(r"^(?P<sensor>.+?)_p?(?P<axis>[xyz])$", re.IGNORECASE)


def _header(path: Path, raw: bytes) -> tuple[dict[str, str], dict[int, str], bytes]:
    """The header's fields, its channel names by number, and the data after it."""
    end = raw.find(END)
    if end < 0:
        raise InputError(path, "EST track file without EST_Header_End")
    newline = raw.find(b"\n", end)
    body = raw[newline + 1:] if newline >= 0 else b""
    fields: dict[str, str] = {}
    names: dict[int, str] = {}
    for line in raw[:end].decode("ascii", errors="replace").splitlines()[1:]:
        parts = line.split(None, 1)
        if len(parts) != 2:
            continue
        key, val = parts[0], parts[1].strip()
        number = key.removeprefix("Channel_")
        if key.startswith("Channel_") and number.isdigit():
            names[int(number)] = val
        fields[key] = val
    return fields, names, body


def _frames(path: Path, fields: dict[str, str], body: bytes, n_frames: int, n_chan: int
            ) -> np.ndarray:
    """The frames as ``(frames, 2 + channels)``: time, break flag (1 when none), channels."""
    breaks = fields.get("BreaksPresent", "false").lower() == "true"
    if fields.get("DataType", "ascii") == "binary":
        width = 1 + breaks + n_chan
        order = "<" if fields.get("ByteOrder", "10") == "01" else ">"
        if len(body) < n_frames * width * 4:
            raise InputError(path, f"binary EST data holds {len(body) // 4} values, "
                                   f"{n_frames * width} expected (truncated?)")
        data = np.frombuffer(body, f"{order}f4", n_frames * width).reshape(n_frames, width)
        data = data.astype(np.float64)
    else:
        rows = [ln.split() for ln in body.decode("ascii", errors="replace").splitlines() if ln.strip()]
        if len(rows) < n_frames:
            raise InputError(path, f"EST data holds {len(rows)} frames, its header says {n_frames} "
                                   f"(truncated?)")
        try:
            data = np.array([[float(v) for v in r] for r in rows[:n_frames]])
        except ValueError as exc:
            raise InputError(path, f"EST data is not numeric ({exc})") from None
        if data.ndim != 2 or data.shape[1] not in (n_chan + 1, n_chan + 2):
            raise InputError(path, f"EST rows have {data.shape[-1]} columns, {n_chan + 2} expected")
        breaks = data.shape[1] == n_chan + 2
    if not breaks:
        data = np.insert(data, 1, 1.0, axis=1)
    return data


def read_est_track(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """An EST track's times, break flags, channel values and names (``""`` where unnamed)."""
    raw = read_binary(path, "EST track file")
    fields, names, body = _header(path, raw)
    try:
        n_frames, n_chan = int(fields["NumFrames"]), int(fields["NumChannels"])
    except (KeyError, ValueError) as exc:
        raise InputError(path, "EST header lacks NumFrames/NumChannels") from exc
    if not 1 <= n_frames <= 100_000_000 or not 1 <= n_chan <= 10000:
        raise InputError(path, f"EST header gives {n_frames} frames of {n_chan} channels")
    data = _frames(path, fields, body, n_frames, n_chan)
    return data[:, 0], data[:, 1], data[:, 2:], [names.get(i, "") for i in range(n_chan)]


def sensors_of(names: list[str]) -> tuple[dict[str, dict[str, int]], list[str]]:
    """Channels grouped into sensors by name (``{sensor: {axis: channel}}``) and the channels
    that are no sensor coordinate.

    >>> sensors_of(["T1_px", "T1_py", "T1_pz", "T1_ox", "ul_x", "ul_y"])
    ({'T1': {'x': 0, 'y': 1, 'z': 2}, 'ul': {'x': 4, 'y': 5}}, ['T1_ox'])
    """
    sensors: dict[str, dict[str, int]] = {}
    other = []
    for i, name in enumerate(names):
        m = _AXIS.match(name)
        if m:
            sensors.setdefault(m["sensor"], {})[m["axis"].lower()] = i
        elif name:
            other.append(name)
    for sensor in [s for s, axes in sensors.items() if not {"x", "y"} <= set(axes)]:
        other.extend(names[i] for i in sensors.pop(sensor).values())
    return sensors, other


def read_est(path: Path) -> MarkerRecording:
    """Read an EST track of EMA channels (see the module's description)."""
    times, flags, chans, names = read_est_track(path)
    sensors, other = sensors_of(names)
    if not sensors:
        return _unnamed(path, times, flags, chans, names)
    if other:
        log.info("%s: channels that are no sensor position left out: %s", path.name,
                 " ".join(other[:12]) + (" ..." if len(other) > 12 else ""))
    planar = all("z" not in axes for axes in sensors.values())
    if planar and {s.upper() for s in sensors} <= set(MOCHA_COILS):
        order = sorted(sensors, key=lambda s: list(MOCHA_COILS).index(s.upper()))
        xs = np.stack([chans[:, sensors[s]["x"]] for s in order], axis=1)
        ys = np.stack([chans[:, sensors[s]["y"]] for s in order], axis=1)
        rec = mocha_recording(path, times, xs, ys, [s.upper() for s in order])
    else:
        rec = MarkerRecording(_positions(sensors, chans), _rate(path, times), list(sensors))
    rec.missing = mark_missing(path, rec.markers, _missing(rec.markers, flags), "EST breaks or NaN")
    return rec


def _positions(sensors: dict[str, dict[str, int]], chans: np.ndarray) -> np.ndarray:
    """Sensors in mm: 3-D in the file's axes, 2-D (x forward, y up) in the midsagittal plane."""
    cols = []
    for axes in sensors.values():
        if "z" in axes:
            cols.append(chans[:, [axes["x"], axes["y"], axes["z"]]])
        else:
            cols.append(midsagittal(chans[:, axes["x"]], chans[:, axes["y"]]))
    return np.stack(cols, axis=1)


def _missing(markers: np.ndarray, flags: np.ndarray) -> np.ndarray:
    """Samples with no data: a frame the track marks as a break, or a NaN coordinate."""
    return (flags == 0)[:, None] | ~np.isfinite(markers).all(axis=2)


def _rate(path: Path, times: np.ndarray) -> float:
    return rate_of_times(path, times) if len(times) > 1 else MOCHA_RATE


def _unnamed(path: Path, times: np.ndarray, flags: np.ndarray, chans: np.ndarray,
             names: list[str]) -> MarkerRecording:
    """A track without sensor names: MOCHA's 20 channels by position (with a warning), else refused."""
    if chans.shape[1] != 20:
        shown = " ".join(n or f"#{i}" for i, n in enumerate(names[:8]))
        raise InputError(path, f"its {chans.shape[1]} channels ({shown}{' ...' if len(names) > 8 else ''}) "
                               f"are not named <sensor>_x, _y[, _z] (or _px, _py, _pz): facetraj "
                               f"does not guess which channel is which; name them in the header")
    warn_file(log, path, "EST channels without names read in MOCHA's order",
              "its 20 channels have no sensor names: read as MOCHA-TIMIT's coils in the MOCHAtools "
              "column order (name them in the header to be sure)")
    xs = np.stack([chans[:, cx - 3] for cx, _ in MOCHA_COILS.values()], axis=1)
    ys = np.stack([chans[:, cy - 3] for _, cy in MOCHA_COILS.values()], axis=1)
    rec = mocha_recording(path, times, xs, ys, list(MOCHA_COILS))
    rec.missing = mark_missing(path, rec.markers, _missing(rec.markers, flags), "EST breaks or NaN")
    return rec


FORMATS = (MarkerFormat("EST track", (".ema", ".est"), read_est, sniff=lambda head: head.startswith(MAGIC),
                        signature="'EST_File Track' header", order=31),)
