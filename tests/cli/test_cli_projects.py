"""`servostudio project …` as a subprocess: JSON on stdout, errors on stderr, exit codes.

Each call starts a Python process, so set-up that is not under test is done in-process.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from servostudio.od import builtin_library
from servostudio.services.projects import Axis, Bus, ProjectService


def run(store: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "servostudio", "project", "--projects", str(store), *args],
        capture_output=True,
        text=True,
        timeout=60,
    )


def ok(store: Path, *args: str):
    result = run(store, *args)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@pytest.fixture
def store(tmp_path: Path) -> Path:
    return tmp_path / "projects"


@pytest.fixture
def prepared(store: Path) -> Path:
    service = ProjectService(store, builtin_library())
    service.store.create("p", buses=(Bus("sim", "sim"),))
    service.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    return store


def test_edit_archive_unarchive_dcf(prepared: Path, tmp_path: Path):
    revision = ProjectService(prepared, builtin_library()).store.open("p").revision
    changed = ok(prepared, "set", "p", "X", "0x6060=Sequence", "0x3051=3", "--revision", revision)
    assert [row["value"] for row in changed["parameters"]] == [-3, 3]
    archive = ok(prepared, "archive", "p", str(tmp_path / "p.zip"))["archive"]
    assert ok(prepared, "unarchive", archive, "--name", "copy")["axes"][0]["node_id"] == 1
    assert ok(prepared, "dcf", "copy", "X", str(tmp_path / "X.dcf")) == {"dcf": str(tmp_path / "X.dcf")}
    assert "ParameterValue=-3" in (tmp_path / "X.dcf").read_text(encoding="latin-1")


def test_refusals_have_exit_codes_and_messages(prepared: Path):
    before = (prepared / "p" / "X" / "DRIVEPAR.TXT").read_bytes()
    out_of_range = run(prepared, "set", "p", "X", "0x3051=1", "0x6410,14=30")
    assert out_of_range.returncode == 3
    assert out_of_range.stderr.startswith("error: 0x6410,14") and "outside 1..24" in out_of_range.stderr
    assert out_of_range.stdout == ""
    assert (prepared / "p" / "X" / "DRIVEPAR.TXT").read_bytes() == before
    missing = run(prepared, "get", "p", "nope", "0x6060")
    assert missing.returncode == 4 and "no axis 'nope'" in missing.stderr
