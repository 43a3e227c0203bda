"""MATLAB v7.3 files (HDF5) as the dicts ``scipy.io.loadmat(simplify_cells=True)`` gives for older
ones, enough for MVIEW's struct arrays (:mod:`.mview`).

MATLAB's v7.3 layout: a variable is a dataset or (a struct) a group; a struct array's fields are
datasets of object references, one per element, to the values in ``#refs#``; arrays are stored
transposed (column-major); ``char`` is uint16 with ``MATLAB_class = 'char'``; an empty value is a
dataset of its dimensions with ``MATLAB_empty = 1``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError

#: Deeper than this, a file is refused (MVIEW nests two levels: channels, then PHONES).
MAX_DEPTH = 6
#: The largest value read (a damaged file may claim any size; MATLAB compresses, so the file's
#: own size is no bound): 512 MiB, 35 minutes of 16 sensors x 3 at 1250 Hz.
MAX_VALUE_BYTES = 512 << 20


def _class(obj) -> str:
    value = obj.attrs.get("MATLAB_class", b"")
    return value.decode("ascii", "replace") if isinstance(value, bytes) else str(value)


def _value(h5, obj, depth: int = 0):
    """A MATLAB value from a dataset or group."""
    import h5py

    if depth > MAX_DEPTH:
        raise ValueError("nested too deeply")
    if isinstance(obj, h5py.Group):
        return _struct(h5, obj, depth + 1)
    if obj.attrs.get("MATLAB_empty", 0):
        return np.zeros(0)
    if obj.size * obj.dtype.itemsize > MAX_VALUE_BYTES:
        raise ValueError(f"{obj.name} claims {obj.size * obj.dtype.itemsize} bytes")
    data = obj[()]
    if obj.dtype == h5py.ref_dtype:
        items = [_value(h5, h5[ref], depth + 1) for ref in np.asarray(data).T.ravel()]
        return items[0] if len(items) == 1 else items
    if _class(obj) == "char":
        return "".join(chr(c) for c in np.asarray(data).T.ravel() if c)
    array = np.asarray(data).T
    return array.reshape(-1) if 1 in array.shape and array.ndim == 2 else array


def _struct(h5, group, depth: int):
    """A struct (a dict) or struct array (a list of dicts: every field a dataset of references of
    one shape, not 1 x 1) from a group."""
    import h5py

    fields = {name: group[name] for name in group}
    refs = {n: f for n, f in fields.items()
            if isinstance(f, h5py.Dataset) and f.dtype == h5py.ref_dtype}
    shapes = {f.shape for f in refs.values()}
    if refs and len(refs) == len(fields) and len(shapes) == 1 and shapes != {(1, 1)}:
        count = next(iter(refs.values())).size
        out: list[dict] = [{} for _ in range(count)]
        for name, ds in refs.items():
            for i, ref in enumerate(np.asarray(ds[()]).T.ravel()):
                out[i][name] = _value(h5, h5[ref], depth + 1)
        return out
    return {name: _value(h5, f, depth + 1) for name, f in fields.items()}


def variables_v73(path: Path) -> dict:
    """The variables of a v7.3 (HDF5) file, as ``scipy.io.loadmat(simplify_cells=True)`` gives
    them for older files."""
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            variables = {name: _value(h5, h5[name]) for name in h5 if name != "#refs#"}
    except Exception as exc:  # h5py raises many kinds on a damaged file
        raise InputError(path, f"not a readable MATLAB v7.3 file ({str(exc).splitlines()[0][:120]})"
                         ) from None
    return variables
