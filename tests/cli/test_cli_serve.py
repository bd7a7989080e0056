"""`servostudio serve`: localhost by default, and the rule that refuses another address without --allow-remote."""

from __future__ import annotations

import pytest

from servostudio.cli import RemoteBindRefused, build_parser, check_bind_host


@pytest.mark.parametrize(
    "argv, host, port",
    [(["serve"], "127.0.0.1", 8000), (["serve", "--host", "0.0.0.0", "--port", "9000"], "0.0.0.0", 9000)],
)
def test_serve_binds_localhost_by_default(argv, host, port) -> None:
    args = build_parser().parse_args(argv)
    assert (args.host, args.port) == (host, port)


@pytest.mark.parametrize("host", ["127.0.0.1", "::1", "localhost", "127.0.0.2"])
def test_serve_accepts_loopback(host):
    check_bind_host(host, allow_remote=False)


@pytest.mark.parametrize("host", ["0.0.0.0", "192.168.1.10", "example.org"])
def test_serve_refuses_other_addresses(host):
    with pytest.raises(RemoteBindRefused, match="localhost only"):
        check_bind_host(host, allow_remote=False)
    check_bind_host(host, allow_remote=True)  # explicit opt-in, e.g. inside the container
