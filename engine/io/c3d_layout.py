"""The bytes of a C3D file of 3-D points (and, for facetraj's outputs, the screen axes and the
speech as an analog channel: :class:`C3dExtras`), written in one piece.

A C3D file (https://www.c3d.org/docs/C3D_User_Guide.pdf; :mod:`.c3d_check` reads the same
layout) is a 512-byte header, a parameter section (groups ANALOG, POINT and TRIAL, each a chain of
named parameters with their own size fields) and the data block: per frame, per point, x y z and
a residual word (int16, or float32 when the scale is negative), padded to 512 bytes.

:func:`c3d_bytes` lays out exactly the bytes the ``c3d`` package (0.6) writes for the same points
(header fields, parameter order and descriptions, its parameter-block count), so that the default
corpus's C3D files stay byte for byte what they were (tested against ``c3d.Writer``), but builds
the data block from one array instead of a Python loop over frames (3,600 frames took that
library longer than the synthesis).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

BLOCK = 512
INTEL = 84                  # processor type: little-endian IEEE floats
UINT16_MAX = 65535
MAX_POINTS = 255            # a dimension is one byte: POINT:LABELS holds at most 255 names


@dataclass(frozen=True)
class C3dExtras:
    """What a C3D written as a facetraj output declares beyond its points (issue 38).

    ``x_screen``, ``y_screen``: POINT:X_SCREEN and POINT:Y_SCREEN, the C3D standard's two-letter
    parameters naming the axis of the data drawn to the right of the screen and the one drawn up
    (facetraj's head frame: x to the talker's left, which is the right of a viewer facing them, y
    up, z forward out of the face: ``+X``, ``+Y``, a front view), so that a viewer that honours
    them shows the face upright, not lying on its back as a Z-up default draws it.

    ``analog``: one channel's samples ``(frames, per_frame)`` in [-1, 1] (``None``: no analog
    data), at ``analog_rate`` = ``per_frame`` x the point rate, stored as the points are (int16
    steps of 1/32767, or float32), named ``analog_label``, described by ``analog_description``,
    in ``analog_units``."""

    x_screen: str = "+X"
    y_screen: str = "+Y"
    analog: np.ndarray | None = None
    analog_rate: float = 0.0
    analog_label: str = "SPEECH"
    analog_description: str = "speech"
    analog_units: str = "1"

    @property
    def per_frame(self) -> int:
        return 0 if self.analog is None else int(self.analog.shape[1])


def _param(name: str, group_id: int, size: int, dims: Sequence[int], data: bytes,
           desc: str) -> bytes:
    """One parameter entry: name, offset to the next entry, element size, dimensions, data,
    description (C3D User Guide, "Parameter records")."""
    key, text = name.encode(), desc.encode()
    rest = struct.pack("<hbB", 0, size, len(dims)) + bytes(dims) + data + bytes([len(text)]) + text
    offset = len(rest)                              # from the offset word to the next entry
    return struct.pack("bb", len(key), group_id) + key + struct.pack("<h", offset) + rest[2:]


def _group(name: str, group_id: int, params: Sequence[tuple]) -> bytes:
    """A group entry (its id negative) followed by its parameters."""
    key, text = name.encode(), f"{name} group".encode()
    head = struct.pack("bb", len(key), -group_id) + key + struct.pack("<hB", 3 + len(text), len(text))
    return head + text + b"".join(_param(p[0], group_id, *p[1:]) for p in params)


def _f32(v: float) -> bytes:
    return struct.pack("<f", v)


def _u16(v: int) -> bytes:
    return struct.pack("<H", v)


def _analog_group(extras: C3dExtras | None, integer: bool) -> list[tuple]:
    """The ANALOG group: none used (in the order and with the descriptions ``c3d.Writer`` uses),
    or the one channel of ``extras``."""
    if extras is None or extras.analog is None:
        return [("GEN_SCALE", 4, [], _f32(1.0), "Analog general scale factor"),
                ("USED", 2, [], _u16(0), "Analog channel count"),
                ("RATE", 4, [], _f32(0.0), "Analog samples per second"),
                ("SCALE", 4, [0], b"", "Analog channel scale factors"),
                ("OFFSET", 2, [0], b"", "Analog channel offsets"),
                ("DESCRIPTIONS", -1, [1, 0], b"", "Channel descriptions.")]
    e = extras
    text = [(e.analog_label, "Channel labels."), (e.analog_description, "Channel descriptions."),
            (e.analog_units, "Channel units.")]
    return [("GEN_SCALE", 4, [], _f32(1.0), "Analog general scale factor"),
            ("USED", 2, [], _u16(1), "Analog channel count"),
            ("RATE", 4, [], _f32(e.analog_rate), "Analog samples per second"),
            ("SCALE", 4, [1], _f32(1 / ANALOG_STEPS if integer else 1.0),
             "Analog channel scale factors"),
            ("OFFSET", 2, [1], struct.pack("<h", 0), "Analog channel offsets"),
            *[(name, -1, [len(t), 1], t.encode(), d)
              for name, (t, d) in zip(("LABELS", "DESCRIPTIONS", "UNITS"), text, strict=True)],
            ("FORMAT", -1, [6], b"SIGNED", "Analog data format."),
            ("BITS", 2, [], _u16(16), "Analog resolution in bits.")]


#: int16 analog data: a sample of 1 is stored as this many steps
ANALOG_STEPS = 32767


def _parameters(n_frames: int, n_points: int, labels: Sequence[str], scale: float, rate: float,
                units: str, data_block: int, extras: C3dExtras | None = None) -> bytes:
    """The three groups, in the order and with the descriptions ``c3d.Writer`` uses (and what
    ``extras`` declares after them)."""
    width = max(len(label) for label in labels)
    packed = "".join(label.ljust(width) for label in labels).encode()
    f32, u16 = _f32, _u16
    analog = _analog_group(extras, scale > 0)
    point = [("LABELS", -1, [width, len(labels)], packed, "Point labels."),
             ("USED", 2, [], u16(n_points), "Number of point samples"),
             ("FRAMES", 2, [], u16(min(UINT16_MAX, n_frames)), "Total frame count")]
    if n_frames >= UINT16_MAX:
        point.append(("LONG_FRAMES", 4, [], f32(n_frames), "Total frame count"))
    point += [("DATA_START", 2, [], u16(data_block), "First data block containing frame samples."),
              ("SCALE", 4, [], f32(scale), "Point data scaling factor"),
              ("RATE", 4, [], f32(rate), "Point data sample rate"),
              ("UNITS", -1, [len(units)], units.encode(), "Units used for point data measurements."),
              ("DESCRIPTIONS", -1, [1, n_points], b" " * n_points, "Channel descriptions.")]
    if extras is not None:
        point += [("X_SCREEN", -1, [2], extras.x_screen.encode(), "Axis drawn to the right."),
                  ("Y_SCREEN", -1, [2], extras.y_screen.encode(), "Axis drawn up.")]
    trial = [("ACTUAL_START_FIELD", 2, [2], struct.pack("<I", 1), "Actual start frame"),
             ("ACTUAL_END_FIELD", 2, [2], struct.pack("<I", n_frames), "Actual end frame")]
    return _group("ANALOG", 1, analog) + _group("POINT", 2, point) + _group("TRIAL", 3, trial)


def c3d_bytes(raw: np.ndarray, rate: float, scale: float, labels: Sequence[str],
              units: str = "mm  ", extras: C3dExtras | None = None) -> bytes:
    """A whole C3D file for ``raw``, the data block as stored: ``(frames, points, 4)`` int16
    (``scale`` > 0, the mm per step) or float32 (``scale`` < 0), x y z and the residual word;
    with ``extras``, the screen axes and an analog channel after each frame's points, stored as
    they are (``None``: the bytes ``c3d.Writer`` writes).

    >>> raw = np.zeros((2, 1, 4), dtype="<f4")
    >>> data = c3d_bytes(raw, 60.0, -1.0, ["UL"])
    >>> len(data) % 512, data[1], struct.unpack_from("<H", data, 2)[0]   # blocks, 0x50, 1 point
    (0, 80, 1)
    """
    n_frames, n_points = raw.shape[:2]
    if raw.ndim != 3 or raw.shape[2] != 4 or n_points != len(labels) or n_frames < 1 \
            or not 1 <= n_points <= MAX_POINTS or max(map(len, labels)) > MAX_POINTS:
        raise ValueError(f"raw must be (frames >= 1, {len(labels)}, 4), got {raw.shape}")
    if raw.dtype not in (np.dtype("<i2"), np.dtype("<f4")) or (raw.dtype.kind == "f") != (scale < 0):
        raise ValueError(f"{raw.dtype} data does not go with the scale {scale}")
    probe = _parameters(n_frames, n_points, labels, scale, rate, units, 0, extras)
    # c3d counts every group twice (its table holds each under its id and its name)
    blocks = math.ceil((4 + 2 * len(probe)) / BLOCK)
    data_block = 2 + blocks
    params = struct.pack("BBBB", 0, 0, blocks, INTEL) + _parameters(
        n_frames, n_points, labels, scale, rate, units, data_block, extras)
    per_frame = extras.per_frame if extras is not None else 0
    header = struct.pack("<BBHHHHHfHHf274sHHH164s44s", 2, 0x50, n_points, per_frame, 1,
                         min(n_frames, UINT16_MAX), 0, scale, data_block, per_frame, rate, b"",
                         0, 0, 0, b"", b"")
    meta = header.ljust(BLOCK, b"\0") + params.ljust(blocks * BLOCK, b"\0")
    body = _frames(raw, extras).tobytes()
    return meta + body + b"\0" * (-len(body) % BLOCK)


def _frames(raw: np.ndarray, extras: C3dExtras | None) -> np.ndarray:
    """The data block's frames: each frame's points, then its analog samples in the points'
    type (int16 steps of 1 / :data:`ANALOG_STEPS`, or float32)."""
    if extras is None or extras.analog is None:
        return np.ascontiguousarray(raw)
    analog = np.clip(np.asarray(extras.analog, dtype=np.float64), -1.0, 1.0)
    if len(analog) != len(raw):
        raise ValueError(f"{len(analog)} frames of analog samples for {len(raw)} frames of points")
    if raw.dtype.kind == "i":
        analog = np.rint(analog * ANALOG_STEPS)
    return np.concatenate([raw.reshape(len(raw), -1), analog.astype(raw.dtype)], axis=1)
