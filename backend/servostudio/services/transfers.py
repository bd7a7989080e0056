"""Backup and restore as the communication server runs them: many drives of one bus in parallel as jobs (their
progress events name the bus), or one file of one drive to and from text.

A job's result is per node: the list of file results, or ``{"error": message}`` for a node that failed; the other
nodes go on, and the job ends ``partial`` (some nodes failed) or ``failed`` (all did).  The file work itself is
``services.backup``.

The server reads and writes backups only below its own directories (the project store and the export directory of
its settings, ``Settings.transfer_roots``), so a request cannot name an arbitrary server path.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from servostudio.drive.access import Drive
from servostudio.errors import InvalidInput, ServoStudioError
from servostudio.formats.textfile import FILE_ENCODING
from servostudio.services.backup import (
    BackupResult,
    FileKind,
    Progress,
    RestoreResult,
    backup_drive,
    backup_file,
    restore_drive,
    restore_text,
    run_per_drive,
)
from servostudio.services.bus import BusConnection, Job, JobRegistry, UnitResults
from servostudio.services.cancel import Cancellation

FileResult = BackupResult | RestoreResult


class DirectoryRefused(InvalidInput):
    """A backup or restore directory outside the project store and the export directory."""


def target_directory(directory: str, roots: Sequence[Path]) -> Path:
    """The directory a request names (absolute, or relative to the server's working directory), refused without
    echoing any server path when it is not inside one of ``roots`` (symbolic links resolved first)."""
    try:
        target = Path(directory).resolve()
    except (OSError, RuntimeError, ValueError):  # a symbolic link loop, a NUL byte
        raise DirectoryRefused("the backup directory is not a usable path") from None
    if not any(target.is_relative_to(root.resolve()) for root in roots):
        raise DirectoryRefused("the backup directory must be inside the project store or the server's export directory")
    return target


def file_kind(name: str) -> FileKind:
    """A drive file by its name (case-insensitive): DRIVEPAR.TXT, USER_PAR.TXT or SEQUENCE.TXT."""
    try:
        return FileKind(name.upper())
    except ValueError:
        raise InvalidInput(f"files must be among {', '.join(kind.value for kind in FileKind)}") from None


def start_backup(
    jobs: JobRegistry,
    connection: BusConnection,
    roots: Sequence[Path],
    directory: str,
    nodes: list[int] | None,
    files: list[str] | None,
) -> Job:
    """Back up drives in parallel into ``DIRECTORY/node<N>/`` (default: every node of the last scan, every file)."""
    chosen, kinds, root = _nodes(connection, nodes), _kinds(files), target_directory(directory, roots)

    def backup_one(drive: Drive, progress: Progress, cancel: Cancellation) -> Sequence[FileResult]:
        return backup_drive(drive, root / f"node{drive.node}", kinds, progress, cancel)

    return jobs.start("backup", _per_drive(connection, chosen, backup_one))


def start_restore(
    jobs: JobRegistry,
    connection: BusConnection,
    roots: Sequence[Path],
    directory: str,
    nodes: list[int] | None,
    files: list[str] | None,
    store: bool,
) -> Job:
    """Restore drives in parallel from ``DIRECTORY/node<N>/`` (validated first, verified, stored)."""
    chosen, kinds, root = _nodes(connection, nodes), _kinds(files), target_directory(directory, roots)

    def restore_one(drive: Drive, progress: Progress, cancel: Cancellation) -> Sequence[FileResult]:
        return restore_drive(drive, root / f"node{drive.node}", kinds, progress, store, cancel)

    return jobs.start("restore", _per_drive(connection, chosen, restore_one))


def download(drive: Drive, kind: FileKind) -> tuple[str, dict[str, object]]:
    """Back up one file of one drive now: its text, and the backup's result (objects, skipped) without the server's
    temporary path."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / kind.value
        result = backup_file(drive, path, kind)
        return path.read_text(encoding=FILE_ENCODING), {**result.as_dict(), "file": kind.value}


def upload(drive: Drive, kind: FileKind, data: bytes, store: bool) -> RestoreResult:
    """Restore an uploaded file to the drive (validated first: an invalid line writes nothing)."""
    return restore_text(drive, data.decode(FILE_ENCODING), kind, store=store)


def start_upload(
    jobs: JobRegistry, connection: BusConnection, drive: Drive, kind: FileKind, data: bytes, store: bool
) -> Job:
    """The uploaded file restored by a cancellable job; its result is ``{node: [restore result]}`` like a restore
    job's."""
    text = data.decode(FILE_ENCODING)

    def work(progress: Progress, cancel: Cancellation) -> object:
        result = restore_text(drive, text, kind, _on_bus(progress, connection), store, cancel)
        return node_results({drive.node: [result]})

    return jobs.start("restore", work)


def _kinds(names: Sequence[str] | None) -> list[FileKind] | None:
    return [file_kind(name) for name in names] if names is not None else None


def _nodes(connection: BusConnection, nodes: list[int] | None) -> list[int]:
    chosen = nodes if nodes is not None else sorted(connection.nodes)
    if not chosen:
        raise InvalidInput(f"no nodes given and none known on bus {connection.id}: scan the bus first")
    return chosen


def _per_drive(
    connection: BusConnection, nodes: list[int], work: Callable[[Drive, Progress, Cancellation], Sequence[FileResult]]
) -> Callable[[Progress, Cancellation], object]:
    """A job's work: ``work`` on every node's drive in parallel, the result per node."""

    def run(progress: Progress, cancel: Cancellation) -> object:
        drives = [connection.drive(node) for node in nodes]
        on_bus = _on_bus(progress, connection)
        return node_results(run_per_drive(drives, lambda drive: work(drive, on_bus, cancel)))

    return run


def node_results(results: Mapping[int, Sequence[FileResult] | Exception]) -> UnitResults:
    """A job's result per node (`per_node`), with the nodes that failed: the job is partial or failed by them."""
    failures = [failure for node, outcome in results.items() if (failure := node_failure(node, outcome))]
    return UnitResults(per_node(results), len(results), tuple(failures))


def node_failure(node: int, outcome: Sequence[FileResult] | Exception) -> str | None:
    """Why a node's work failed — its error, or a restore that did not complete — or None when it succeeded."""
    if isinstance(outcome, Exception):
        return f"node {node}: {_shown_error(outcome)}"
    incomplete = [item for item in outcome if isinstance(item, RestoreResult) and not item.ok]
    if incomplete:
        return f"node {node}: {incomplete[0].error or f'{incomplete[0].kind} restore not verified'}"
    return None


def per_node(results: Mapping[int, Sequence[FileResult] | Exception]) -> dict[str, object]:
    """Per node: its file results, or ``{"error": …}`` when it failed."""
    shown: dict[str, object] = {}
    for node, outcome in results.items():
        if isinstance(outcome, Exception):
            shown[str(node)] = {"error": _shown_error(outcome)}
        else:
            shown[str(node)] = [item.as_dict() for item in outcome]
    return shown


def _shown_error(error: Exception) -> str:
    """A node's error as its result shows it; one outside the taxonomy (a bug, logged by `run_per_drive`) may name
    server paths, so only its class is shown."""
    if isinstance(error, ServoStudioError):
        return str(error)
    return f"internal error ({type(error).__name__}); the server log has the details"


def _on_bus(progress: Progress, connection: BusConnection) -> Progress:
    return lambda event: progress({**event, "bus": connection.id})
