"""`servostudio serve`: localhost by default, and the rule that refuses another address unless asked for with
--allow-remote and protected by logins (users in the data directory; never password-less)."""

from __future__ import annotations

import pytest

from servostudio.cli import RemoteBindRefused, build_parser
from servostudio.services.users import Level, UserStore, check_bind


@pytest.mark.parametrize(
    "argv, host, port",
    [(["serve"], "127.0.0.1", 8000), (["serve", "--host", "0.0.0.0", "--port", "9000"], "0.0.0.0", 9000)],
)
def test_serve_binds_localhost_by_default(argv, host, port) -> None:
    args = build_parser().parse_args(argv)
    assert (args.host, args.port) == (host, port)


@pytest.mark.parametrize("host", ["127.0.0.1", "::1", "localhost", "127.0.0.2"])
def test_serve_accepts_loopback(host, tmp_path):
    check_bind(host, allow_remote=False, store=UserStore(tmp_path))


@pytest.mark.parametrize("host", ["0.0.0.0", "192.168.1.10", "example.org"])
def test_serve_refuses_other_addresses_unless_asked_and_protected(host, tmp_path):
    store = UserStore(tmp_path)
    with pytest.raises(RemoteBindRefused, match="localhost only"):
        check_bind(host, allow_remote=False, store=store)
    with pytest.raises(RemoteBindRefused, match="has no users"):
        check_bind(host, allow_remote=True, store=store)  # asked for, but nobody would need to log in
    store.add_user("admin", Level.ADMINISTRATOR, "a long enough secret")
    check_bind(host, allow_remote=True, store=store)  # explicit opt-in with logins, e.g. inside the container


def test_password_less_mode_never_serves_other_machines(tmp_path):
    store = UserStore(tmp_path)
    store.choose_passwordless()
    check_bind("127.0.0.1", allow_remote=False, store=store)
    with pytest.raises(RemoteBindRefused, match="password-less mode is for localhost only"):
        check_bind("0.0.0.0", allow_remote=True, store=store)
