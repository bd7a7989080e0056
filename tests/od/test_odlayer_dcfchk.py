"""Every built-in EDS passes lely's dcfchk (dcf-tools) without a single warning."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DCFCHK = Path(sys.executable).parent / "dcfchk"
EDS_FILES = sorted((REPO / "eds").glob("*.eds"))


def test_there_are_builtin_dictionaries_to_check() -> None:
    assert DCFCHK.is_file(), f"dcfchk not installed next to {sys.executable}"
    assert {path.stem for path in EDS_FILES} >= {"xtrapulspac", "cd1k", "encotrive"}


@pytest.mark.parametrize("eds", EDS_FILES, ids=[path.name for path in EDS_FILES])
def test_dcfchk_accepts_the_file(eds: Path) -> None:
    # dcfchk resolves $NODEID while building the PDO tables, so it needs a node ID.
    result = subprocess.run([str(DCFCHK), "-n", "1", str(eds)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stderr == "", result.stderr
