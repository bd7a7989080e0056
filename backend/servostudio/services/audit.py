"""The audit log: who wrote what to which drive or project, and every motion start and stop, one JSON line each.

A commissioning server moves motors and overwrites drives, so afterwards someone must be able to say who did what:
every write to a drive (user, client, axis, object, old → new, result — refusals included), every change of a
project's values, and every arm, enable, stop, quick stop on a lost client and take-over.  The file is append-only
(``Settings.audit_file``, JSON lines): nothing in the product rewrites or shortens it, and a line is written with
one ``write`` on a file opened for appending, so concurrent writers never interleave inside a line.

*Who* is the :class:`Actor` of the work in progress: the API sets it for each request (``api.deps``), the CLI for
each command, the terminal for each message, and work a request starts (jobs, per-drive threads) carries it along
as a context variable.  ``docs/security.md`` (Audit log) describes the format.
"""

from __future__ import annotations

import contextlib
import contextvars
import csv
import fcntl
import io
import json
import os
import threading
import time
from collections import deque
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path

from servostudio.errors import InvalidInput
from servostudio.formats.parameterfile import parse_drive_file
from servostudio.formats.textfile import FILE_ENCODING

#: the columns of an entry, in the order CSV exports them
FIELDS = (
    "seq",
    "time",
    "user",
    "client",
    "action",
    "axis",
    "project",
    "project_axis",
    "object",
    "name",
    "old",
    "new",
    "result",
    "detail",
)
#: the project files whose changes are logged object by object (``formats.objectfile``)
OBJECT_FILES = frozenset({"DRIVEPAR.TXT", "USER_PAR.TXT", "TTAPAR.TXT"})
#: what a log without a file keeps in memory (a tool or test that gave no data directory)
MEMORY_ENTRIES = 10_000
MAX_PAGE = 1000


@dataclass(frozen=True)
class Actor:
    """Who is acting: a user (name and level) and the live client they act through, which motion needs."""

    user: str
    level: str = "administrator"
    client: str | None = None


#: nobody said who acts: the guard treats it as a caller without a live client, the log names it so
ANONYMOUS = Actor(user="anonymous", level="operator")
#: the server acting on its own behalf (the quick stop of an axis whose controller went away)
SERVER = Actor(user="server", level="administrator")

_acting: contextvars.ContextVar[Actor] = contextvars.ContextVar("servostudio_actor", default=ANONYMOUS)


def current_actor() -> Actor:
    """Who the work in progress is done for (``ANONYMOUS`` when no entry point said)."""
    return _acting.get()


def act_as(actor: Actor) -> None:
    """``actor`` acts for the rest of the current context (an API request's task: everything it runs)."""
    _acting.set(actor)


@contextlib.contextmanager
def acting_as(actor: Actor) -> Iterator[Actor]:
    """``actor`` acts inside the block (a CLI command, a terminal message, a quick stop)."""
    token = _acting.set(actor)
    try:
        yield actor
    finally:
        _acting.reset(token)


def axis_name(bus: str, node: int) -> str:
    """An axis as entries and filters name it: ``BUS:NODE``."""
    return f"{bus}:{node}"


def printable(value: object) -> object:
    """A value as JSON can hold it: bytes as hex, the rest as it is."""
    return value.hex() if isinstance(value, bytes | bytearray) else value


@dataclass(frozen=True)
class AuditQuery:
    """Which entries a reader wants: filters (all optional) and one page of them, newest first."""

    axis: str | None = None
    user: str | None = None
    project: str | None = None
    action: str | None = None
    since: str | None = None  # ISO 8601 times as entries carry them (see :func:`parse_time`)
    until: str | None = None
    offset: int = 0
    limit: int = 100

    def matches(self, entry: Mapping[str, object]) -> bool:
        wanted = {"axis": self.axis, "user": self.user, "project": self.project, "action": self.action}
        if any(value is not None and entry.get(key) != value for key, value in wanted.items()):
            return False
        stamp = str(entry.get("time", ""))
        return (self.since is None or stamp >= self.since) and (self.until is None or stamp < self.until)


@dataclass(frozen=True)
class AuditPage:
    total: int  # entries matching the filters
    entries: list[dict[str, object]]  # the page asked for, newest first


class AuditLog:
    """Append-only JSON lines in ``path`` (in memory, bounded, when there is none)."""

    def __init__(self, path: Path | None) -> None:
        self.path = path
        self._lock = threading.Lock()
        self._memory: deque[dict[str, object]] = deque(maxlen=MEMORY_ENTRIES)

    def record(self, entries: Iterable[Mapping[str, object]]) -> None:
        """Append entries, stamped with the time and the acting user unless they name theirs, and numbered."""
        actor, now = current_actor(), format_time(time.time())
        stamped = [{"time": now, "user": actor.user, "client": actor.client, **entry} for entry in entries]
        if not stamped:
            return
        with self._lock:
            if self.path is None:
                self._memory.extend(_numbered(stamped, self._memory[-1]["seq"] if self._memory else 0))
            else:
                _append(self.path, stamped)

    def entries(self, query: AuditQuery) -> AuditPage:
        """One page of the matching entries, newest first, and how many match."""
        if not 0 < query.limit <= MAX_PAGE or query.offset < 0:
            raise InvalidInput(f"limit must be 1..{MAX_PAGE} and offset ≥ 0")
        matching = [entry for entry in self._all() if query.matches(entry)]
        newest_first = matching[::-1]
        return AuditPage(len(matching), newest_first[query.offset : query.offset + query.limit])

    def export(self, query: AuditQuery, form: str) -> Iterator[str]:
        """Every matching entry, oldest first, as JSON lines (``jsonl``) or CSV with a header (``csv``)."""
        if form not in ("jsonl", "csv"):
            raise InvalidInput(f"export format {form!r}: use csv or jsonl")
        chosen = (entry for entry in self._all() if query.matches(entry))
        return _csv(chosen) if form == "csv" else (json.dumps(entry, ensure_ascii=False) + "\n" for entry in chosen)

    def _all(self) -> Iterator[dict[str, object]]:
        if self.path is None:
            with self._lock:
                yield from list(self._memory)
            return
        yield from _read_lines(self.path)


def _numbered(entries: list[dict[str, object]], last: object) -> list[dict[str, object]]:
    """Entries with the sequence numbers after ``last``, the number first."""
    first = int(last) + 1 if isinstance(last, int) else 1
    return [{"seq": first + offset, **entry} for offset, entry in enumerate(entries)]


def _append(path: Path, entries: list[dict[str, object]]) -> None:
    """Number and append under an exclusive lock of the file: a server and CLI commands may share it, and the
    numbers follow the file's order whoever wrote."""
    path.parent.mkdir(parents=True, exist_ok=True)
    descriptor = os.open(path, os.O_RDWR | os.O_APPEND | os.O_CREAT, 0o600)
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX)
        tail = _tail(descriptor)
        lines = [json.dumps(entry, ensure_ascii=False, default=str) for entry in _numbered(entries, _last_seq(tail))]
        line_break = "\n" if tail and not tail.endswith("\n") else ""  # a writer killed mid-line: start afresh
        os.write(descriptor, (line_break + "\n".join(lines) + "\n").encode("utf-8"))
    finally:
        os.close(descriptor)


def _tail(descriptor: int, size: int = 65536) -> str:
    """The end of the file, enough for its last complete line."""
    end = os.fstat(descriptor).st_size
    return os.pread(descriptor, min(size, end), max(0, end - size)).decode("utf-8", errors="replace")


def _read_lines(path: Path) -> Iterator[dict[str, object]]:
    """The entries of a log file; a line cut short (the server killed mid-write) is skipped, not fatal."""
    if not path.is_file():
        return
    with path.open(encoding="utf-8", errors="replace") as lines:
        for line in lines:
            with contextlib.suppress(ValueError):
                entry = json.loads(line)
                if isinstance(entry, dict):
                    yield entry


def _last_seq(tail: str) -> int:
    """The sequence number to continue from: the last complete line's."""
    for line in reversed(tail.splitlines()):
        with contextlib.suppress(ValueError, TypeError, KeyError):
            return int(json.loads(line)["seq"])
    return 0


def _csv(entries: Iterable[Mapping[str, object]]) -> Iterator[str]:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, FIELDS, extrasaction="ignore")
    writer.writeheader()
    for entry in entries:
        writer.writerow({key: _cell(entry.get(key)) for key in FIELDS})
        yield buffer.getvalue()
        buffer.seek(0)
        buffer.truncate()
    yield buffer.getvalue()


def _cell(value: object) -> object:
    """A CSV cell: structured values as JSON, nothing as an empty cell."""
    if value is None:
        return ""
    return json.dumps(value) if isinstance(value, dict | list) else value


def format_time(epoch: float) -> str:
    """An entry's time: ISO 8601 UTC with milliseconds, so text order is time order."""
    return datetime.fromtimestamp(epoch, UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")


_UNITS = {"s": 1, "m": 60, "h": 3600, "d": 86400}


def parse_time(text: str, now: float | None = None) -> str:
    """A time a reader gives — ISO 8601 (``2026-12-01``, ``2026-12-01T10:00``, with or without zone; naive is UTC)
    or an age (``30m``, ``2h``, ``7d``: that long ago) — as entries carry it."""
    stripped = text.strip()
    if stripped[:-1].isdigit() and stripped[-1:] in _UNITS:
        ago = timedelta(seconds=int(stripped[:-1]) * _UNITS[stripped[-1]])
        return format_time((now if now is not None else time.time()) - ago.total_seconds())
    try:
        moment = datetime.fromisoformat(stripped.replace("Z", "+00:00"))
    except ValueError:
        raise InvalidInput(f"time {text!r}: use ISO 8601 (2026-12-01T10:00Z) or an age such as 30m, 2h, 7d") from None
    moment = moment if moment.tzinfo is not None else moment.replace(tzinfo=UTC)
    return format_time(moment.timestamp())


class ProjectAudit:
    """The project store's journal (``services.projects.store.ProjectJournal``): each object an axis file change
    sets, changes or drops, old → new, and each change of the project itself, as ``project_write`` entries."""

    def __init__(self, log: AuditLog) -> None:
        self.log = log

    def axis_file(self, project: str, axis: str, file_name: str, old: bytes, new: bytes) -> None:
        where = {"action": "project_write", "project": project, "project_axis": axis, "result": "ok"}
        self.log.record([where | change for change in _file_changes(file_name, old, new)])

    def project(self, project: str, what: str) -> None:
        self.log.record([{"action": "project_write", "project": project, "result": "ok", "detail": what}])


def _file_changes(file_name: str, old: bytes, new: bytes) -> list[dict[str, object]]:
    """Object by object for a parameter file; one entry for any other file (SEQUENCE.TXT, a capture)."""
    object_file = file_name.upper() in OBJECT_FILES
    before, after = (_object_values(file_name, old), _object_values(file_name, new)) if object_file else (None, None)
    if before is None or after is None:
        return [] if old == new else [{"object": file_name, "detail": f"{file_name} replaced"}]
    keys = sorted(set(before) | set(after))
    return [
        {"object": f"0x{index:04X},{sub}", "old": before.get((index, sub)), "new": after.get((index, sub))}
        for index, sub in keys
        if before.get((index, sub)) != after.get((index, sub))
    ]


def _object_values(file_name: str, data: bytes) -> dict[tuple[int, int], int | str] | None:
    """The assignments of a parameter file in its syntax (TTAPAR.TXT's PNU,IND too), or None when the text is not
    one."""
    try:
        entries = parse_drive_file(file_name, data.decode(FILE_ENCODING))
    except (InvalidInput, UnicodeDecodeError):
        return None
    return {(entry.index, entry.sub): entry.value for entry in entries}
