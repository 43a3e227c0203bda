"""Bounds of a C3D file, checked before a C3D library reads it.

A C3D file (https://www.c3d.org/docs/C3D_User_Guide.pdf) starts with a 512-byte header: word 1
the parameter block, word 2 the number of 3-D points, word 3 the analog samples per frame, words
4-5 the first and last frame, words 7-8 the scale (negative: float data), word 9 the data block,
words 11-12 the frame rate. The parameter section (byte 3 of its first block: the processor type,
84 Intel, 85 DEC, 86 MIPS) is a chain of groups and parameters, each with its own size fields.

:func:`check_c3d` walks the parameter chain (every entry inside the section, every parameter's
data inside its entry), reads the point count, frame count and rate from the header and the
POINT / ANALOG parameters, and checks that the samples they ask for fit in the file and that the
rate is sane. A damaged file is refused in microseconds instead of making the reader allocate
gigabytes. Raises :class:`~facetraj_engine.errors.InputError` naming the file.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

from ..errors import InputError

BLOCK = 512
MIN_RATE, MAX_RATE = 1.0, 10000.0
_PROCESSORS = {84: "<", 85: "<", 86: ">"}


def _float(raw: bytes, order: str, dec: bool) -> float:
    if dec:  # DEC F_floating: 16-bit halves swapped, exponent bias 2 more than IEEE
        return struct.unpack("<f", raw[2:4] + raw[0:2])[0] / 4.0
    return struct.unpack(order + "f", raw)[0]


def read_c3d_parameters(path: Path, data: bytes) -> tuple[str, bool, dict[tuple[str, str], list]]:
    """The byte order, DEC flag and numeric parameters ``{(GROUP, NAME): values}`` of a C3D.

    Raises :class:`InputError` when any entry of the parameter chain points outside the
    section or its data does not fit in its entry."""
    def bad(problem: str) -> InputError:
        return InputError(path, f"not a readable C3D file ({problem})")

    if len(data) < BLOCK or data[1] != 0x50:
        raise bad("no C3D header")
    start = (data[0] - 1) * BLOCK
    if data[0] < 2 or start + 4 > len(data):
        raise bad("the parameter section lies outside the file")
    proc = data[start + 3]
    if proc not in _PROCESSORS:
        raise bad(f"unknown processor type {proc}")
    order, dec = _PROCESSORS[proc], proc == 85
    n_blocks = data[start + 2]
    end = min(start + max(n_blocks, 1) * BLOCK, len(data))
    pos = start + 4
    groups: dict[int, str] = {}
    raw_params: list[tuple[int, str, int, tuple[int, ...], bytes]] = []
    while pos + 2 <= end:
        name_len = abs(struct.unpack("b", data[pos:pos + 1])[0])
        gid = struct.unpack("b", data[pos + 1:pos + 2])[0]
        if name_len == 0:
            break
        name_end = pos + 2 + name_len
        if name_end + 2 > end:
            raise bad("a parameter name runs past the parameter section")
        name = "".join(c if c.isascii() and c.isprintable() else "?" for c in
                       data[pos + 2:name_end].decode("ascii", errors="replace")).strip().upper()[:32]
        offset = struct.unpack(order + "h", data[name_end:name_end + 2])[0]
        nxt = name_end + offset
        if offset == 0:
            nxt = end
        elif offset < 2 or nxt > end:
            raise bad(f"parameter {name!r} points outside the parameter section")
        body = name_end + 2
        if gid < 0:
            if body + 1 > nxt or body + 1 + data[body] > nxt:
                raise bad(f"the description of group {name!r} runs past its entry")
            groups[-gid] = name
        elif gid > 0:
            if body + 2 > nxt:
                raise bad(f"parameter {name!r} is cut short")
            dtype = struct.unpack("b", data[body:body + 1])[0]
            ndim = data[body + 1]
            if dtype not in (-1, 1, 2, 4):
                raise bad(f"parameter {name!r} has an unknown data type {dtype}")
            dims = tuple(data[body + 2:body + 2 + ndim])
            size = abs(dtype) * math.prod(dims)
            first = body + 2 + ndim
            if first + size > nxt:
                raise bad(f"parameter {name!r} declares {size} bytes of data, more than its entry holds")
            if first + size + 1 > nxt or first + size + 1 + data[first + size] > nxt:
                raise bad(f"the description of parameter {name!r} runs past its entry")
            if dtype in (1, 2, 4):
                raw_params.append((gid, name, dtype, dims, data[first:first + size]))
        if offset == 0:
            break
        pos = nxt
    params: dict[tuple[str, str], list] = {}
    for gid, name, dtype, _dims, raw in raw_params:
        n = len(raw) // abs(dtype)
        if dtype == 4:
            vals = [_float(raw[4 * i:4 * i + 4], order, dec) for i in range(n)]
        elif dtype == 2:
            vals = list(struct.unpack(f"{order}{n}h", raw))
        else:
            vals = list(raw)
        params[(groups.get(gid, "?"), name)] = vals
    return order, dec, params


def check_c3d(path: Path, max_bytes: int = 1 << 31) -> None:
    """Refuse a C3D whose header or parameters ask for more than the file holds (module doc)."""
    path = Path(path)
    size = path.stat().st_size
    if size > max_bytes:
        raise InputError(path, f"the C3D file is {size} bytes; at most {max_bytes} are read")
    with open(path, "rb") as handle:
        head = handle.read(BLOCK)
        if len(head) < BLOCK or head[1] != 0x50:
            raise InputError(path, "not a readable C3D file (no C3D header)")
        param_end = (head[0] - 1) * BLOCK + 4
        handle.seek(0)
        data = handle.read(max(param_end, 0) + 255 * BLOCK)
    order, dec, params = read_c3d_parameters(path, data)

    def word(i: int) -> int:  # 1-based 16-bit header word, unsigned
        return struct.unpack(order + "H", head[2 * (i - 1):2 * i])[0]

    def param(group: str, name: str, default: float) -> float:
        vals = params.get((group, name))
        return float(vals[0]) if vals else default

    n_points = max(word(2), int(param("POINT", "USED", 0)) & 0xFFFF)
    analog = word(3)
    frames_header = word(5) - word(4) + 1 if word(5) >= word(4) else 0
    frames = max(frames_header, int(param("POINT", "FRAMES", 0)) & 0xFFFF)
    scale = _float(head[12:16], order, dec)
    rate = param("POINT", "RATE", _float(head[20:24], order, dec))
    if not math.isfinite(rate) or not MIN_RATE <= rate <= MAX_RATE:
        raise InputError(path, f"the C3D frame rate {rate:g} Hz is outside {MIN_RATE:g}-"
                               f"{MAX_RATE:g} Hz")
    data_start = word(9)
    if data_start < 2:
        raise InputError(path, f"not a readable C3D file (data block {data_start})")
    item = 4 if (math.isfinite(scale) and scale < 0) or param("POINT", "SCALE", 1.0) < 0 else 2
    need = (data_start - 1) * BLOCK + frames * (n_points * 4 + analog) * item
    if need > size:
        raise InputError(path, f"not a readable C3D file ({n_points} points x {frames} frames "
                               f"need {need} bytes; the file has {size}: truncated or damaged)")
