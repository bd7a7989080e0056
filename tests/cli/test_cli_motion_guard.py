"""The CLI's in-process commands write through the same motion guard as the server, and record in the same audit log.

A command is a live client only while it holds an axis (``state … operation-enabled``, tests/cli/test_cli_motion_
hold.py); ``write`` and ``restore`` end at once, so an enabling write through them is refused (exit 3) and the
drive, read back over the shared simulated bus, did not enable.  ``servostudio audit`` then shows the refusals."""

from __future__ import annotations

import csv
import io
import json

import pytest
from tests.support.commands import run

from servostudio.drive.cia402 import State
from servostudio.drive.control import read_state, set_state
from servostudio.services.bus import ConnectionManager

NODE = "2"


@pytest.fixture
def data_dir(tmp_path, monkeypatch):
    """The commands' audit log goes to a data directory of the test's own."""
    monkeypatch.setenv("SERVOSTUDIO_DATA_DIR", str(tmp_path / "data"))
    return tmp_path / "data"


@pytest.fixture
def switched_on(socketcand):
    """Node 2 one command away from Operation enabled; switched off again afterwards."""
    manager = ConnectionManager()
    drive = manager.open(socketcand.spec).drive(int(NODE))
    set_state(drive, State.SWITCHED_ON)
    yield lambda: read_state(drive)[0]
    set_state(drive, State.SWITCH_ON_DISABLED)
    manager.close_all()


@pytest.mark.parametrize("value", ["15", "15.0", "1.5e1", "0x8F"])
def test_write_cannot_enable(socketcand, switched_on, data_dir, capsys, value):
    code, _, error = run(capsys, "write", "--bus", socketcand.spec, "--node", NODE, "controlword", value)
    assert code == 3 and "live client" in error, error
    assert switched_on() is State.SWITCHED_ON


def test_restore_of_a_file_that_enables_is_refused(socketcand, switched_on, data_dir, tmp_path, capsys):
    drive_file = tmp_path / "DRIVEPAR.TXT"
    drive_file.write_text("0x6040,0=15\n", encoding="latin-1")
    code, _, error = run(capsys, "restore", "--bus", socketcand.spec, "--node", NODE, "--in", str(drive_file))
    assert code == 3 and "controller" in error, error
    assert switched_on() is State.SWITCHED_ON


def test_audit_shows_who_was_refused_what(socketcand, switched_on, data_dir, capsys):
    run(capsys, "write", "--bus", socketcand.spec, "--node", NODE, "controlword", "15")
    run(capsys, "write", "--bus", socketcand.spec, "--node", NODE, "0x60F9,2", "120")
    code, out, _ = run(capsys, "audit", "--since", "1h", "--action", "drive_write")
    entries = [json.loads(line) for line in out.splitlines()]
    assert code == 0 and [(entry["object"], entry["new"], entry["result"]) for entry in entries] == [
        ("0x6040,0", 15, "refused"),
        ("0x60F9,2", 120, "ok"),
    ]
    assert entries[0]["user"].startswith("cli:") and "controller" in entries[0]["detail"]
    assert isinstance(entries[1]["old"], int)  # read before the write
    code, out, _ = run(capsys, "audit", "--format", "csv", "--axis", f"socketcand:{NODE}")
    rows = list(csv.DictReader(io.StringIO(out)))
    assert code == 0 and [row["result"] for row in rows] == ["refused", "ok"]
