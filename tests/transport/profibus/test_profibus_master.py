"""The project's DP master against the simulated TTA-PRO over its TCP byte stream (real telegrams on a socket):
scan, parameterisation, Data_Exchange, FCB repetition, refusals, corrupted input, a cut line."""

from __future__ import annotations

import socket
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.errors import ServoStudioError
from servostudio.od.pnu import builtin_parameter_list
from servostudio.sim.plant import Plant
from servostudio.sim.profibus.endpoints import ProfibusPty, ProfibusTcpServer
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.slave import TtaProSlave
from servostudio.sim.profibus.station import StationState
from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus.dp_services import SetPrm
from servostudio.transport.profibus.master import ByteLink, DpLinkError, DpMaster, DpNoResponse, DpRefused, prm_for
from servostudio.transport.profibus.ppo import PPO1, PPO2
from servostudio.transport.profibus.scan import scan
from servostudio.transport.profibus.telegram import ED, SD1

ADDRESSES = (5, 9)
IDENT = 0x00C7


@pytest.fixture
def line() -> Iterator[ProfibusLine]:
    parameters = builtin_parameter_list()
    line = ProfibusLine([TtaProSlave(address, parameters, Plant.commissioned()) for address in ADDRESSES])
    line.start()
    yield line
    line.stop()


@pytest.fixture
def server(line: ProfibusLine) -> Iterator[ProfibusTcpServer]:
    server = ProfibusTcpServer(line).start()
    yield server
    server.stop()


@pytest.fixture
def master(server: ProfibusTcpServer) -> Iterator[DpMaster]:
    master = DpMaster(ByteLink("socket://{}:{}".format(*server.address)))
    yield master
    master.close()


def test_a_scan_finds_the_stations_and_their_ident_numbers_quickly(master: DpMaster) -> None:
    found = scan(master, range(1, 126))
    assert sorted(found) == list(ADDRESSES)
    assert {diag.ident_number for diag in found.values()} == {IDENT}
    assert all(diag.status_2 & dp.DIAG_PRM_REQUEST for diag in found.values())


def test_parameterisation_brings_the_slave_into_data_exchange(master: DpMaster, line: ProfibusLine) -> None:
    diag = master.parameterise(5, PPO2, watchdog=0.5, ident_number=IDENT)
    assert diag.master_address == master.address and diag.status_2 & dp.DIAG_WATCHDOG_ON
    assert line.slaves[5].station.state is StationState.DATA_EXCHANGE
    assert line.slaves[5].station.watchdog == pytest.approx(0.5)
    inputs = master.data_exchange(5, bytes(PPO2.length))
    assert len(inputs) == PPO2.length
    assert line.slaves[9].station.state is StationState.WAIT_PRM  # the other station is untouched


def test_global_control_reaches_the_stations_in_data_exchange(master: DpMaster, line: ProfibusLine) -> None:
    master.parameterise(5, PPO2, watchdog=None, ident_number=IDENT)
    station = line.slaves[5].station
    master.global_control(dp.SYNC | dp.FREEZE)
    master.data_exchange(5, bytes(PPO2.length))  # answered after the broadcast: it has been handled
    assert station.sync and station.freeze
    master.global_control(dp.UNSYNC | dp.UNFREEZE)
    master.data_exchange(5, bytes(PPO2.length))
    assert not station.sync and not station.freeze


def test_refusals_are_errors_of_the_one_root_with_readable_reasons(master: DpMaster) -> None:
    with pytest.raises(DpRefused, match=r"station 5 refused parameterisation: .*ident number"):
        master.parameterise(5, PPO2, watchdog=None, ident_number=0x1234)
    with pytest.raises(DpRefused, match=r"station 5 refused Data_Exchange: service not activated \(RS\)"):
        master.data_exchange(5, bytes(PPO2.length))
    with pytest.raises(DpNoResponse, match="station 33 did not answer Slave_Diag") as caught:
        master.slave_diag(33, timeout=0.01)
    assert isinstance(caught.value, ServoStudioError) and caught.value.outcome.http_status == 504


def test_a_wrong_ppo_length_is_refused_by_the_slave(master: DpMaster) -> None:
    master.parameterise(5, PPO1, watchdog=None, ident_number=IDENT)
    assert len(master.data_exchange(5, bytes(PPO1.length))) == PPO1.length
    with pytest.raises(DpRefused, match="RS"):
        master.data_exchange(5, bytes(PPO2.length))


def test_a_repeated_request_keeps_its_frame_count_bit(master: DpMaster, line: ProfibusLine) -> None:
    """The first request goes with FCV clear; a request whose response got lost is repeated with the same FCB and
    answered from the station's memory, not executed again."""
    master.slave_diag(5)
    first = master._next_function(5)
    master.slave_diag(5)
    assert master._next_function(5) == first ^ 0x20  # toggled after each answered request
    with pytest.raises(DpNoResponse):
        master.slave_diag(77, timeout=0.01)
    assert 77 not in master._frame_count  # forgotten: the next request starts with FCV clear


def test_corrupted_bytes_on_the_line_do_not_break_the_master(master: DpMaster, server: ProfibusTcpServer) -> None:
    master.parameterise(5, PPO2, watchdog=None, ident_number=IDENT)
    master.link.write(bytes((SD1, 5, 2, 0x49, 0x00, ED)) + b"\x68\x05\x06\x68" + bytes(9))  # bad FCS, bad LE
    assert len(master.data_exchange(5, bytes(PPO2.length))) == PPO2.length
    assert master.decoder.feed(b"\x11\x22" + bytes((SD1, 2, 5, 0x08, 0x0F, ED))) != []  # resynchronises


def test_a_cut_line_is_an_error_naming_the_line() -> None:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    with pytest.raises(DpLinkError, match=f"cannot open PROFIBUS line socket://127.0.0.1:{port}"):
        ByteLink(f"socket://127.0.0.1:{port}")


def test_the_master_speaks_over_the_pseudo_terminal_too(line: ProfibusLine) -> None:
    pty = ProfibusPty(line).start()
    master = DpMaster(ByteLink(pty.path))
    try:
        assert master.parameterise(9, PPO2, watchdog=None, ident_number=IDENT).master_address == master.address
        assert len(master.data_exchange(9, bytes(PPO2.length))) == PPO2.length
    finally:
        master.close()
        pty.stop()


@given(st.floats(0.01, 600.0))
def test_the_watchdog_factors_give_the_asked_time(seconds: float) -> None:
    prm = prm_for(IDENT, seconds)
    assert 1 <= prm.watchdog_factor_1 <= 255 and 1 <= prm.watchdog_factor_2 <= 255
    assert prm.watchdog == pytest.approx(seconds, rel=0.01, abs=0.0051)  # 10 ms units
    assert SetPrm.decode(prm.encode()) == prm
    assert prm_for(IDENT, None).watchdog is None
