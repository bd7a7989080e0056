"""Atomic file replacement and directory locks.

Every project file is written to a temporary file in the same directory and moved over the old one with
``os.replace``, so a reader never sees half a file. Concurrent writers (threads or processes, several API clients,
the CLI) are serialised with ``flock`` on the directory itself: no lock files end up in the project or in git.
``flock`` locks belong to an open file description, so two threads of one process exclude each other too.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path


def atomic_write(path: Path, data: bytes | str) -> None:
    """Replace ``path`` with ``data`` in one step (temp file in the same directory, fsync, ``os.replace``)."""
    payload = data.encode("utf-8") if isinstance(data, str) else data
    handle, temp_name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(payload)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(temp_name, _mode_of(path, 0o644))
        os.replace(temp_name, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temp_name)
        raise


def _mode_of(path: Path, default: int) -> int:
    """Keep the permissions of the file being replaced (``mkstemp`` would leave 0600)."""
    try:
        return path.stat().st_mode & 0o7777
    except FileNotFoundError:
        return default


@contextlib.contextmanager
def locked_directory(directory: Path, exclusive: bool = True) -> Iterator[os.stat_result]:
    """Hold an exclusive (writers) or shared (readers) lock on ``directory`` for the ``with`` block.

    Yields the directory's stat taken under the lock, so a caller can tell whether the path still names the
    directory it locked (it may have been renamed or deleted while the caller waited).
    """
    descriptor = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
        yield os.fstat(descriptor)
    finally:
        os.close(descriptor)


def is_same_directory(locked: os.stat_result, path: Path) -> bool:
    try:
        current = path.stat()
    except FileNotFoundError:
        return False
    return (current.st_dev, current.st_ino) == (locked.st_dev, locked.st_ino)
