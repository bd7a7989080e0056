"""The pinned procedure commands in-process (``--bus sim``: the command opens its own simulated drives and is the
axis's live controller): JSON on stdout, ``--yes`` required without a terminal, refusals with exit 3."""

from __future__ import annotations

import json

import pytest
from tests.support.commands import run


@pytest.fixture(autouse=True)
def data_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("SERVOSTUDIO_DATA_DIR", str(tmp_path / "data"))


def test_currentloop_prints_the_gains_and_limits_before_and_after(capsys):
    code, out, err = run(capsys, "currentloop", "--bus", "sim", "--node", "1", "--regulator", "low", "--yes")
    assert code == 0, err
    result = json.loads(out)
    assert result["status"] == "done" and result["procedure"] == "current_loop"
    assert result["gains"]["after"]["kp_current_q"] == result["gains"]["before"]["kp_current_q"] // 2  # 250 Hz
    assert set(result["limits"]["after"]) == {"rated_current", "max_current"}


def test_without_yes_and_without_a_terminal_nothing_starts(capsys):
    code, out, err = run(capsys, "currentloop", "--bus", "sim", "--node", "1")
    assert code == 3 and out == ""
    assert "confirm with --yes" in err and "nothing was written" in err


def test_autotune_is_refused_with_the_manual_s_reason(capsys):
    code, out, err = run(capsys, "autotune", "--bus", "sim", "--node", "1", "--bandwidth", "75", "--yes")
    assert code == 3 and out == ""
    assert "brake" in err and "nothing was written" in err
