"""Command line: ``servostudio <command> …``.

Every command prints JSON on stdout (or runs a server) and exits non-zero on failure,
so scripts can chain them.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from servostudio.cli import audit, drive, eds, project, remote, seq, token, user
from servostudio.cli import frequency as frequency_cli
from servostudio.cli import identify as identify_cli
from servostudio.cli import motion as motion_cli
from servostudio.cli import procedures as procedures_cli
from servostudio.cli import report as report_cli
from servostudio.cli import scope as scope_cli
from servostudio.cli import sim as sim_cli
from servostudio.cli.output import crashed, refused
from servostudio.errors import ServoStudioError
from servostudio.services.bus import parse_share
from servostudio.services.bus.share import loopback
from servostudio.services.settings import DEFAULT_HOST, DEFAULT_PORT, Settings
from servostudio.services.users import RemoteBindRefused, UserStore, check_bind

__all__ = ["RemoteBindRefused", "build_parser", "main"]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="servostudio", description=__doc__.splitlines()[0])
    remote.add_options(parser)
    commands = parser.add_subparsers(dest="command", required=True)
    _add_serve(commands)
    user.register(commands)
    token.register(commands)
    eds.register(commands)
    project.register(commands)
    drive.register(commands)
    motion_cli.register(commands)
    procedures_cli.register(commands)
    frequency_cli.register(commands)
    identify_cli.register(commands)
    scope_cli.register(commands)
    seq.register(commands)
    audit.register(commands)
    report_cli.register(commands)
    sim_cli.register(commands)
    return parser


def _add_serve(commands: argparse._SubParsersAction) -> None:
    serve = commands.add_parser("serve", help="start the communication server and the browser UI")
    serve.add_argument("--host", default=DEFAULT_HOST, help=f"address to bind (default: {DEFAULT_HOST})")
    serve.add_argument("--port", type=int, default=DEFAULT_PORT, help=f"TCP port (default: {DEFAULT_PORT})")
    serve.add_argument("--projects", type=Path, default=Path("projects"), help="project store directory")
    serve.add_argument(
        "--user-eds",
        type=Path,
        metavar="DIR",
        help="directory of imported EDS files (default: $SERVOSTUDIO_USER_EDS_DIR, else "
        "$XDG_DATA_HOME/servostudio/eds)",
    )
    serve.add_argument(
        "--export-dir",
        type=Path,
        metavar="DIR",
        help="directory backup and restore jobs may use besides the project store (default: $SERVOSTUDIO_EXPORT_DIR)",
    )
    serve.add_argument(
        "--ui",
        type=Path,
        metavar="DIR",
        help="serve the browser UI built in DIR (default: the package's own build; a `vite build --outDir` of "
        "another version, to compare two UIs side by side)",
    )
    serve.add_argument(
        "--allow-remote",
        action="store_true",
        help="accept a non-loopback --host (needs users in the data directory: everyone must log in)",
    )
    user.data_dir_option(serve)
    serve.add_argument(
        "--allowed-host",
        action="append",
        default=[],
        metavar="NAME",
        help="a Host name browsers may use besides localhost and --host (repeatable; others are refused)",
    )
    serve.add_argument(
        "--allowed-origin",
        action="append",
        default=[],
        metavar="ORIGIN",
        help="a foreign page origin allowed to call the API, e.g. https://hmi.plant.lan (repeatable)",
    )
    serve.add_argument(
        "--bus",
        action="append",
        default=[],
        metavar="SPEC",
        help="bus to open at startup, repeatable (default: sim, the embedded simulated drives)",
    )
    serve.add_argument(
        "--share",
        action="append",
        default=[],
        metavar="BUS=[HOST:]PORT",
        help="share an open bus as a socketcand endpoint for your own CANopen scripts, e.g. sim=29540 (loopback "
        "only; repeatable)",
    )
    serve.add_argument(
        "--audit-old-values",
        choices=["small-writes", "every-write"],
        help="which drive writes the audit log reads the old value of first: batches of up to 16 objects (default; "
        "a restore then logs old: null) or every write (a restore takes about 1.4 times as long)",
    )
    serve.set_defaults(handler=_serve)


#: Seconds a stopping server gives the requests in flight before it closes the buses (which ends every drive wait
#: and job at once), so a SIGTERM stops it within 5 s whatever runs.
SHUTDOWN_GRACE = 2


def _serve(args: argparse.Namespace) -> int:
    import uvicorn

    from servostudio.api.app import create_app

    settings = Settings.given(
        projects_dir=args.projects,
        user_eds_dir=args.user_eds,
        export_dir=args.export_dir,
        static_dir=args.ui,
        buses=tuple(args.bus or ["sim"]),
        shares=tuple(args.share),
        host=args.host,
        port=args.port,
        data_dir=args.data_dir,
        allowed_hosts=tuple(args.allowed_host),
        allowed_origins=tuple(args.allowed_origin),
        audit_old_values=args.audit_old_values,
    )
    check_bind(settings.host, args.allow_remote, UserStore(settings.data_dir))
    for share in settings.shares:  # refused before the server starts (exit 3), not in its lifespan
        loopback(parse_share(share)[1])
    uvicorn.run(
        create_app(settings),
        host=settings.host,
        port=settings.port,
        log_level="info",
        timeout_graceful_shutdown=SHUTDOWN_GRACE,
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    """Run one command; a refusal exits with the code of its kind, anything else is reported as a bug (70)."""
    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except ServoStudioError as error:
        return refused(error)
    except BrokenPipeError:
        # The reader of our JSON went away (e.g. `| head`): not an error of the command itself.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except Exception as error:  # noqa: BLE001 - a bug: reported as such, with its traceback
        return crashed(error)
