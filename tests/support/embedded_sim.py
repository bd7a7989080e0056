"""The server's embedded simulated bus (spec ``sim``) opened the way the project code finds it, for the live project
tests of the services, API and CLI folders."""

from __future__ import annotations

import pytest

from servostudio.services.bus import ConnectionManager

#: The machine is shared by many processes; a drive in this process may answer late, never wrongly.
SDO_TIMEOUT = 1.0


def open_sim(manager: ConnectionManager, spec: str = "sim") -> None:
    """Open the simulated bus the way the project code will find it (same spec, shared) with a patient timeout."""
    connection = manager.open(spec, wait=5.0)
    assert connection.link.wait_connected(5.0)  # an already open bus is returned without waiting
    connection.engine.timeout = SDO_TIMEOUT


@pytest.fixture(scope="session")
def sim_opener():
    """`open_sim` as a fixture, for tests that open the bus inside an app they build themselves."""
    return open_sim
