"""Command line: ``servostudio <command> …``.

Every command prints JSON on stdout (or runs a server) and exits non-zero on failure,
so scripts can chain them.
"""

from __future__ import annotations

import argparse
import ipaddress
import os
import sys
from pathlib import Path

from servostudio.cli import drive, eds, project
from servostudio.cli.output import EXIT_USAGE, CommandError
from servostudio.od.library import DEFAULT_USER_EDS_DIR
from servostudio.sim import cli as sim_cli


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="servostudio", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    _add_serve(commands)
    eds.register(commands)
    project.register(commands)
    drive.register(commands)
    sim_cli.register(commands)
    return parser


def _add_serve(commands: argparse._SubParsersAction) -> None:
    serve = commands.add_parser("serve", help="start the communication server and the browser UI")
    serve.add_argument("--host", default="127.0.0.1", help="address to bind (default: 127.0.0.1)")
    serve.add_argument("--port", type=int, default=8000, help="TCP port (default: 8000)")
    serve.add_argument("--projects", type=Path, default=Path("projects"), help="project store directory")
    serve.add_argument(
        "--user-eds",
        type=Path,
        default=DEFAULT_USER_EDS_DIR,
        metavar="DIR",
        help=f"directory of imported EDS files (default: {DEFAULT_USER_EDS_DIR})",
    )
    serve.add_argument(
        "--allow-remote",
        action="store_true",
        help="accept a non-loopback --host (there is no login yet: only inside a container or a trusted network)",
    )
    serve.add_argument(
        "--bus",
        action="append",
        default=[],
        metavar="SPEC",
        help="bus to open at startup, repeatable (default: sim, the embedded simulated drives)",
    )
    serve.set_defaults(handler=_serve)


def check_bind_host(host: str, allow_remote: bool) -> None:
    """The communication server binds to this machine only, unless explicitly told otherwise."""
    try:
        local = host == "localhost" or ipaddress.ip_address(host).is_loopback
    except ValueError:
        local = False
    if not (local or allow_remote):
        raise CommandError(
            f"--host {host}: the server binds to localhost only (127.0.0.1, ::1); "
            "pass --allow-remote to accept connections from other machines",
            EXIT_USAGE,
        )


def _serve(args: argparse.Namespace) -> int:
    import uvicorn

    from servostudio.api.app import Settings, create_app

    check_bind_host(args.host, args.allow_remote)
    app = create_app(Settings(projects_dir=args.projects, user_eds_dir=args.user_eds, buses=args.bus or ["sim"]))
    uvicorn.run(app, host=args.host, port=args.port, log_level="info")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except CommandError as error:
        print(f"error: {error}", file=sys.stderr)
        return error.exit_code
    except BrokenPipeError:
        # The reader of our JSON went away (e.g. `| head`): not an error of the command itself.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
