"""The trajectory writers (issue 28): TSV/CSV and C3D written without a Python loop over frames,
their content unchanged (the bytes ``numpy.savetxt`` and ``c3d``'s frame-by-frame writer
produced, and the values read back), and the NPZ's compression an option."""

import io
import warnings

import numpy as np
import pytest

from facetraj_engine.io.export import write_trajectories
from facetraj_engine.io.markerfiles import read_c3d, read_marker_table, write_c3d, write_marker_tsv
from facetraj_engine.io.numtext import fixed_point_lines

NAMES = [f"M{i}" for i in range(7)]


def _markers(frames=400, seed=0):
    return np.random.default_rng(seed).standard_normal((frames, len(NAMES), 3)) * 40.0


def _savetxt(table, decimals, sep="\t"):
    out = io.BytesIO()
    np.savetxt(out, table, delimiter=sep, fmt=[f"%.{d}f" for d in decimals])
    return out.getvalue()


@pytest.mark.parametrize("seed", range(12))
def test_fixed_point_lines_equal_savetxt_byte_for_byte(seed):
    """Random magnitudes, NaN, infinities, -0.0, exact halves, values near a half, huge ones."""
    rng = np.random.default_rng(seed)
    rows, cols = int(rng.integers(1, 150)), int(rng.integers(1, 10))
    t = rng.standard_normal((rows, cols)) * 10.0 ** rng.integers(-6, 12, (rows, cols))
    for value, share in ((np.nan, 0.02), (np.inf, 0.01), (-np.inf, 0.01), (-0.0, 0.02),
                         (1e17, 0.01), (2.5, 0.02), (-0.03125, 0.02), (1.00005, 0.03)):
        t[rng.random((rows, cols)) < share] = value
    decimals = rng.integers(0, 10, cols).tolist()
    assert fixed_point_lines(t, decimals) == _savetxt(t, decimals)
    assert fixed_point_lines(t, decimals, ",") == _savetxt(t, decimals, ",")


#: numbers whose text is easy to get wrong, each with its %.4f and %.6f text as Python writes it
TRICKY = [np.nan, -np.nan, np.inf, -np.inf, 0.0, -0.0, -0.00004, 0.00004, -0.00005, 0.00005,
          9999.99995, -9999.99995, 9999.9999, 10000.0, -10000.5, 100000000.00001, 1e-300,
          -1e-300, 5e-324, 123456789012.25, -98765432109.875, 2.0 ** 50 / 1e4, 2.0 ** 52,
          1e15, -1e17, 1e300, 0.125, 2.5e-5, 1.00005, 0.30000000000000004, 12345.6789]


@pytest.mark.parametrize("sep", ["\t", ","])
def test_tricky_numbers_are_written_as_python_writes_them(sep):
    """NaN (of either sign: ``nan``), infinities, negative zero and negative numbers that round
    to zero (``-0.0000``), halves and numbers next to them, integer parts of more than four
    digits (with zero groups inside), huge and tiny magnitudes; every number in every column
    position, at 0 to 12 decimals."""
    values = np.array(TRICKY)
    table = np.stack([np.roll(values, k) for k in range(4)], axis=1)     # (31, 4)
    for decimals in ([4, 4, 4, 4], [6, 4, 4, 4], [0, 1, 9, 12], [3, 3, 8, 8]):
        want = "".join(sep.join(f"%.{d}f" % x for x, d in zip(row, decimals, strict=True)) + "\n"
                       for row in table.tolist()).encode()
        assert fixed_point_lines(table, decimals, sep) == want
        assert fixed_point_lines(table, decimals, sep) == _savetxt(table, decimals, sep)


@pytest.mark.parametrize("seed", range(40))
def test_many_columns_of_mixed_decimals_equal_savetxt(seed):
    """Tables shaped like the trajectories' (a column of one precision, then many of another)
    and shuffled runs of decimals, magnitudes from 1e-6 to 1e9, some NaN."""
    rng = np.random.default_rng(100 + seed)
    rows, cols = int(rng.integers(1, 60)), int(rng.integers(1, 40))
    t = rng.standard_normal((rows, cols)) * 10.0 ** rng.integers(-6, 10, (rows, cols))
    t[rng.random((rows, cols)) < 0.02] = np.nan
    decimals = ([6] + [4] * (cols - 1)) if seed % 2 else rng.integers(0, 7, cols).tolist()
    assert fixed_point_lines(t, decimals, ",") == _savetxt(t, decimals, ",")


def test_line_ends_one_per_row_after_the_numbers():
    """``ends``: each line's own end (a labelled table's text columns); numbers Python writes (a
    half at the last decimal, one too long for any slot) in lines that end so too."""
    t = np.array([[0.125, 1.0], [2.0, 1e300], [np.nan, -0.0]])
    ends = [b",x\n", b",yy\n", b"\n"]
    want = b"".join(line + end for line, end in zip(_savetxt(t, [2, 1], ",").split(b"\n"), ends,
                                                      strict=False))
    assert fixed_point_lines(t, [2, 1], ",", ends) == want
    with pytest.raises(ValueError, match="2 line ends for 3 rows"):
        fixed_point_lines(t, [2, 1], ",", ends[:2])


@pytest.mark.parametrize("seed", range(5))
def test_blocks_side_by_side_are_the_joined_tables_lines(seed):
    """A trajectory table's time and coordinates as two blocks (not copied into one), an empty
    block among them, NaN: the lines of the table they make."""
    from facetraj_engine.io.numtext import fixed_point_blocks

    rng = np.random.default_rng(seed)
    t = np.arange(50)[:, None] / 60.0
    m = rng.standard_normal((50, 9)) * 10.0 ** rng.integers(-2, 6)
    m[rng.random(m.shape) < 0.05] = np.nan
    ends = [f",{i}\n".encode() for i in range(50)]
    for sep in ("\t", ","):
        want = fixed_point_lines(np.column_stack([t, m]), [6] + [4] * 9, sep)
        assert fixed_point_blocks([(t, 6), (np.zeros((50, 0)), 2), (m, 4)], sep) == want
        assert fixed_point_blocks([(t, 6), (m, 4)], sep, ends) == fixed_point_lines(
            np.column_stack([t, m]), [6] + [4] * 9, sep, ends)


def test_one_ascii_character_between_fields():
    with pytest.raises(ValueError, match="one ASCII character"):
        fixed_point_lines(np.zeros((2, 2)), [1, 1], ", ")
    with pytest.raises(ValueError, match="one ASCII character"):
        fixed_point_lines(np.zeros((2, 2)), [1, 1], "\u2192")
    assert fixed_point_lines(np.zeros((0, 3)), [1, 1, 1]) == b""


def _labelled_table(markers, rate, names, labels, sep):
    """The labelled table as it was written before issue 48: ``savetxt``'s text, then each
    line joined in Python with its labels (the reference)."""
    n = len(markers)
    table = np.column_stack([np.arange(n) / rate, markers.reshape(n, -1)])
    text = _savetxt(table, [6] + [4] * (table.shape[1] - 1), sep).decode()
    columns = [[str(v).replace(sep, " ").replace("\n", " ") for v in col] for col in labels.values()]
    header = sep.join(["time"] + [f"{m}_{a}" for m in names for a in "xyz"] + list(labels))
    body = "".join(sep.join([row, *(c[i] for c in columns)]) + "\n"
                   for i, row in enumerate(text.splitlines()))
    return (header + "\n" + body).encode()


@pytest.mark.parametrize("suffix", [".tsv", ".csv"])
def test_label_columns_are_the_reference_bytes(tmp_path, suffix):
    """The phone and word columns after the numbers (the app's trajectory export): labels that
    hold the separator, a newline, nothing, or letters beyond ASCII; NaN coordinates (a
    dropout) and a row with a number Python writes (a half at the 4th decimal)."""
    m = _markers(frames=50)
    m[4, 1] = np.nan
    m[7, 0, 2] = 0.00005
    phones = ["sil", "p", "a,b", "c\td", "", "e\nf", "ʃ", "aɪ"] * 6 + ["sil", "sil"]
    if suffix == ".tsv":
        phones[9] = "nul\0in it"                   # the writer's padding byte, kept as it was
    words = [f"word{i // 7}" if i % 9 else "" for i in range(50)]
    path = tmp_path / f"take{suffix}"
    write_marker_tsv(path, m, 60.0, NAMES, labels={"phone": phones, "word": words})
    sep = "," if suffix == ".csv" else "\t"
    want = _labelled_table(m, 60.0, NAMES, {"phone": phones, "word": words}, sep)
    assert path.read_bytes() == want
    assert path.read_bytes().count(b"\n") == 51
    np.testing.assert_allclose(read_marker_table(path).markers, m, atol=5e-5)


@pytest.mark.parametrize("suffix", [".tsv", ".csv"])
def test_marker_table_is_what_savetxt_wrote_and_reads_back(tmp_path, suffix):
    m = _markers()
    m[3, 2] = np.nan
    path = tmp_path / f"face{suffix}"
    write_marker_tsv(path, m, 60.0, NAMES)
    sep = "," if suffix == ".csv" else "\t"
    table = np.column_stack([np.arange(len(m)) / 60.0, m.reshape(len(m), -1)])
    header = sep.join(["time"] + [f"{n}_{a}" for n in NAMES for a in "xyz"])
    want = header.encode() + b"\n" + _savetxt(table, [6] + [4] * (table.shape[1] - 1), sep)
    assert path.read_bytes() == want
    back = read_marker_table(path)
    np.testing.assert_allclose(back.markers, m, atol=5e-5)
    assert np.isnan(back.markers[3, 2]).all() and back.names == NAMES


def _c3d_frame_by_frame(path, markers, rate, integer, names=NAMES):
    """``write_c3d`` as it was: every frame handed to ``c3d.Writer`` (the reference)."""
    import c3d

    from facetraj_engine.io.markerfiles import C3D_INT_SCALE

    finite = np.isfinite(markers).all(axis=2)
    if integer:
        q = np.round(markers / C3D_INT_SCALE) * C3D_INT_SCALE
        markers = q + np.copysign(C3D_INT_SCALE * 1e-3, q)
    writer = c3d.Writer(point_rate=float(rate), analog_rate=0.0,
                        point_scale=C3D_INT_SCALE if integer else -1.0, point_units="mm  ")
    frames = []
    for t in range(markers.shape[0]):
        p = np.zeros((markers.shape[1], 5))
        p[:, :3] = np.where(finite[t, :, None], markers[t], 0.0)
        p[:, 3] = np.where(finite[t], 0.0, -1.0)
        frames.append((p, np.zeros((0, 0))))
    writer.add_frames(frames)
    writer.set_point_labels(list(names))
    with open(path, "wb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        writer.write(handle)


@pytest.mark.parametrize("integer", [True, False])
def test_c3d_is_what_the_frame_by_frame_writer_wrote(tmp_path, integer):
    m = _markers(frames=300)
    write_c3d(tmp_path / "new.c3d", m, 60.0, NAMES, integer=integer)
    _c3d_frame_by_frame(tmp_path / "old.c3d", m, 60.0, integer)
    assert (tmp_path / "new.c3d").read_bytes() == (tmp_path / "old.c3d").read_bytes()


@pytest.mark.parametrize(("frames", "points", "rate", "integer"), [
    (1, 1, 60.0, True),            # the smallest file
    (2, 120, 59.94, False),        # a parameter section of several blocks, long and short names
    (37, 255, 200.0, True),        # the most points a C3D label parameter holds
    (65600, 1, 60.0, True),        # over 65,535 frames: POINT:LONG_FRAMES, the header's count capped
])
def test_c3d_layout_is_the_c3d_packages_for_every_size(tmp_path, frames, points, rate, integer):
    names = [f"P{i}" + "x" * (i % 9) for i in range(points)]
    m = np.random.default_rng(points).standard_normal((frames, points, 3)) * 40.0
    write_c3d(tmp_path / "new.c3d", m, rate, names, integer=integer)
    _c3d_frame_by_frame(tmp_path / "old.c3d", m, rate, integer, names)
    assert (tmp_path / "new.c3d").read_bytes() == (tmp_path / "old.c3d").read_bytes()
    back = read_c3d(tmp_path / "new.c3d")
    assert back.markers.shape == (frames, points, 3) and back.names == names


def test_c3d_refuses_more_points_than_it_can_name(tmp_path):
    from facetraj_engine.errors import InputError

    names = [f"P{i}" for i in range(256)]
    with pytest.raises(InputError, match="1 to 255 points"):
        write_c3d(tmp_path / "big.c3d", np.zeros((3, 256, 3)), 60.0, names)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("integer", [True, False])
def test_c3d_with_unseen_points_reads_back_the_same(tmp_path, integer):
    m = _markers(frames=200, seed=3)
    m[10:14, 2] = np.nan
    m[50] = np.nan
    write_c3d(tmp_path / "new.c3d", m, 60.0, NAMES, integer=integer)
    _c3d_frame_by_frame(tmp_path / "old.c3d", m, 60.0, integer)
    new, old = read_c3d(tmp_path / "new.c3d"), read_c3d(tmp_path / "old.c3d")
    np.testing.assert_array_equal(new.markers, old.markers)
    assert np.isnan(new.markers[10:14, 2]).all() and np.isnan(new.markers[50]).all()
    assert new.rate == old.rate == 60.0 and new.names == NAMES
    np.testing.assert_allclose(new.markers[0], m[0], atol=0.006 if integer else 1e-4)


@pytest.mark.parametrize("compress", [False, True])
def test_npz_compression_is_an_option_and_the_content_the_same(tmp_path, compress):
    m = _markers()
    path = tmp_path / "face.npz"
    write_trajectories(path, m, 60.0, NAMES, {"pcs": m[:, :2, 0]}, compress=compress)
    with np.load(path) as z:
        np.testing.assert_array_equal(z["markers"], m)
        np.testing.assert_array_equal(z["pcs"], m[:, :2, 0])
        assert z["marker_names"].tolist() == NAMES
    import zipfile

    with zipfile.ZipFile(path) as zf:
        kinds = {info.compress_type for info in zf.infolist()}
    assert kinds == ({zipfile.ZIP_DEFLATED} if compress else {zipfile.ZIP_STORED})
