"""``servostudio io`` (docs/io.md): the I/O configuration on a bus of its own and through a running server, the same
change written the same way (read back from the drive), a bad option or a refused change exits 3 with nothing
written."""

from __future__ import annotations

import pytest
from tests.support.commands import run_json
from tests.support.live_server import LiveServer


@pytest.fixture(scope="module")
def server(socketcand, tmp_path_factory):
    projects = tmp_path_factory.mktemp("io-cli") / "projects"
    projects.mkdir()
    live = LiveServer(projects, ["--bus", socketcand.spec])
    try:
        live.wait_ready()
        yield live
    finally:
        live.stop()


def row(configuration, name: str) -> dict:
    return next(item for item in configuration["inputs"] if item["name"] == name)


def test_io_shows_and_changes_a_limit_switch_here_and_through_the_server(server, socketcand, capsys):
    here = ("--bus", socketcand.spec, "--node", "1")
    code, changed, _ = run_json(capsys, "io", *here, "--input", "IN3=positive_limit:inverted")
    try:
        assert code == 0 and changed["written"] == ["0x3051,0", "0x3050,3"]
        code, through, _ = run_json(capsys, "io", "--server", server.url, "--node", "1")
        assert code == 0 and (row(through, "IN3")["function"], row(through, "IN3")["inverted"]) == (
            "positive_limit",
            True,
        )
        code, _, _ = run_json(capsys, "io", "--server", server.url, "--node", "1", "--input", "IN3=:normal")
        assert code == 0
        code, shown, _ = run_json(capsys, "read", *here, "0x3051,0")
        assert code == 0 and not int(shown["raw"]) & 0b100  # IN3's polarity bit, read back from the drive
    finally:
        run_json(capsys, "io", *here, "--input", "IN3=none:normal")


def test_a_refused_change_or_a_bad_option_exits_3_and_writes_nothing(socketcand, capsys):
    here = ("--bus", socketcand.spec, "--node", "1")
    _, before, _ = run_json(capsys, "read", *here, "0x3050,4", "0x3050,5")
    code, _, error = run_json(capsys, "io", *here, "--input", "IN4=home", "--input", "IN5=home")
    assert code == 3 and "IN4 and IN5 would both be 'home'" in error
    code, _, error = run_json(capsys, "io", *here, "--input", "IN4")
    assert code == 3 and "NAME=FUNCTION" in error
    assert run_json(capsys, "read", *here, "0x3050,4", "0x3050,5")[1] == before
