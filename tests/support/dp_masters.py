"""The simulated PROFIBUS-DP line of the transport and drive tests, and the two DP masters that reach it: pyprofibus's
DPM1 over the line's pseudo-terminal (the transport of a serial `profibus:` bus) and the project's own master over
its TCP stream (`profibus:socket://…`)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from servostudio.drive.access import Drive
from servostudio.drive.profibus.engine import PkwEngine
from servostudio.drive.profibus.link import ProfibusLink
from servostudio.drive.profiles import profile_for
from servostudio.od.pnu import builtin_parameter_list
from servostudio.sim.plant import Plant
from servostudio.sim.profibus.endpoints import ProfibusPty, ProfibusTcpServer
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.slave import TtaProSlave
from servostudio.transport.profibus.interface import DpLine
from servostudio.transport.profibus.master import ByteLink, DpMaster
from servostudio.transport.profibus.pyprofibus_master import PyprofibusMaster

PYPROFIBUS = "pyprofibus over the pty"
OWN_MASTER = "own master over TCP"
TRANSPORTS = (PYPROFIBUS, OWN_MASTER)
IDENT = 0x00C7


@contextlib.contextmanager
def simulated_line(*addresses: int) -> Iterator[ProfibusLine]:
    """Commissioned TTA-PROs at `addresses`, running on the wall clock, without an endpoint yet."""
    parameters = builtin_parameter_list()
    line = ProfibusLine([TtaProSlave(address, parameters, Plant.commissioned()) for address in addresses])
    line.start()
    try:
        yield line
    finally:
        line.stop()


@contextlib.contextmanager
def dp_master(transport: str, line: ProfibusLine) -> Iterator[DpLine]:
    """A master of `transport` on the line, with the line's endpoint it needs."""
    if transport == PYPROFIBUS:
        endpoint: ProfibusPty | ProfibusTcpServer = ProfibusPty(line).start()
    else:
        endpoint = ProfibusTcpServer(line).start()
    try:
        with contextlib.closing(_master(endpoint)) as master:
            yield master
    finally:
        endpoint.stop()


@contextlib.contextmanager
def dp_drive(transport: str, line: ProfibusLine, address: int) -> Iterator[Drive]:
    """The TTA-PRO at ``address`` as a `Drive` on the PKW engine, through a master of ``transport``."""
    with dp_master(transport, line) as master:
        parameters = builtin_parameter_list()
        link = ProfibusLink("pb", master)
        link.start()
        try:
            yield Drive(PkwEngine(link, lambda node: parameters), address, parameters, profile_for("ttapro"))
        finally:
            link.close()


def _master(endpoint: ProfibusPty | ProfibusTcpServer) -> DpLine:
    if isinstance(endpoint, ProfibusPty):
        return PyprofibusMaster(endpoint.path)
    return DpMaster(ByteLink("socket://{}:{}".format(*endpoint.address)))
