"""`servostudio eds …` as a subprocess: find an object, check and import a user EDS, reject a malformed one."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from tests.support.small_eds import SMALL_EDS, write_small_eds


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "servostudio", *args], capture_output=True, text=True, timeout=60)


def test_cli_show_finds_an_object_by_name_and_address() -> None:
    by_address = run_cli("eds", "show", "xtrapulspac", "0x6041")
    assert by_address.returncode == 0, by_address.stderr
    entry = json.loads(by_address.stdout)
    assert (entry["index"], entry["subindex"], entry["data_type"]) == ("0x6041", 0, "UNSIGNED16")
    missing = run_cli("eds", "show", "xtrapulspac", "0x5FFF,9")
    assert missing.returncode == 4 and "error:" in missing.stderr


def test_cli_check_and_import(tmp_path: Path) -> None:
    eds = write_small_eds(tmp_path)
    checked = run_cli("eds", "check", str(eds))
    assert checked.returncode == 0, checked.stderr
    assert json.loads(checked.stdout)["product_code"] == 0x42
    user_dir = tmp_path / "lib"
    imported = run_cli("eds", "--user-dir", str(user_dir), "import", str(eds))
    assert imported.returncode == 0, imported.stderr
    listed = json.loads(run_cli("eds", "--user-dir", str(user_dir), "list").stdout)
    assert "acme" in {entry["device"] for entry in listed}


def test_cli_check_rejects_a_malformed_file_with_exit_3(tmp_path: Path) -> None:
    eds = write_small_eds(tmp_path, SMALL_EDS.replace("ParameterName=Speed limit\n", ""))
    result = run_cli("eds", "check", str(eds))
    assert result.returncode == 3
    assert "acme.eds:" in result.stderr and "[2000]" in result.stderr
