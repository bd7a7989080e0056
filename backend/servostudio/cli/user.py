"""`servostudio user …` and `servostudio setup`: the users of a data directory, or of a server (``--server``).

Passwords never go on the command line (where other users could read them in the process list): they are asked
twice on the terminal, or read from the first line of standard input with ``--password-stdin``.
"""

from __future__ import annotations

import argparse
import getpass
import sys
from pathlib import Path

from servostudio.cli import remote
from servostudio.cli.output import emit
from servostudio.errors import InvalidInput
from servostudio.services.settings import Settings
from servostudio.services.users import Level, UserStore

LEVELS = [level.value for level in Level]


class NoPassword(InvalidInput):
    """No terminal to ask the password on, and no --password-stdin."""


def register(commands: argparse._SubParsersAction) -> None:
    user = commands.add_parser("user", help="users and their levels")
    actions = user.add_subparsers(dest="action", required=True)
    add = command(actions, "add", "add a user (password asked, or --password-stdin)", _add)
    add.add_argument("name")
    add.add_argument("--level", required=True, choices=LEVELS)
    add.add_argument("--password-stdin", action="store_true", help="read the password from standard input")
    command(actions, "list", "the users (JSON)", _list)
    remove = command(actions, "remove", "remove a user and its tokens", _remove)
    remove.add_argument("name")
    setup = commands.add_parser("setup", help="first start without the setup link")
    setup.add_argument("--passwordless", action="store_true", required=True, help="single-user, localhost only")
    data_dir_option(setup)
    setup.set_defaults(handler=_passwordless)


def command(actions: argparse._SubParsersAction, name: str, help: str, handler: object) -> argparse.ArgumentParser:
    """A ``user`` or ``token`` sub-command: on ``--data-dir``, or through ``--server`` with ``--token``."""
    parser = actions.add_parser(name, help=help)
    data_dir_option(parser)
    remote.add_options(parser, suppress=True)
    parser.set_defaults(handler=handler)
    return parser


def data_dir_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--data-dir",
        type=Path,
        metavar="DIR",
        help="the server's data directory (default: $SERVOSTUDIO_DATA_DIR, else $XDG_DATA_HOME/servostudio)",
    )


def store(args: argparse.Namespace) -> UserStore:
    return UserStore(Settings.given(data_dir=args.data_dir).data_dir)


def _add(args: argparse.Namespace) -> int:
    password = _password(args.password_stdin)
    server = remote.Remote.of(args)
    if server is not None:
        return emit(server.call("POST", "/api/users", {"name": args.name, "level": args.level, "password": password}))
    return emit(store(args).add_user(args.name, Level(args.level), password).public())


def _list(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    if server is not None:
        return emit(server.call("GET", "/api/users"))
    return emit([account.public() for account in store(args).contents().accounts])


def _remove(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    if server is not None:
        server.call("DELETE", f"/api/users/{args.name}")
    else:
        store(args).remove_user(args.name)
    return emit({"removed": args.name})


def _passwordless(args: argparse.Namespace) -> int:
    """Password-less single-user mode, chosen by whoever owns the data directory (the server still refuses it on
    anything but loopback)."""
    store(args).choose_passwordless()
    return emit({"passwordless": True})


def _password(from_stdin: bool) -> str:
    if from_stdin:
        return sys.stdin.readline().rstrip("\r\n")
    if not sys.stdin.isatty():
        raise NoPassword("no terminal to ask the password on: pass --password-stdin and write it to standard input")
    first, second = getpass.getpass("password: "), getpass.getpass("password again: ")
    if first != second:
        raise InvalidInput("the two passwords differ; nothing was changed")
    return first
