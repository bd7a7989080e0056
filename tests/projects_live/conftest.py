"""Fixtures of the live project tests: the communication server's ConnectionManager with its embedded simulated
drives (bus spec ``sim``: XtrapulsPac nodes 1, 2, 3 in this process, real time) and a project store on it.

One simulation serves the session (starting one costs a second); each module uses its own project names and sets
or reads back every drive value it checks."""

from __future__ import annotations

import sys

import pytest

from servostudio.od import builtin_library
from servostudio.services.bus import ConnectionManager
from servostudio.services.projects import ProjectService
from servostudio.services.projects.live import LiveProjects

# The simulated drives, the bus reader and the test share one interpreter: a short GIL switch interval keeps each
# SDO round trip at a fraction of a millisecond instead of 5 ms.
sys.setswitchinterval(0.0002)

#: The machine is shared by many processes; a drive in this process may answer late, never wrongly.
SDO_TIMEOUT = 1.0


def open_sim(manager: ConnectionManager, spec: str = "sim") -> None:
    """Open the simulated bus the way the project code will find it (same spec, shared) with a patient timeout."""
    connection = manager.open(spec, wait=5.0)
    assert connection.link.wait_connected(5.0)  # an already open bus is returned without waiting
    connection.engine.timeout = SDO_TIMEOUT


@pytest.fixture(scope="session")
def sim_opener():
    return open_sim


@pytest.fixture(scope="session")
def manager():
    connections = ConnectionManager(builtin_library())
    open_sim(connections)
    yield connections
    connections.close_all()


@pytest.fixture(scope="session")
def service(tmp_path_factory) -> ProjectService:
    root = tmp_path_factory.mktemp("live-store")
    return ProjectService(root / "store", builtin_library(), motors_dir=root / "builtin-motors")


@pytest.fixture(scope="session")
def live(service: ProjectService, manager: ConnectionManager) -> LiveProjects:
    return LiveProjects(service, manager)
