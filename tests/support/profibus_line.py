"""A simulated TTA-PRO on a PROFIBUS-DP line, reached over its TCP byte stream as the product reaches a line: the
bus spec ``profibus:tcp:HOST:PORT`` (the simulator's ``--profibus-tcp``), the slave running in this process."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client

from servostudio.od.pnu import builtin_parameter_list
from servostudio.services.settings import Settings
from servostudio.sim.plant import Plant
from servostudio.sim.profibus.endpoints import ProfibusTcpServer
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.slave import TtaProSlave


@dataclass(frozen=True)
class TtaProLine:
    spec: str
    line: ProfibusLine
    slaves: dict[int, TtaProSlave]


@contextmanager
def ttapro_line(*addresses: int) -> Iterator[TtaProLine]:
    """Simulated TTA-PROs at ``addresses`` (commissioned plants) on one line with a TCP endpoint."""
    parameters = builtin_parameter_list()
    slaves = {address: TtaProSlave(address, parameters, Plant.commissioned()) for address in addresses}
    line = ProfibusLine(list(slaves.values()))
    line.start()
    server = ProfibusTcpServer(line).start()
    try:
        yield TtaProLine("profibus:tcp:{}:{}".format(*server.address), line, slaves)
    finally:
        server.stop()
        line.stop()


@contextmanager
def tool_on_line(root: Path, line: TtaProLine) -> Iterator[TestClient]:
    """An administrator's REST client of a server in this process with the line opened as bus ``pb``."""
    app = admin_app(Settings(projects_dir=root / "store", static_dir=root / "no-ui", buses=[]), root / "data")
    with api_client(app) as client:
        opened = client.post("/api/buses", json={"spec": line.spec, "id": "pb"})
        assert opened.status_code == 201, opened.text
        yield client
