"""`servostudio token …`: API tokens for scripts, made on the data directory or by a server (``--server``).

``token create`` prints the token once; only its digest is kept. Made on the data directory, a token belongs to
the machine's owner (no user); made through a server, to the caller, at most at the caller's level.
"""

from __future__ import annotations

import argparse

from servostudio.cli import remote
from servostudio.cli.output import emit
from servostudio.cli.user import LEVELS, command, store
from servostudio.services.users import TOKEN_DAYS_DEFAULT, Level


def register(commands: argparse._SubParsersAction) -> None:
    token = commands.add_parser("token", help="API tokens for scripts and the CLI")
    actions = token.add_subparsers(dest="action", required=True)
    create = command(actions, "create", "make a token and print it once", _create)
    create.add_argument("--level", required=True, choices=LEVELS)
    create.add_argument("--expires", type=int, default=TOKEN_DAYS_DEFAULT, metavar="DAYS", help="default: 30")
    create.add_argument("--label", default="", help="what the token is for")
    command(actions, "list", "the tokens (without their secrets)", _list)
    revoke = command(actions, "revoke", "revoke a token by its id", _revoke)
    revoke.add_argument("id")


def _create(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    if server is not None:
        body = {"level": args.level, "days": args.expires, "label": args.label}
        return emit(server.call("POST", "/api/tokens", body))
    text, record = store(args).create_token(Level(args.level), args.expires, label=args.label)
    return emit({**record.public(), "token": text})


def _list(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    if server is not None:
        return emit(server.call("GET", "/api/tokens"))
    return emit([record.public() for record in store(args).contents().tokens])


def _revoke(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    if server is not None:
        server.call("DELETE", f"/api/tokens/{args.id}")
    else:
        store(args).revoke_token(args.id)
    return emit({"revoked": args.id})
