"""One embedded simulated XtrapulsPac (spec ``sim:1``) reached the way the server reaches it (its programs:
``tests/support/sequence_programs.py``)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.embedded_sim import open_sim

from servostudio.services.bus import ConnectionManager


@pytest.fixture
def manager() -> Iterator[ConnectionManager]:
    manager = ConnectionManager()
    open_sim(manager, "sim:1")
    yield manager
    manager.close_all()


@pytest.fixture
def connection(manager):
    return manager.get("sim")


@pytest.fixture
def drive(connection):
    return connection.drive(1)
