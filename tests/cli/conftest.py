"""What every CLI test shares: no server or config file of the developer's chooses where a command goes (running a
command: ``tests/support/commands.py``)."""

from __future__ import annotations

import pytest

from servostudio.cli.remote import CONFIG_VARIABLE, SERVER_VARIABLE


@pytest.fixture(autouse=True)
def no_default_server(monkeypatch, tmp_path):
    """Neither the developer's environment nor their config file may choose a server for these tests."""
    monkeypatch.delenv(SERVER_VARIABLE, raising=False)
    monkeypatch.setenv(CONFIG_VARIABLE, str(tmp_path / "absent.toml"))
