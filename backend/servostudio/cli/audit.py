"""``servostudio audit``: read the audit log; and who the other commands act as and where they record it.

A command that talks to a bus itself (``write``, ``restore``, ``state``, ``project commission`` …) writes through
the same motion guard as the server, records into the same audit log (``Settings.audit_path``: the data directory's
``audit.jsonl``) and acts as the person at the terminal — the local administrator as far as levels go.

    servostudio audit [--since 2h] [--until 2026-12-01T12:00] [--axis sim:1] [--user NAME] [--project NAME]
                      [--action drive_write] [--format jsonl|csv] [--file PATH]
"""

from __future__ import annotations

import argparse
import getpass
import sys
from pathlib import Path

from servostudio.od import EdsLibrary
from servostudio.services.audit import Actor, AuditLog, AuditQuery, parse_time
from servostudio.services.bus import ConnectionManager
from servostudio.services.motion import MotionGuard
from servostudio.services.settings import Settings


def local_actor() -> Actor:
    """The person at the terminal: named after the login, the local administrator's level."""
    return Actor(user=f"cli:{getpass.getuser()}", level="administrator")


def audit_log(settings: Settings | None = None) -> AuditLog:
    return AuditLog((settings or Settings()).audit_path)


def guarded_connections(audit: AuditLog, library: EdsLibrary | None = None) -> ConnectionManager:
    """A command's buses, their drives writing through a motion guard that records into ``audit`` (old values as
    ``SERVOSTUDIO_AUDIT_OLD_VALUES`` says, as the server's ``--audit-old-values``)."""
    return ConnectionManager(library, motion=MotionGuard(audit=audit, old_values_up_to=Settings().old_values_up_to))


def register(commands: argparse._SubParsersAction) -> None:
    audit = commands.add_parser(
        "audit", help="print the audit log (drive and project writes, motion) as JSON lines or CSV"
    )
    audit.add_argument("--since", help="ISO 8601 time or an age (30m, 2h, 7d)")
    audit.add_argument("--until", help="ISO 8601 time or an age")
    audit.add_argument("--axis", metavar="BUS:NODE", help="one axis, e.g. sim:1")
    audit.add_argument("--user")
    audit.add_argument("--project")
    audit.add_argument("--action", help="drive_write, project_write, arm, release, enable, stop, quick_stop, …")
    audit.add_argument("--format", choices=("jsonl", "csv"), default="jsonl")
    audit.add_argument("--file", type=Path, help="the log to read (default: the data directory's audit.jsonl)")
    audit.set_defaults(handler=_audit)


def _audit(args: argparse.Namespace) -> int:
    """Every matching entry, oldest first, on stdout."""
    log = AuditLog(args.file) if args.file else audit_log()
    since, until = (parse_time(text) if text else None for text in (args.since, args.until))
    query = AuditQuery(args.axis, args.user, args.project, args.action, since, until)
    for chunk in log.export(query, args.format):
        sys.stdout.write(chunk)
    return 0
