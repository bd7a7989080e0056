"""Every `servostudio project` action, run in-process through `servostudio.cli.main` (the subprocess tests cover
the process boundary: exit codes, stdout, stderr)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from servostudio.cli import main


@pytest.fixture
def cli(tmp_path: Path, capsys):
    store = tmp_path / "projects"

    def run(*args: str, code: int = 0):
        assert main(["project", "--projects", str(store), *args]) == code
        captured = capsys.readouterr()
        run.stderr = captured.err
        return json.loads(captured.out) if captured.out else None

    return run


def test_every_action(cli, tmp_path: Path):
    cli("create", "p", "--bus", "sim=sim", "--bus", "can=socketcan:can0@250000")
    cli("axis-add", "p", "X", "--device", "xtrapulspac", "--node", "1", "--bus", "sim")
    shown = cli("show", "p")
    assert [b["bitrate"] for b in shown["buses"]] == [None, 250000]
    edited = cli("axis-edit", "p", "X", "--new-name", "Lift", "--node", "5", "--bus", "can", "--description", "z")
    assert edited["axes"] == [
        {
            "name": "Lift",
            "device": "xtrapulspac",
            "node_id": 5,
            "bus": "can",
            "description": "z",
            "motor": "",
            "application": "",
        }
    ]
    cli("set", "p", "Lift", "0x3051=2", "60F9,2=100")
    assert [row["name"] for row in cli("params", "p", "Lift", "--only-set")["parameters"]] == [
        "0x3051,0 Digital inputs polarity",
        cli("get", "p", "Lift", "60F9,2")["name"],
    ]
    assert cli("params", "p", "Lift", "--only-differences", "--group", "Servo Loops")["parameters"][0]["value"] == 100
    assert len(cli("params", "p", "Lift", "--all")["parameters"]) > len(cli("params", "p", "Lift")["parameters"])
    assert cli("reset", "p", "Lift", "0x3051")["parameters"][0]["file"] is None
    compare = cli("compare", "p", "Lift", "--only-differences")
    assert [row["index"] for row in compare["rows"]] == [0x60F9]
    templates = cli("template-list", "--device", "cd1k")
    assert [t["key"] for t in templates] == ["expert"]
    assert cli("motor-list") == []
    cli("rename", "p", "q")
    cli("duplicate", "q", "r")
    cli("axis-remove", "r", "Lift")
    cli("delete", "q")
    assert [(p["name"], p["axis_count"]) for p in cli("list")] == [("r", 0)]


def test_bad_bus_option_is_refused(cli):
    assert cli("create", "p", "--bus", "no-equals-sign", code=3) is None
    assert "expected NAME=INTERFACE" in cli.stderr


def test_motor_and_template_selection(cli, tmp_path: Path):
    cli("create", "p", "--bus", "sim=sim")
    cli("axis-add", "p", "X", "--device", "xtrapulspac", "--node", "1", "--bus", "sim")
    motor = tmp_path / "TEST-M.toml"
    motor.write_text('[motor]\nreference = "TEST-M"\nsource = "test data"\n\n[motor_data]\nmax_speed = 2000\n')
    assert cli("motor-add", str(motor))["reference"] == "TEST-M"
    selected = cli("motor-select", "p", "X", "TEST-M")
    assert {(row["index"], row["value"]) for row in selected["changed"]} == {(0x6410, 2000), (0x6080, 2000)}
    applied = cli("template-apply", "p", "X", "stepper-emulation")
    assert applied["project"]["axes"][0] == {
        "name": "X",
        "device": "xtrapulspac",
        "node_id": 1,
        "bus": "sim",
        "description": "",
        "motor": "TEST-M",
        "application": "stepper-emulation",
    }
    assert cli("motor-remove", "TEST-M") == {"removed": "TEST-M"}
    assert cli("motor-list") == []
