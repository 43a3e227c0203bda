"""``facetraj_engine.io.npz.write_npz``: numpy's ``.npz`` without numpy's copies."""

from __future__ import annotations

import io
import os

import numpy as np
import pytest

from facetraj_engine.io.npz import write_npz


def _arrays() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(0)
    return {"markers": rng.standard_normal((361, 54, 3)), "names": np.array(["UL_C", "LL_C"]),
            "which": np.array("synthesized"), "empty": np.zeros((0, 18)),
            "ids": np.arange(-5, 5, dtype=np.int64), "f32": rng.random(7).astype(np.float32),
            "flags": np.array([True, False]), "scalar": np.array(2.5)}


def test_the_bytes_are_numpys() -> None:
    mine, theirs = io.BytesIO(), io.BytesIO()
    write_npz(mine, _arrays())
    np.savez(theirs, **_arrays())
    assert mine.getvalue() == theirs.getvalue()


def test_a_view_in_another_order_reads_back_equal() -> None:
    base = np.arange(24.0).reshape(4, 6)
    arrays = {"fortran": np.asfortranarray(base), "strided": base[:, ::2], "t": base.T}
    out = io.BytesIO()
    write_npz(out, arrays)
    back = np.load(io.BytesIO(out.getvalue()))
    for name, value in arrays.items():
        assert back[name].shape == value.shape and np.array_equal(back[name], value)


def test_python_objects_are_refused() -> None:
    with pytest.raises(ValueError, match="Python objects"):
        write_npz(io.BytesIO(), {"bad": np.array([{"a": 1}], dtype=object)})


def test_a_file_on_disk_has_numpys_bytes_and_ends_where_they_end(tmp_path) -> None:
    """Written to a file, its disk blocks given first (``facetraj_engine.io.files.preallocated``, sized
    by a guess): the same bytes as in memory, the file cut where the archive ends, for a guess
    above the size (large arrays) and below it (many empty ones)."""
    for arrays in (_arrays(), {f"e{k}": np.zeros(0) for k in range(40)}):
        theirs = io.BytesIO()
        np.savez(theirs, **arrays)
        with open(tmp_path / "x.npz", "wb") as handle:
            write_npz(handle, arrays)
        assert (tmp_path / "x.npz").read_bytes() == theirs.getvalue()


def test_preallocated_gives_the_blocks_before_the_writes(tmp_path) -> None:
    """Where the system has fallocate, the blocks exist before a byte is written (ext4 then has
    nothing to write out when a rename replaces a file); the file is cut where writing stopped."""
    from facetraj_engine.io.files import _fallocate, preallocated

    path = tmp_path / "x.bin"
    with open(path, "wb") as handle, preallocated(handle, 1 << 20):
        before = os.fstat(handle.fileno()).st_blocks * 512
        handle.write(b"x" * 1000)
    assert path.read_bytes() == b"x" * 1000
    if _fallocate() is not None and before == 0:
        pytest.skip("this file system has no fallocate")
    assert before >= (1 << 20) or _fallocate() is None
    with open(path, "ab") as handle, preallocated(handle, 10):
        handle.write(b"yz")                                # an append is left as it is
    assert path.read_bytes() == b"x" * 1000 + b"yz"


def test_preallocated_leaves_a_pipe_and_memory_as_they_are() -> None:
    """Nothing to give blocks to: no fallocate, and no truncate (a pipe cannot be cut)."""
    from facetraj_engine.io.files import preallocated

    read, write = os.pipe()
    with open(write, "wb") as handle, preallocated(handle, 1 << 16):
        handle.write(b"through a pipe")
    with open(read, "rb") as handle:
        assert handle.read() == b"through a pipe"
    memory = io.BytesIO()
    write_npz(memory, _arrays())
    assert np.load(io.BytesIO(memory.getvalue()))["markers"].shape == (361, 54, 3)
