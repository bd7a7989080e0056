"""Text I/O shared by the drive files: their encoding, their line splitting, and atomic replacement."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

#: The drive files are 8-bit text; Latin-1 maps every byte, so reading never fails and writing keeps bytes.
FILE_ENCODING = "latin-1"


def split_lines(text: str) -> list[str]:
    """Split at LF (dropping a CR before it), the way the drive counts lines.

    ``str.splitlines`` would also split at characters such as U+0085 that Latin-1 decoding produces from an
    ordinary byte, and then the line numbers in error messages would no longer match the file.
    """
    return [line.removesuffix("\r") for line in text.split("\n")]


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (Latin-1) atomically: see `write_bytes_atomic`."""
    write_bytes_atomic(path, text.encode(FILE_ENCODING))


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to a temporary file next to ``path`` (``.NAME.*.tmp``), flush it to disk, then rename it over
    ``path`` and flush the directory.

    ``os.replace`` within one directory is atomic, so ``path`` holds either the old or the new content, never a
    mix, even if the process dies mid-write; what such a death leaves is only the temporary file, which the project
    store removes at the next start.
    """
    target = Path(path)
    descriptor, temp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(descriptor, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(temp_name, _mode_for(target))
        os.replace(temp_name, target)
    except BaseException:
        Path(temp_name).unlink(missing_ok=True)
        raise
    _sync_directory(target.parent)


def _sync_directory(directory: Path) -> None:
    """Make the rename itself durable (a power loss after it must not bring the old file back)."""
    descriptor = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


def _mode_for(target: Path) -> int:
    """Keep the permissions of the file being replaced; a new file gets the usual rw-r--r--.

    (``mkstemp`` creates 0600 files; reading the umask would mean changing it, which is not thread-safe.)
    """
    try:
        return target.stat().st_mode & 0o7777
    except FileNotFoundError:
        return 0o644
