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
from collections.abc import Iterator
from pathlib import Path

from servostudio.formats.textfile import write_bytes_atomic


def atomic_write(path: Path, data: bytes | str) -> None:
    """Replace ``path`` with ``data`` (text as UTF-8) in one step: `write_bytes_atomic`."""
    write_bytes_atomic(path, data.encode("utf-8") if isinstance(data, str) else data)


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
