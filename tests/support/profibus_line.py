"""A simulated TTA-PRO on a PROFIBUS-DP line, reached over its TCP byte stream as the product reaches a line: the
bus spec ``profibus:tcp:HOST:PORT`` (the simulator's ``--profibus-tcp``), the slave running in this process."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from servostudio.od.pnu import builtin_parameter_list
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
