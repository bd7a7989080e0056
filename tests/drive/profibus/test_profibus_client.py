"""The TTA-PRO client (PKW request/response and PZD words over the cyclic Data_Exchange) against the simulated slave,
through both DP masters — pyprofibus's DPM1 over the line's pseudo-terminal and the project's own over its TCP
stream: reads, writes, refusals, a procedure, the enabling state machine, a lost and recovered station, a cut
line."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.dp_masters import TRANSPORTS, dp_master, simulated_line
from tests.support.waits import eventually

from servostudio.drive.profibus.client import PkwTimeout, ProfibusLinkDown, TtaProClient
from servostudio.drive.profibus.pkw import read_request
from servostudio.drive.profibus.pkw_errors import PkwRefused
from servostudio.drive.profibus.pzd import ENABLING_SEQUENCE, DriveState, drive_state
from servostudio.errors import Conflict
from servostudio.sim.profibus.endpoints import ProfibusTcpServer
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.transport.profibus.master import ByteLink, DpMaster

ADDRESS = 5


@pytest.fixture
def line() -> Iterator[ProfibusLine]:
    with simulated_line(ADDRESS) as line:
        yield line


@pytest.fixture(params=TRANSPORTS)
def client(request: pytest.FixtureRequest, line: ProfibusLine) -> Iterator[TtaProClient]:
    with dp_master(request.param, line) as master:
        client = TtaProClient(master, ADDRESS).start()
        yield client
        client.close()


def test_pnus_read_and_write_with_their_width_and_sign(client: TtaProClient) -> None:
    assert client.read(700, double=False, signed=False) == 4  # pole pairs of the commissioned axis
    assert client.read(700, double=False, signed=False) == 4  # the same read twice: the separator at work
    client.write(760, 1000, double=False)
    assert client.read(760, double=False, signed=False) == 1000
    client.write(767, -4096, double=True)  # a signed double word (PZD5-6 override it in the default mapping)
    client.write(757, 70000, double=True)
    assert client.read(757, double=True, signed=False) == 70000
    assert client.read(828, double=False, signed=False, index=2) == 0x2306  # feedback mapping slot 2


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda c: c.read(999, double=False, signed=False), r"^PNU 999: illegal PNU \(PKW error 0\)$"),
        (lambda c: c.write(774, 1, double=False), r"^PNU 774: parameter cannot be modified \(PKW error 1\)$"),
        (lambda c: c.write(700, 40, double=False), r"^PNU 700: lower or upper limit exceeded \(PKW error 2\)$"),
        (lambda c: c.read(700, double=False, signed=False, index=3), r"^PNU 700\[3\]: index error"),
    ],
)
def test_a_negative_reply_is_a_readable_error_naming_the_pnu(client: TtaProClient, call, message: str) -> None:
    with pytest.raises(PkwRefused, match=message) as caught:
        call(client)
    assert isinstance(caught.value, Conflict)
    assert client.read(700, double=False, signed=False) == 4  # the channel goes on


def test_a_procedure_holds_its_request_until_done(client: TtaProClient, line: ProfibusLine) -> None:
    client.write(757, 1234, double=True)  # INPOS window, an E parameter
    assert line.slaves[ADDRESS].memory.eeprom[(757, 0)] != 1234
    client.run_procedure(729)  # save to EEPROM: PWE 0 while it runs, then 1
    assert line.slaves[ADDRESS].memory.eeprom[(757, 0)] == 1234


def test_the_control_word_walks_the_state_machine(client: TtaProClient) -> None:
    expected = (
        DriveState.ENABLE_INHIBITED,
        DriveState.READY_FOR_ENABLE,
        DriveState.READY,
        DriveState.OPERATION_ENABLED,
    )
    for word, state in zip(ENABLING_SEQUENCE, expected, strict=True):
        _command(client, word, state)
    _command(client, ENABLING_SEQUENCE[1], DriveState.READY_FOR_ENABLE)  # OFF: ramp stop and disable


def _command(client: TtaProClient, control_word: int, state: DriveState) -> None:
    client.set_output(0, control_word)
    eventually(lambda: drive_state(client.status_word) is state)


def test_a_silent_slave_is_reported_and_recovered(client: TtaProClient, line: ProfibusLine) -> None:
    assert client.read(700, double=False, signed=False) == 4
    client.exchange.master.timeout = 0.02
    with line.lock:
        slave = line.slaves.pop(ADDRESS)  # the station stops answering (cable pulled)
    eventually(lambda: client.exchange.error is not None)
    with pytest.raises(ProfibusLinkDown, match="PNU 700: DP station 5 did not answer"):
        client.read(700, double=False, signed=False)
    with line.lock:
        line.slaves[ADDRESS] = slave
    eventually(lambda: client.exchange.error is None)
    assert client.read(700, double=False, signed=False) == 4


def test_a_cut_tcp_line_is_reported_and_reopened(line: ProfibusLine) -> None:
    server = ProfibusTcpServer(line).start()
    host, port = server.address
    master = DpMaster(ByteLink(f"socket://{host}:{port}"), timeout=0.02)
    client = TtaProClient(master, ADDRESS).start()
    try:
        assert client.read(700, double=False, signed=False) == 4
        server.stop()  # the line is cut: the connection closes
        eventually(lambda: client.exchange.error is not None)
        assert "PROFIBUS line" in str(client.exchange.error) or "did not answer" in str(client.exchange.error)
        server = ProfibusTcpServer(line, host, port).start()  # and comes back on the same port
        eventually(lambda: client.exchange.error is None, timeout=5.0)
        assert client.read(700, double=False, signed=False) == 4
    finally:
        client.close()
        master.close()
        server.stop()


def test_a_reply_that_never_comes_times_out(client: TtaProClient, line: ProfibusLine) -> None:
    line.slaves[ADDRESS].pkw.cycle = lambda: None  # type: ignore[method-assign]  # the PKW server stops serving
    with pytest.raises(PkwTimeout, match=r"PNU 700: no PKW reply from station 5 within 0\.2 s"):
        client.transaction(read_request(700), timeout=0.2)
