"""Which addresses the server may listen on: this machine only, unless logins protect it.

Binding to anything but loopback needs ``--allow-remote`` and users in the data directory (an administrator to
log in with); the password-less single-user mode is refused there, since it would let every machine in.
"""

from __future__ import annotations

import ipaddress

from servostudio.errors import RefusedForSafety
from servostudio.services.users.store import UserStore

ADD_ADMINISTRATOR = "servostudio user add NAME --level administrator"


class RemoteBindRefused(RefusedForSafety):
    """A non-loopback address without --allow-remote, or without users to log in with."""


def is_loopback(host: str) -> bool:
    try:
        return host == "localhost" or ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def check_bind(host: str, allow_remote: bool, store: UserStore) -> None:
    """Refuse to serve other machines unless asked to, and unless every caller must then log in."""
    if is_loopback(host):
        return
    if not allow_remote:
        raise RemoteBindRefused(
            f"--host {host}: the server binds to localhost only (127.0.0.1, ::1); "
            "pass --allow-remote to accept connections from other machines"
        )
    if not store.contents().accounts:
        raise RemoteBindRefused(
            f"--host {host} --allow-remote: other machines may connect only when everyone must log in, and "
            f"{store.path} has no users (password-less mode is for localhost only); add one first: "
            f"{ADD_ADMINISTRATOR}"
        )
