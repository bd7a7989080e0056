"""The CLI's exit codes come from the kind of the error (`servostudio.errors.OUTCOMES`): 3 refused — nothing
written, 4 not found, 5 the bus or the drive failed; an exception outside the taxonomy is reported as a bug with its
traceback and exit code 70. Run in-process through `main(argv)`, on the in-process simulated drives (`--bus sim`)."""

from __future__ import annotations

import argparse

import pytest

from servostudio.cli import build_parser, main
from servostudio.cli import drive as drive_commands
from servostudio.errors import OUTCOMES, ErrorKind


def run(capsys, *argv: str) -> tuple[int, str]:
    code = main(list(argv))
    return code, capsys.readouterr().err


def exits(kind: ErrorKind, code: int) -> None:
    assert code == OUTCOMES[kind].exit_code


def test_not_found_exits_4(capsys):
    code, error = run(capsys, "read", "--bus", "sim", "--node", "1", "0x2FFE")
    exits(ErrorKind.NOT_FOUND, code)
    assert code == 4 and "0x2FFE" in error


def test_invalid_input_exits_3(capsys):
    code, error = run(capsys, "state", "--bus", "sim", "--node", "1", "dancing")
    exits(ErrorKind.INVALID_INPUT, code)
    assert code == 3 and "unknown CiA 402 state 'dancing'" in error


def test_conflict_exits_3(capsys, tmp_path):
    store = str(tmp_path / "projects")
    assert run(capsys, "project", "--projects", store, "create", "p")[0] == 0
    code, error = run(capsys, "project", "--projects", store, "create", "p")
    exits(ErrorKind.CONFLICT, code)
    assert code == 3 and "already exists" in error


def test_refused_for_safety_exits_3(capsys):
    code, error = run(capsys, "serve", "--host", "0.0.0.0")
    exits(ErrorKind.REFUSED_FOR_SAFETY, code)
    assert code == 3 and "localhost only" in error


def test_timeout_exits_5(capsys):
    code, error = run(capsys, "read", "--bus", "sim", "--node", "42", "0x1000")
    exits(ErrorKind.TIMEOUT, code)
    assert code == 5 and "node 42 does not answer" in error


def test_communication_exits_5(capsys, tmp_path):
    out = tmp_path / "DRIVEPAR.TXT"
    code, error = run(capsys, "backup", "--bus", "sim", "--node", "42", "--device", "xtrapulspac", "--out", str(out))
    exits(ErrorKind.COMMUNICATION, code)
    assert code == 5 and "no file written" in error and not out.exists()


def test_unavailable_exits_5(capsys):
    code, error = run(capsys, "read", "--bus", "socketcand:127.0.0.1:9", "--node", "1", "0x1000")
    exits(ErrorKind.UNAVAILABLE, code)
    assert code == 5 and "not connected" in error


def test_a_bug_exits_70_with_its_traceback(capsys, monkeypatch):
    def broken(args, connection):
        raise ValueError("a programming error")

    monkeypatch.setattr(drive_commands, "_scan", broken)
    code, error = run(capsys, "scan", "--bus", "sim")
    exits(ErrorKind.INTERNAL, code)
    assert code == 70
    assert "Traceback" in error and "error: unexpected ValueError: a programming error" in error


@pytest.mark.parametrize("argv", [["nmt", "--bus", "sim", "jump"], ["nmt", "--bus", "sim", "start", "--node", "200"]])
def test_refused_nmt_is_invalid_input_not_a_bug(capsys, argv):
    code, error = run(capsys, *argv)
    assert code == 3 and "Traceback" not in error


def test_every_command_prints_its_help(capsys):
    """``servostudio COMMAND --help`` answers for every command (a ``%`` in a help text once broke two of them)."""
    parser = build_parser()
    commands = next(action for action in parser._actions if isinstance(action, argparse._SubParsersAction))
    for name in commands.choices:
        with pytest.raises(SystemExit) as ended:
            main([name, "--help"])
        assert ended.value.code == 0, name
        assert "usage: servostudio" in capsys.readouterr().out, name
