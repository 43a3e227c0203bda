"""Files written safely, and small text and JSON files.

Every writer of facetraj goes through :func:`atomic_write`, so an interrupted write never leaves a
half-written file where the user's file was; :func:`check_output_path` refuses an output that
cannot be written before any work is done.
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import stat
import tempfile
import threading
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

if TYPE_CHECKING:
    import numpy as np

from ..errors import InputError, OutputError, OutputExistsError

_NAME_MAX = 255  # bytes in one file name on the usual file systems


#: What an OS error while writing means, in words (instead of the raw errno text).
_WRITE_PROBLEMS = {
    errno.EACCES: "permission denied", errno.EPERM: "permission denied",
    errno.EROFS: "the file system is read-only", errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "the disk quota is exceeded", errno.ENAMETOOLONG: "the name is too long",
    errno.EISDIR: "it is a folder", errno.ENOTDIR: "a folder in the path is a file",
    errno.ENOENT: "the folder does not exist", errno.EFBIG: "the file would be too large",
}


def write_problem(exc: OSError) -> str:
    """The reason an output cannot be written, in words."""
    return _WRITE_PROBLEMS.get(exc.errno, exc.strerror or type(exc).__name__)


def check_output_path(path: str | os.PathLike[str], overwrite: bool = True,
                      formats: Sequence[str] | None = None, probe: bool = False) -> Path:
    """Refuse an output path that cannot be written, before any work is done: a suffix not among
    ``formats`` (lower case, with the dot; ``None``: any), an existing file without ``overwrite``
    (:class:`~facetraj_engine.errors.OutputExistsError`), a folder at the path, a parent that is a
    regular file, a name too long, a folder we may not write in; with ``probe``, a file is made
    and removed in the nearest folder that exists, so that a place that takes no new files (a
    read-only or special file system such as ``/proc``, a full disk) is named for what it is
    (issue 38), not found out after the work. Raises :class:`InputError` naming the path;
    returns it as a :class:`Path`."""
    path = Path(path)
    if formats is not None and path.suffix.lower() not in formats:
        names = [f for f in formats if f != ".txt"]
        listed = ", ".join(names[:-1]) + f" or {names[-1]}" if len(names) > 1 else names[0]
        raise OutputError(path, f"facetraj does not write {path.suffix or 'files without a suffix'}"
                                f"{' files' if path.suffix else ''} here: give a {listed} name")
    if len(os.fsencode(path.name)) > _NAME_MAX:
        raise OutputError(path, f"the file name is too long ({len(os.fsencode(path.name))} bytes; "
                               f"at most {_NAME_MAX})")
    if path.is_dir():
        raise OutputError(path, "a folder is at this path; give a file name")
    if path.exists() and not overwrite:
        raise OutputExistsError(path, "already exists; choose to overwrite it (--overwrite) or "
                                      "give another name")
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if folder.exists() and not folder.is_dir():
        raise OutputError(path, f"cannot be written: {folder} is a file, not a folder")
    if folder.is_dir() and not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(path, f"cannot be written: no permission to write in {folder}")
    if probe and folder.is_dir():
        try:
            fd, tmp = tempfile.mkstemp(prefix=".facetraj-probe-", dir=folder)
            os.close(fd)
            os.unlink(tmp)
        except OSError as exc:
            raise OutputError(path, f"cannot be written: {place_problem(folder, exc)}") from exc
    return path


def place_problem(folder: Path, exc: OSError) -> str:
    """Why no file can be made in ``folder``, which exists, in words (the error of making one).

    >>> place_problem(Path("/proc"), FileNotFoundError(errno.ENOENT, "No such file"))
    '/proc takes no new files (a special file system, such as /proc or /sys)'
    """
    if exc.errno in (errno.ENOENT, errno.EEXIST, errno.ENOTDIR) and folder.is_dir():
        return f"{folder} takes no new files (a special file system, such as /proc or /sys)"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return f"no permission to write in {folder}"
    if exc.errno == errno.EROFS:
        return f"the file system is read-only ({folder})"
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return f"{write_problem(exc)} in {folder}"
    return f"{write_problem(exc)} ({folder})"


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


class _TermToExit:
    """While a write is under way in the main thread, SIGTERM raises ``SystemExit(143)`` (as
    SIGINT raises KeyboardInterrupt), so the temporary file is removed; the previous handler is
    restored afterwards."""

    def __enter__(self):
        self.previous = None
        if threading.current_thread() is threading.main_thread():
            try:
                self.previous = signal.signal(signal.SIGTERM, self._raise)
            except ValueError:  # not the main interpreter
                self.previous = None
        return self

    @staticmethod
    def _raise(signum, frame):
        raise SystemExit(128 + signum)

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGTERM, self.previous)
        return False


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], overwrite: bool = True) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it into place only if the block succeeds.

    The file gets the mode of the file it replaces, or the user's umask for a new one. The
    temporary file is removed when the block fails, on Ctrl-C and on SIGTERM. Raises
    :class:`~facetraj_engine.errors.OutputExistsError` when ``path`` exists and ``overwrite`` is false, and
    :class:`InputError` naming ``path`` when it cannot be written (see :func:`check_output_path`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "x.txt"
    >>> with atomic_write(out) as tmp:
    ...     _ = tmp.write_text("done")
    >>> out.read_text()
    'done'
    """
    path = check_output_path(path, overwrite)
    try:
        mode = stat.S_IMODE(path.stat().st_mode) if path.exists() else 0o666 & ~_umask()
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem[:40]}.part-", suffix=path.suffix[:20],
                                   dir=path.parent)
        os.close(fd)
    except OSError as exc:
        where = path.parent if path.parent.is_dir() else None
        raise OutputError(path, f"cannot be written: {place_problem(where, exc)}" if where
                          else f"cannot be written ({write_problem(exc)})") from exc
    tmp_path = Path(tmp)
    try:
        with _TermToExit():
            try:
                yield tmp_path
                os.chmod(tmp_path, mode)
                os.replace(tmp_path, path)
            except OSError as exc:
                if isinstance(exc, InputError):
                    raise
                raise OutputError(path, f"cannot be written ({write_problem(exc)})") from exc
    finally:
        with contextlib.suppress(OSError):
            if tmp_path.exists():
                tmp_path.unlink()


def write_bytes(path: str | os.PathLike[str], *data: bytes) -> None:
    """``data`` (one or more pieces, one after the other) written to ``path`` (the temporary file
    of :func:`atomic_write`)."""
    with open(path, "wb") as handle:
        for piece in data:
            handle.write(piece)


def write_npz(handle: BinaryIO, arrays: Mapping[str, np.ndarray]) -> None:
    """``arrays`` as an uncompressed ``.npz`` archive (``numpy.savez``) to the open binary file
    ``handle``; an array of Python objects is refused (models and trajectories hold numbers and
    text only: nothing is pickled, nothing is unpickled when they are read).

    >>> import io
    >>> import numpy as np
    >>> out = io.BytesIO()
    >>> write_npz(out, {"x": np.arange(3.0), "name": np.array("jaw")})
    >>> sorted((k, v.tolist()) for k, v in np.load(io.BytesIO(out.getvalue())).items())
    [('name', 'jaw'), ('x', [0.0, 1.0, 2.0])]
    """
    import numpy as np  # not for the command's start: only where arrays are

    arrays = {name: np.asarray(value) for name, value in arrays.items()}
    for name, arr in arrays.items():
        if arr.dtype.hasobject:
            raise ValueError(f"{name}: an array of Python objects is not saved (no pickle)")
    np.savez(handle, **arrays)


def write_json(path: str | os.PathLike[str], data: object, overwrite: bool = True) -> Path:
    """Write ``data`` as indented JSON (UTF-8, a final newline) through :func:`atomic_write`.

    >>> import tempfile, pathlib
    >>> out = write_json(pathlib.Path(tempfile.mkdtemp()) / "r.json", {"r": 0.87})
    >>> out.read_text().splitlines()
    ['{', ' "r": 0.87', '}']
    """
    import json

    path = Path(path)
    with atomic_write(path, overwrite) as tmp:
        tmp.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return path


def read_json(path: str | os.PathLike[str]) -> object | None:
    """The JSON value in the file at ``path`` (what :func:`write_json` wrote), or ``None`` when
    there is no such file.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> read_json(write_json(folder / "r.json", {"r": 0.87})), read_json(folder / "none.json")
    ({'r': 0.87}, None)
    """
    import json

    path = Path(path)
    if not path.is_file():
        return None
    return json.loads(path.read_text(encoding="utf-8"))


#: the largest text file read (a label file, a marker table): its text and what is parsed from
#: it stay well under the 2 GB that no input may make facetraj allocate
MAX_TEXT_BYTES = 256 << 20


def read_text(path: Path, what: str = "label file") -> str:
    """The text of a small file (UTF-8, or UTF-16 with a byte-order mark); ``what`` names the
    kind of file in the error for a missing one."""
    if not path.exists():
        raise InputError(path, f"no such {what}")
    if path.is_dir():
        raise InputError(path, "is a folder, not a file")
    size = path.stat().st_size
    if size > MAX_TEXT_BYTES:
        raise InputError(path, f"is {size} bytes, more than facetraj reads as a {what} (at most "
                               f"{MAX_TEXT_BYTES >> 20} MiB)")
    raw = path.read_bytes()
    try:
        if raw.startswith((b"\xff\xfe", b"\xfe\xff")):  # UTF-16 (Praat writes it) only with a BOM
            return raw.decode("utf-16")
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(path, "the file is not UTF-8 (or UTF-16) text") from None
