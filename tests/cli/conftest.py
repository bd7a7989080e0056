"""What every CLI test shares: no server or config file of the developer's chooses where a command goes, and the
command run in this process with its exit code, output and error text."""

from __future__ import annotations

import json

import pytest

from servostudio.cli import main
from servostudio.cli.remote import CONFIG_VARIABLE, SERVER_VARIABLE


@pytest.fixture(autouse=True)
def no_default_server(monkeypatch, tmp_path):
    """Neither the developer's environment nor their config file may choose a server for these tests."""
    monkeypatch.delenv(SERVER_VARIABLE, raising=False)
    monkeypatch.setenv(CONFIG_VARIABLE, str(tmp_path / "absent.toml"))


def run(capsys, *argv: str) -> tuple[int, str, str]:
    """``servostudio ARGV`` in this process: its exit code, standard output and standard error."""
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def run_json(capsys, *argv: str) -> tuple[int, object, str]:
    """As ``run``, the output read as the JSON document the command prints (None when it printed nothing)."""
    code, out, err = run(capsys, *argv)
    return code, json.loads(out) if out.strip() else None, err
