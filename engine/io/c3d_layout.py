"""The bytes of a C3D file of 3-D points (no analog channels), written in one piece.

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

import numpy as np

BLOCK = 512
INTEL = 84                  # processor type: little-endian IEEE floats
UINT16_MAX = 65535
MAX_POINTS = 255            # a dimension is one byte: POINT:LABELS holds at most 255 names


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


def _parameters(n_frames: int, n_points: int, labels: Sequence[str], scale: float, rate: float,
                units: str, data_block: int) -> bytes:
    """The three groups, in the order and with the descriptions ``c3d.Writer`` uses."""
    width = max(len(label) for label in labels)
    packed = "".join(label.ljust(width) for label in labels).encode()
    f32 = lambda v: struct.pack("<f", v)  # noqa: E731
    u16 = lambda v: struct.pack("<H", v)  # noqa: E731
    analog = [("GEN_SCALE", 4, [], f32(1.0), "Analog general scale factor"),
              ("USED", 2, [], u16(0), "Analog channel count"),
              ("RATE", 4, [], f32(0.0), "Analog samples per second"),
              ("SCALE", 4, [0], b"", "Analog channel scale factors"),
              ("OFFSET", 2, [0], b"", "Analog channel offsets"),
              ("DESCRIPTIONS", -1, [1, 0], b"", "Channel descriptions.")]
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
    trial = [("ACTUAL_START_FIELD", 2, [2], struct.pack("<I", 1), "Actual start frame"),
             ("ACTUAL_END_FIELD", 2, [2], struct.pack("<I", n_frames), "Actual end frame")]
    return _group("ANALOG", 1, analog) + _group("POINT", 2, point) + _group("TRIAL", 3, trial)


def c3d_bytes(raw: np.ndarray, rate: float, scale: float, labels: Sequence[str],
              units: str = "mm  ") -> bytes:
    """A whole C3D file for ``raw``, the data block as stored: ``(frames, points, 4)`` int16
    (``scale`` > 0, the mm per step) or float32 (``scale`` < 0), x y z and the residual word.

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
    probe = _parameters(n_frames, n_points, labels, scale, rate, units, 0)
    # c3d counts every group twice (its table holds each under its id and its name)
    blocks = math.ceil((4 + 2 * len(probe)) / BLOCK)
    data_block = 2 + blocks
    params = struct.pack("BBBB", 0, 0, blocks, INTEL) + _parameters(
        n_frames, n_points, labels, scale, rate, units, data_block)
    header = struct.pack("<BBHHHHHfHHf274sHHH164s44s", 2, 0x50, n_points, 0, 1,
                         min(n_frames, UINT16_MAX), 0, scale, data_block, 0, rate, b"", 0, 0, 0,
                         b"", b"")
    meta = header.ljust(BLOCK, b"\0") + params.ljust(blocks * BLOCK, b"\0")
    body = np.ascontiguousarray(raw).tobytes()
    return meta + body + b"\0" * (-len(body) % BLOCK)
