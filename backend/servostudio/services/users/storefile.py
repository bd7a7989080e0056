"""The user store's file on disk: read whole, written whole and atomically, readable by its owner only (0600).

The server and ``servostudio user …`` / ``token …`` commands run against the same data directory may change it at
the same time: every change is read-modify-write under an exclusive lock (``flock`` on ``users.lock``; on Windows
one process at a time is the user's to ensure), and a reader never sees a half-written file (``os.replace``).
"""

from __future__ import annotations

import contextlib
import json
import os
import secrets
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from servostudio.errors import Unavailable

if sys.platform != "win32":
    import fcntl

PRIVATE_FILE = 0o600
PRIVATE_DIR = 0o700
_THREADS = threading.Lock()


class UserStoreUnreadable(Unavailable):
    """The user store exists but is not valid JSON of the expected shape: nobody can log in until it is fixed."""


@contextlib.contextmanager
def locked(path: Path) -> Iterator[None]:
    """Hold the store's lock (threads of this process, and other processes) for one read-modify-write."""
    _private_dir(path.parent)
    lock = path.with_name(path.name + ".lock")
    with _THREADS, open(lock, "a", encoding="utf-8") as handle:
        if sys.platform != "win32":
            fcntl.flock(handle, fcntl.LOCK_EX)
        yield


def read_json(path: Path) -> dict[str, Any] | None:
    """The file's object, or None when there is no file yet."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as error:
        raise UserStoreUnreadable(f"{path.name} cannot be read ({error}); fix or remove it") from None
    if not isinstance(data, dict):
        raise UserStoreUnreadable(f"{path.name} is not a JSON object; fix or remove it")
    return data


def write_json(path: Path, data: dict[str, Any]) -> None:
    """Replace the file atomically with ``data``; the new file is created 0600, never world-readable."""
    _remove_stale_temporaries(path)
    temporary = path.with_name(f".{path.name}.{secrets.token_hex(4)}.tmp")
    descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, PRIVATE_FILE)
    with os.fdopen(descriptor, "w", encoding="utf-8") as handle:
        json.dump(data, handle, indent=1)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(temporary, path)
    _sync_directory(path.parent)


def signature(path: Path) -> tuple[int, int, int] | None:
    """What changes when the file is replaced (a cached copy is stale when this differs)."""
    try:
        status = path.stat()
    except FileNotFoundError:
        return None
    return (status.st_ino, status.st_mtime_ns, status.st_size)


def _private_dir(folder: Path) -> None:
    folder.mkdir(mode=PRIVATE_DIR, parents=True, exist_ok=True)


def _remove_stale_temporaries(path: Path) -> None:
    """Temporaries of an interrupted write (the lock is held, so none is in progress)."""
    for stale in path.parent.glob(f".{path.name}.*.tmp"):
        stale.unlink(missing_ok=True)


def _sync_directory(folder: Path) -> None:
    if sys.platform == "win32":
        return
    descriptor = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)
