"""Fixtures of the live project tests: the communication server's ConnectionManager with its embedded simulated
drives (bus spec ``sim``: XtrapulsPac nodes 1, 2, 3 in this process, real time) and a project store on it.

One simulation serves the session (starting one costs a second); each module uses its own project names and sets
or reads back every drive value it checks. `service` here overrides the offline store of the parent folder's
conftest: a live test works on the session's store, which the simulated drives' axes are scanned into."""

from __future__ import annotations

import pytest
from tests.support.embedded_sim import open_sim

from servostudio.od import builtin_library
from servostudio.services.bus import ConnectionManager
from servostudio.services.projects import ProjectService
from servostudio.services.projects.live import LiveProjects


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
