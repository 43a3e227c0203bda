"""``engine.io.npz.write_npz``: numpy's ``.npz`` without numpy's copies."""

from __future__ import annotations

import io

import numpy as np
import pytest

from engine.io.npz import write_npz


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
