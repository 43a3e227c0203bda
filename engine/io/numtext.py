"""Tables of numbers as text, byte for byte what ``numpy.savetxt`` writes with ``%.Nf`` formats,
without formatting each number in Python (issue 28: ``savetxt`` was most of ``facetraj synth``'s
time on 60 s of speech to ``.tsv``; issue 48: the same bytes, fewer passes).

Each number is rounded to its column's decimals as an integer, and its field is written into a
fixed-width slot of bytes, right aligned, with NUL bytes where it is shorter: four digits at a
time (one gather from a table of ``"0000"`` to ``"9999"``, the leading zeros of the integer part
NUL), a run of columns of the same decimals at once. The NULs are then deleted in one pass
(``bytes.translate``). NaN and the infinities are written as Python writes them (``nan``,
``inf``, ``-inf``); the few numbers that rounding in floating point could put on the other side
of a half (within 1e-6 of it) and numbers too large for exact integers are formatted by Python's
``%`` instead, their rows spliced in.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from itertools import pairwise

import numpy as np

#: ``|x| * 10**decimals`` at or above this is formatted by Python (the integers stay exact)
_EXACT_LIMIT = 2.0 ** 50
#: a scaled number this close to a half (x.5) is formatted by Python: the product ``x * 10**d``
#: is off by at most ~1e-9 below the limit above, far inside it
_TIE_MARGIN = 1e-6
_NAN, _INF = np.frombuffer(b"nan", np.uint8), np.frombuffer(b"inf", np.uint8)


def fixed_point_lines(table: np.ndarray, decimals: Sequence[int], sep: str = "\t",
                      ends: Sequence[bytes] | None = None) -> bytes:
    """The rows of ``table`` ``(rows, columns)`` as text lines: column ``j`` formatted as
    ``%.{decimals[j]}f``, fields separated by ``sep`` (one character), each line ending in a
    newline (what ``numpy.savetxt(f, table, fmt=[...], delimiter=sep)`` writes, tested byte for
    byte), or in its own of ``ends`` (one per row: e.g. its text columns, then a newline).

    >>> fixed_point_lines(np.array([[0.5, -0.00004, 12.34567], [1.0, np.nan, -3.0]]), [2, 4, 0])
    b'0.50\\t-0.0000\\t12\\n1.00\\tnan\\t-3\\n'
    >>> fixed_point_lines(np.array([[0.5], [2.0]]), [1], ",", [b",a\\n", b",b\\n"])
    b'0.5,a\\n2.0,b\\n'
    """
    v = np.asarray(table, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != len(decimals):
        raise ValueError(f"table must be (rows, {len(decimals)}), got {v.shape}")
    dec = np.asarray(decimals, dtype=np.int64)
    return fixed_point_blocks([(v[:, a:b], int(dec[a])) for a, b in _runs(dec)], sep, ends,
                              rows=len(v))


def fixed_point_blocks(blocks: Sequence[tuple[np.ndarray, int]], sep: str = "\t",
                       ends: Sequence[bytes] | None = None, rows: int | None = None) -> bytes:
    """:func:`fixed_point_lines` of the columns of ``blocks`` side by side, each ``(table,
    decimals)``: a table ``(rows, k)`` whose columns have these decimals (a trajectory table's
    time and its coordinates, without copying them into one; ``rows``: when there is no block).

    >>> fixed_point_blocks([(np.array([[0.0], [0.5]]), 3), (np.array([[1.0, -2.0], [3.0, 4.0]]), 1)])
    b'0.000\\t1.0\\t-2.0\\n0.500\\t3.0\\t4.0\\n'
    """
    tables = [np.asarray(t, dtype=np.float64) for t, _ in blocks]
    rows = len(tables[0]) if tables else (rows or 0)
    if len(sep) != 1 or not sep.isascii() or any(t.ndim != 2 or len(t) != rows for t in tables):
        raise ValueError(f"blocks must be tables of {rows} rows and sep one ASCII character, got "
                         f"{[t.shape for t in tables]} and {sep!r}")
    if ends is not None and len(ends) != rows:
        raise ValueError(f"{len(ends)} line ends for {rows} rows")
    if rows == 0 or not any(t.shape[1] for t in tables):
        return b"".join(ends) if ends is not None else b"\n" * rows
    if ends is not None and b"\0" in b"".join(ends):  # NUL is the padding: line by line
        lines = fixed_point_blocks(blocks, sep).split(b"\n")[:rows]
        return b"".join(line + end for line, end in zip(lines, ends, strict=True))
    found = [(v, int(d), *_rounded(v, int(d), np.isfinite(v)))
             for v, (_, d) in zip(tables, blocks, strict=True) if v.shape[1]]
    widths = [_width(q, d) * v.shape[1] for v, d, q, _ in found]
    end_bytes = 0 if ends is None else max(map(len, ends))
    chars = np.zeros((rows, sum(widths) + end_bytes), dtype=np.uint8)
    spliced, at = set(), 0
    for (v, d, q, python), width in zip(found, widths, strict=True):   # each block's columns
        slots = chars[:, at:at + width].reshape(rows, v.shape[1], -1)
        _fill(slots, q, np.signbit(v), np.isfinite(v), v, d, sep)
        spliced |= _python_fields(slots, python, v, d)
        at += width
    if ends is None:                          # the last separator: the line's end
        chars[:, -1] = ord("\n")
    else:                                     # or the line's own end, NUL-padded
        chars[:, at - 1] = 0
        chars[:, at:] = np.array(ends, dtype=f"S{end_bytes}").view(np.uint8).reshape(
            rows, end_bytes)
    pieces, at = [], 0
    for r in sorted(spliced):                 # rows with a number too long for its slot
        pieces += [chars[at:r].tobytes().translate(None, b"\0"),
                   _python_line([(v[r], d) for v, d, _, _ in found], sep)
                   + (b"\n" if ends is None else ends[r])]
        at = r + 1
    pieces.append(chars[at:].tobytes().translate(None, b"\0"))
    return b"".join(pieces) if len(pieces) > 1 else pieces[0]


def _rounded(v: np.ndarray, dec: int, finite: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each number times ``10**dec`` rounded to an integer (0 where Python writes it, and for
    NaN and the infinities; int32 when every one fits), and where Python writes it: a half
    within the margin, or too large (``|scaled - q|`` is exact, as is ``0.5`` minus it)."""
    with np.errstate(invalid="ignore", over="ignore"):
        scaled = np.abs(v)
        scaled *= 10.0 ** dec
        python = scaled >= _EXACT_LIMIT
        q = np.rint(scaled)
        np.subtract(scaled, q, out=scaled)
        np.abs(scaled, out=scaled)
        python |= scaled > 0.5 - _TIE_MARGIN
    python &= finite
    q[python | ~finite] = 0.0
    small = q.max(initial=0.0) < 2.0 ** 31 and dec <= 8
    return q.astype(np.int32 if small else np.int64), python


def _width(q: np.ndarray, dec: int) -> int:
    """The slot of a field of ``dec`` decimals whose rounded numbers are ``q``: the sign, the
    integer part's groups of four digits, the point, the decimals' groups, the separator."""
    g_whole = max(1, -(-len(str(int(q.max(initial=0)) // 10 ** dec)) // 4))
    return 1 + 4 * g_whole + 1 + 4 * -(-dec // 4) + 1


def _runs(dec: np.ndarray) -> list[tuple[int, int]]:
    """``[a, b)`` of the runs of neighbouring columns with the same decimals."""
    edges = [0, *(np.flatnonzero(np.diff(dec)) + 1).tolist(), len(dec)]
    return list(pairwise(edges))


@functools.cache
def _digit_words() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``"0000"`` to ``"9999"`` as 4-byte words (four digits written by one gather); the same
    with leading zeros NUL, ``"0"`` kept for 0 (the integer part's first group); and with every
    zero NUL for 0 (a first group above others).

    >>> [bytes(w[[0, 7, 120, 9999]]).replace(b"\\0", b"_") for w in _digit_words()]
    [b'0000000701209999', b'___0___7_1209999', b'_______7_1209999']
    """
    i = np.arange(10000)
    digits = (i[:, None] // np.array([1000, 100, 10, 1]) % 10 + ord("0")).astype(np.uint8)
    full = np.ascontiguousarray(digits).view(np.uint32)[:, 0]
    lead = digits.copy()
    lead[:, :3][i[:, None] < np.array([1000, 100, 10])] = 0         # leading zeros, not the last
    inner = lead.copy()
    inner[0] = 0
    return full, lead.view(np.uint32)[:, 0], inner.view(np.uint32)[:, 0]


def _words(slots: np.ndarray, at: int, words: np.ndarray) -> None:
    """Write ``words`` ``(rows, cols)`` of 4 bytes into every slot at byte ``at``."""
    slots[:, :, at:at + 4].view(np.uint32)[..., 0] = words


def _fill(slots: np.ndarray, q: np.ndarray, negative: np.ndarray, finite: np.ndarray,
          v: np.ndarray, dec: int, sep: str) -> None:
    """Write the fields of a run of columns of ``dec`` decimals into ``slots`` ``(rows, cols,
    width)`` (zeros, :func:`_width` wide): the sign (``negative``), the integer digits and
    ``dec`` decimals of ``q`` (the numbers ``v`` times ``10**dec``, rounded), the point, then
    ``sep``, right aligned, NUL where not part of the field; NaN and the infinities (not
    ``finite``) by name."""
    width = slots.shape[2]
    g_frac = -(-dec // 4)
    w_frac = 4 * g_frac
    g_whole = (width - 3 - w_frac) // 4
    w_whole = 4 * g_whole
    whole, frac = np.divmod(q, 10 ** dec)
    np.multiply(negative, np.uint8(ord("-")), out=slots[:, :, 0])
    full, lead, inner = _digit_words()
    above_zero = None                         # the integer groups so far are all zero
    for g in range(g_whole):
        group = (whole // 10 ** (4 * (g_whole - 1 - g))) % 10000 if g_whole > 1 else whole
        first = (lead if g == g_whole - 1 else inner)[group]
        _words(slots, 1 + 4 * g, first if above_zero is None else
               np.where(above_zero, first, full[group]))
        above_zero = group == 0 if above_zero is None else above_zero & (group == 0)
    if dec:
        slots[:, :, 1 + w_whole] = ord(".")
        if w_frac > dec:
            frac = frac * 10 ** (w_frac - dec)
        for g in range(g_frac):
            _words(slots, 2 + w_whole + 4 * g,
                   full[(frac // 10 ** (4 * (g_frac - 1 - g))) % 10000 if g_frac > 1 else frac])
        slots[:, :, 2 + w_whole + dec:-1] = 0
    slots[:, :, -1] = ord(sep)
    if not finite.all():                      # nan, inf, -inf: as Python writes them
        at = np.nonzero(~finite)
        nan = np.isnan(v[at])
        slots[at[0], at[1], 1:-1] = 0
        slots[at[0], at[1], 0] *= ~nan                  # -inf's sign, not -nan's
        slots[at[0], at[1], 2:5] = np.where(nan[:, None], _NAN, _INF)


def _python_fields(slots: np.ndarray, python: np.ndarray, v: np.ndarray, dec: int) -> set[int]:
    """Write the numbers of a run that Python formats (``python``: a half within the margin, or
    too large) into their slots as Python writes them; the rows of those too long for their
    slot (spliced in whole by the caller)."""
    too_long = set()
    width = slots.shape[2]
    for r, c in zip(*np.nonzero(python), strict=True):
        text = (f"%.{dec}f" % v[r, c]).encode()
        if len(text) < width:
            slots[r, c, :-1] = 0
            slots[r, c, width - 1 - len(text):-1] = np.frombuffer(text, np.uint8)
        else:
            too_long.add(int(r))
    return too_long


def _python_line(fields: Sequence[tuple[np.ndarray, int]], sep: str) -> bytes:
    """A line's numbers as Python writes them: ``fields`` its blocks' values and decimals."""
    return sep.join(f"%.{d}f" % x for values, d in fields for x in values.tolist()).encode()
