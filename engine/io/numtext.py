"""Tables of numbers as text, byte for byte what ``numpy.savetxt`` writes with ``%.Nf`` formats,
without formatting each number in Python (issue 28: ``savetxt`` was most of ``facetraj synth``'s
time on 60 s of speech to ``.tsv``).

Each number is rounded to its column's decimals as an integer, its digits are written into a
byte array all numbers at once (one pass per digit position), and the bytes of every field, right
aligned in a fixed width, are kept by a mask in row order. The few numbers that rounding in
floating point could put on the other side of a half (within 1e-6 of it), NaN, infinities and
numbers too large for exact integers are formatted by Python's ``%`` instead, their rows spliced
in.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np

#: ``|x| * 10**decimals`` at or above this is formatted by Python (the integers stay exact)
_EXACT_LIMIT = 2.0 ** 50
#: a scaled number this close to a half (x.5) is formatted by Python: the product ``x * 10**d``
#: is off by at most ~1e-9 below the limit above, far inside it
_TIE_MARGIN = 1e-6


def fixed_point_lines(table: np.ndarray, decimals: Sequence[int], sep: str = "\t") -> bytes:
    """The rows of ``table`` ``(rows, columns)`` as text lines: column ``j`` formatted as
    ``%.{decimals[j]}f``, fields separated by ``sep``, each line ending in a newline (what
    ``numpy.savetxt(f, table, fmt=[...], delimiter=sep)`` writes, tested byte for byte).

    >>> fixed_point_lines(np.array([[0.5, -0.00004, 12.34567], [1.0, np.nan, -3.0]]), [2, 4, 0])
    b'0.50\\t-0.0000\\t12\\n1.00\\tnan\\t-3\\n'
    """
    v = np.asarray(table, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != len(decimals):
        raise ValueError(f"table must be (rows, {len(decimals)}), got {v.shape}")
    rows, cols = v.shape
    if rows == 0 or cols == 0:
        return b"\n" * rows
    dec = np.broadcast_to(np.asarray(decimals, dtype=np.int64), v.shape).ravel()
    flat = v.ravel()
    with np.errstate(invalid="ignore", over="ignore"):
        scaled = np.abs(flat) * 10.0 ** dec
        python = ~(scaled < _EXACT_LIMIT) | (np.abs(scaled - np.floor(scaled) - 0.5) < _TIE_MARGIN)
    q = np.rint(np.where(python, 0.0, scaled)).astype(np.int64)
    chars = _fields(q, dec, np.signbit(flat) & ~python, sep).reshape(rows, cols, -1)
    chars[:, -1, -1] = ord("\n")
    bad_rows = np.flatnonzero(python.reshape(rows, cols).any(axis=1))
    if bad_rows.size == 0:
        return chars.tobytes().replace(b"\0", b"")
    pieces, at = [], 0
    for r in bad_rows.tolist():                   # the few rows with a number Python formats
        pieces += [chars[at:r].tobytes().replace(b"\0", b""), _python_line(v[r], decimals, sep)]
        at = r + 1
    pieces.append(chars[at:].tobytes().replace(b"\0", b""))
    return b"".join(pieces)


@functools.cache
def _four_digits() -> np.ndarray:
    """``"0000"`` to ``"9999"`` as 4-byte words: four digits written by one gather."""
    return np.array([f"{i:04d}" for i in range(10000)], dtype="S4").view(np.uint32)


def _groups(x: np.ndarray, n_groups: int) -> np.ndarray:
    """The ``4 n_groups`` decimal digits of ``x`` (with leading zeros) as bytes
    ``(4 n_groups, n)``: digit position first."""
    words = np.empty((n_groups, len(x)), dtype=np.uint32)
    for g in range(n_groups):
        words[g] = _four_digits()[(x // 10 ** (4 * (n_groups - 1 - g))) % 10000]
    return words.view(np.uint8).reshape(n_groups, len(x), 4).transpose(0, 2, 1).reshape(
        4 * n_groups, len(x))


def _fields(q: np.ndarray, dec: np.ndarray, negative: np.ndarray, sep: str) -> np.ndarray:
    """Every number's field in a fixed width ``(n, width)`` of bytes, zero where a byte is not
    part of it: the sign, the integer digits (leading zeros dropped), the point and ``dec``
    decimals (of the rounded ``|x| * 10**dec`` in ``q``), then ``sep``. Built by byte position
    (each a contiguous row), then turned to field order."""
    n = len(q)
    one_dec = int(dec[0]) if np.all(dec == dec[0]) else None
    whole, frac = np.divmod(q, 10 ** (one_dec if one_dec is not None else dec))
    small = np.int32 if int(whole.max(initial=0)) < 2 ** 31 and int(dec.max()) <= 9 else np.int64
    whole, frac = whole.astype(small), frac.astype(small)
    g_whole = max(1, -(-len(str(int(whole.max()))) // 4))
    g_frac = -(-int(dec.max()) // 4)
    w_whole, w_frac = 4 * g_whole, 4 * g_frac
    chars = np.empty((1 + w_whole + 1 + w_frac + 1, n), dtype=np.uint8)
    np.multiply(negative, ord("-"), out=chars[0], casting="unsafe")
    digits = np.ones(n, dtype=np.int32)
    for k in range(1, w_whole):
        digits += whole >= 10 ** k
    chars[1:1 + w_whole] = _groups(whole, g_whole)
    chars[1:1 + w_whole][np.arange(w_whole)[:, None] < w_whole - digits] = 0   # leading zeros
    np.multiply(dec > 0, ord("."), out=chars[1 + w_whole], casting="unsafe")
    if g_frac:
        shift = 10 ** (w_frac - (dec if one_dec is None else one_dec))
        wide = np.int64 if g_frac > 2 else small           # 12 digits do not fit in 32 bits
        chars[2 + w_whole:-1] = _groups(frac.astype(wide) * shift, g_frac)
        if one_dec is None or one_dec < w_frac:
            chars[2 + w_whole:-1][np.arange(w_frac)[:, None] >= dec] = 0          # past dec
    chars[-1] = ord(sep)
    return np.ascontiguousarray(chars.T)


def _python_line(row: np.ndarray, decimals: Sequence[int], sep: str) -> bytes:
    return (sep.join(f"%.{d}f" % x for x, d in zip(row.tolist(), decimals, strict=True))
            + "\n").encode()
