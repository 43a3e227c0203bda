"""Writing ``.npz`` archives: the file ``numpy.savez`` writes, byte for byte, without its copy of
every array (``numpy.lib.format.write_array`` writes to a zip member through ``tobytes``: 6.4 MB
of copies for a 60 s synthesis, 3 of its 7 ms; issue 28). Models and trajectories are saved
this way (numbers and text only: nothing is pickled), their disk blocks given before the bytes
are written (:func:`facetraj_engine.io.files.preallocated`)."""

from __future__ import annotations

import zipfile
from collections.abc import Mapping
from typing import BinaryIO

import numpy as np

from .files import preallocated

#: bytes a member adds to its data at most, about (zip headers and directory, ``.npy`` header)
_MEMBER_BYTES = 256


def write_npz(handle: BinaryIO, arrays: Mapping[str, np.ndarray]) -> None:
    """Write ``arrays`` as an uncompressed ``.npz`` archive to the open binary file ``handle``
    (the bytes of ``numpy.savez(handle, **arrays)``; an array in Fortran order is written in C
    order); an array of Python objects is refused.

    >>> import io
    >>> a = {"x": np.arange(3.0), "name": np.array("jaw")}
    >>> mine, theirs = io.BytesIO(), io.BytesIO()
    >>> write_npz(mine, a); np.savez(theirs, **a)
    >>> mine.getvalue() == theirs.getvalue()
    True
    >>> sorted((k, v.tolist()) for k, v in np.load(io.BytesIO(mine.getvalue())).items())
    [('name', 'jaw'), ('x', [0.0, 1.0, 2.0])]
    """
    fmt = np.lib.format
    arrays = {name: np.asarray(value) for name, value in arrays.items()}
    size = sum(arr.nbytes + _MEMBER_BYTES + 2 * len(name) for name, arr in arrays.items())
    with preallocated(handle, size), \
            zipfile.ZipFile(handle, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
        for name, arr in arrays.items():
            if arr.dtype.hasobject:
                raise ValueError(f"{name}: an array of Python objects is not saved (no pickle)")
            if not arr.flags.c_contiguous:
                arr = arr.copy(order="C")
            with zf.open(f"{name}.npy", "w", force_zip64=True) as member:
                fmt.write_array_header_1_0(member, fmt.header_data_from_array_1_0(arr))
                member.write(arr.reshape(-1).view(np.uint8))
