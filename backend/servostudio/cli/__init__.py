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
from servostudio.cli import sim as sim_cli
from servostudio.cli.output import crashed, refused
from servostudio.errors import RefusedForSafety, ServoStudioError
from servostudio.services.settings import DEFAULT_HOST, DEFAULT_PORT, Settings


class RemoteBindRefused(RefusedForSafety):
    """A non-loopback address without --allow-remote: there is no login yet, so the server stays on this machine."""


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
        "--ui",
        type=Path,
        metavar="DIR",
        help="serve the browser UI built in DIR (default: the package's own build; a `vite build --outDir` of "
        "another version, to compare two UIs side by side)",
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
        raise RemoteBindRefused(
            f"--host {host}: the server binds to localhost only (127.0.0.1, ::1); "
            "pass --allow-remote to accept connections from other machines"
        )


def _serve(args: argparse.Namespace) -> int:
    import uvicorn

    from servostudio.api.app import create_app

    check_bind_host(args.host, args.allow_remote)
    settings = Settings.given(
        projects_dir=args.projects,
        user_eds_dir=args.user_eds,
        static_dir=args.ui,
        buses=tuple(args.bus or ["sim"]),
        host=args.host,
        port=args.port,
    )
    uvicorn.run(create_app(settings), host=settings.host, port=settings.port, log_level="info")
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
