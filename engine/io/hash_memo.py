"""Content hashes remembered across processes: a hash over many files (a corpus's data files, the
key of its cached model) is kept in the cache folder under the files' stamps (name, size,
modification and change times, inode), so that the next process knows it from ``stat`` alone
instead of reading every file (issue #15: the app's start reads no utterance it does not show).

Any difference in a stamp means the hash is computed again from the contents. Files changed in
the last :data:`RACY_S` seconds are not trusted by their stamps (a file system's clock is coarse,
so a second write within one tick can keep them; git's index has the same rule), and a memo that
cannot be read or written only costs the recomputation.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from ..errors import FacetrajError
from .cachedir import cache_dir
from .files import atomic_write

log = logging.getLogger(__name__)

MEMO_NAME = "content-hashes.json"
MAX_ENTRIES = 64
RACY_S = 2.0


def file_stamps(paths: Sequence[Path], extra: str = "") -> tuple[str, float]:
    """A digest of the stamps of ``paths`` (and of ``extra``), and the newest change time in them."""
    h = hashlib.sha256(extra.encode())
    newest = 0.0
    for p in paths:
        st = p.stat()
        h.update(f"\0{p.name}\0{st.st_size}\0{st.st_mtime_ns}\0{st.st_ctime_ns}\0{st.st_ino}".encode())
        newest = max(newest, st.st_mtime, st.st_ctime)
    return h.hexdigest(), newest


def memoized_hash(key: str, paths: Sequence[Path], compute: Callable[[], str], extra: str = "") -> str:
    """``compute()`` (a hash of the contents of ``paths`` and of ``extra``), or the value it had for
    the same stamps before, in this or an earlier process. ``key`` names the file set (a folder)."""
    stamp, newest = file_stamps(paths, extra)
    memo = _read()
    entry = memo.get(key)
    if isinstance(entry, dict) and entry.get("stamp") == stamp and isinstance(entry.get("hash"), str):
        return entry["hash"]
    value = compute()
    if time.time() - newest > RACY_S:
        memo.pop(key, None)
        memo[key] = {"stamp": stamp, "hash": value}
        _write(dict(list(memo.items())[-MAX_ENTRIES:]))
    return value


def _memo_path() -> Path:
    return cache_dir() / MEMO_NAME


def _read() -> dict:
    try:
        memo = json.loads(_memo_path().read_text(encoding="utf-8"))
    except FileNotFoundError:
        return {}
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        log.debug("ignoring the content-hash memo: %s", exc)
        return {}
    return memo if isinstance(memo, dict) else {}


def _write(memo: dict) -> None:
    try:
        with atomic_write(_memo_path()) as tmp:
            tmp.write_text(json.dumps(memo, indent=0), encoding="utf-8")
    except (OSError, FacetrajError) as exc:
        log.debug("could not remember content hashes in %s: %s", _memo_path(), exc)


def folder_key(folder: Path) -> str:
    """The memo key of the files of ``folder`` (its resolved path)."""
    return f"folder:{os.path.realpath(folder)}"
