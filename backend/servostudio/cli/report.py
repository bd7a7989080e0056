"""``servostudio report PROJECT [AXIS] --out FILE.html``: the commissioning report (docs/report.md) as one standalone
HTML file — of the whole project, or of one axis.

Offline it is generated here from the project directory (``--projects DIR``, the same store as the ``project``
commands) and, when this machine keeps an audit log (``--data-dir``'s ``audit.jsonl``), who changed the project
when; no drive and no server is needed. With ``--server URL`` (or the configured default server, when neither
``--projects`` nor ``--data-dir`` is given) the server generates it from its own store
(``GET /api/projects/{project}/report``). Either way the file is written atomically: a failed command leaves no
file, or the previous one whole.

Exit codes: 0 written; 3 refused (the output's directory does not exist); 4 no such project or axis; 5 the server
cannot be reached; 6 / 7 the server's login or level refused it.
"""

from __future__ import annotations

import argparse
import urllib.parse
from pathlib import Path

from servostudio.cli import remote, user
from servostudio.cli.output import emit
from servostudio.errors import InvalidInput
from servostudio.formats.textfile import write_bytes_atomic
from servostudio.od import EdsLibrary
from servostudio.services.audit import AuditLog
from servostudio.services.projects import ProjectService
from servostudio.services.report import report_html
from servostudio.services.settings import Settings


class NoOutputDirectory(InvalidInput):
    """``--out`` names a file in a directory that does not exist: nothing is generated."""


def register(commands: argparse._SubParsersAction) -> None:
    parser = commands.add_parser(
        "report", help="the commissioning report of a project or an axis as a standalone HTML file (offline)"
    )
    parser.add_argument("project")
    parser.add_argument("axis", nargs="?", help="one axis of the project (default: every axis)")
    parser.add_argument("--out", type=Path, required=True, metavar="FILE.html")
    parser.add_argument(
        "--projects", type=Path, metavar="DIR", help="project store directory (default: projects; works here)"
    )
    parser.add_argument(
        "--user-eds-dir", type=Path, help="user EDS library (default: $SERVOSTUDIO_USER_EDS_DIR, else the user's data)"
    )
    user.data_dir_option(parser)  # its audit log says who changed the project when; naming it works here
    remote.add_options(parser, suppress=True)
    parser.set_defaults(handler=lambda args: _report(args, parser))


def _report(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    if (args.projects is not None or args.data_dir is not None) and getattr(args, "server", None):
        parser.error("--projects / --data-dir (here) or --server URL (the server's store), not both")
    if not args.out.parent.is_dir():
        raise NoOutputDirectory(f"--out {args.out}: the directory {args.out.parent} does not exist")
    server = remote.Remote.of(args) if args.projects is None else None
    if server is not None:
        html, source = _fetched(server, args.project, args.axis), f"server {server.url}"
    else:
        settings = Settings.given(projects_dir=args.projects, user_eds_dir=args.user_eds_dir, data_dir=args.data_dir)
        html, source = _generated(settings, args.project, args.axis).encode("utf-8"), str(settings.projects_dir)
    write_bytes_atomic(args.out, html)
    return emit({"out": str(args.out), "project": args.project, "axis": args.axis, "bytes": len(html),
                 "from": source})  # fmt: skip


def _generated(settings: Settings, project: str, axis: str | None) -> str:
    """The report made here; the audit log only when this machine keeps one (a fresh one would say nothing)."""
    library = EdsLibrary(settings.builtin_eds_dir, settings.user_eds_dir)
    audit = AuditLog(settings.audit_path) if settings.audit_path.is_file() else None
    projects = ProjectService(settings.projects_dir, library, settings.motors_dir, audit)
    return report_html(projects, project, axis, audit)


def _fetched(server: remote.Remote, project: str, axis: str | None) -> bytes:
    query = f"?{urllib.parse.urlencode({'axis': axis})}" if axis is not None else ""
    return server.exchange("GET", f"/api/projects/{remote.quoted(project)}/report{query}")[0]
