"""pyprofibus's DPM1 behind the package's master interface, against the simulated TTA-PRO over the line's
pseudo-terminal (real telegrams through pyprofibus's serial PHY): scan, parameterisation into data exchange,
refusals, Global_Control, corrupted telegrams, a cut line reported and recovered, the `profibus:` spec choosing the
master, and nothing printed on standard output."""

from __future__ import annotations

import logging
import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from tests.support.dp_masters import IDENT, simulated_line
from tests.support.waits import eventually

from servostudio.drive.profibus.client import ProfibusLinkDown, TtaProClient
from servostudio.errors import ServoStudioError
from servostudio.sim.profibus.endpoints import ProfibusPty, ProfibusTcpServer
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.station import StationState
from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus.master import DpLinkError, DpMaster, DpNoResponse, DpRefused
from servostudio.transport.profibus.open import ProfibusExtraMissing, open_dp_line
from servostudio.transport.profibus.ppo import PPO2, Ppo
from servostudio.transport.profibus.pyprofibus_master import CONNECT_TIMEOUT, PyprofibusMaster
from servostudio.transport.profibus.scan import scan
from servostudio.transport.spec import parse_bus_spec

ADDRESSES = (5, 9)


@pytest.fixture
def line() -> Iterator[ProfibusLine]:
    with simulated_line(*ADDRESSES) as line:
        yield line


@pytest.fixture
def pty(line: ProfibusLine) -> Iterator[ProfibusPty]:
    pty = ProfibusPty(line).start()
    yield pty
    pty.stop()


@pytest.fixture
def master(pty: ProfibusPty) -> Iterator[PyprofibusMaster]:
    master = PyprofibusMaster(pty.path)
    yield master
    master.close()


def _exchange(master: PyprofibusMaster, address: int, ppo: Ppo = PPO2, watchdog: float | None = 0.2):
    received: list[bytes] = []
    exchange = master.exchange(
        address, ppo, lambda: bytes(ppo.length), received.append, lambda _: None, 0.002, watchdog
    )
    return exchange, received


def test_a_scan_during_data_exchange_finds_the_stations_and_keeps_the_exchange(
    master: PyprofibusMaster, line: ProfibusLine
) -> None:
    client = TtaProClient(master, 5).start()
    try:
        started = time.monotonic()
        found = scan(master, range(3, 126))
        elapsed = time.monotonic() - started
        assert sorted(found) == list(ADDRESSES) and {d.ident_number for d in found.values()} == {IDENT}
        assert found[9].status_2 & dp.DIAG_PRM_REQUEST  # not parameterised yet
        assert found[5].master_address == master.address  # locked to us, in data exchange
        assert elapsed < 10.0  # 123 addresses, 20 ms for each absent one: about 3.5 s
        assert client.exchange.error is None and line.slaves[5].station.state is StationState.DATA_EXCHANGE
        assert client.read(700, double=False, signed=False) == 4
    finally:
        client.close()
    with pytest.raises(DpNoResponse, match="DP station 33 did not answer Slave_Diag") as caught:
        master.slave_diag(33, timeout=0.01)
    assert isinstance(caught.value, ServoStudioError) and caught.value.outcome.http_status == 504


def test_dpm1_parameterises_the_slave_with_the_ppo_and_the_watchdog(
    master: PyprofibusMaster, line: ProfibusLine
) -> None:
    exchange, received = _exchange(master, 5, watchdog=0.5)
    exchange.start()
    try:
        station = line.slaves[5].station
        assert station.state is StationState.DATA_EXCHANGE and station.master == master.address
        assert station.watchdog == pytest.approx(0.5)
        eventually(lambda: len(received) > 10)
        assert {len(image) for image in received} == {PPO2.length}
        assert line.slaves[9].station.state is StationState.WAIT_PRM  # the other station is untouched
    finally:
        exchange.stop()


def test_a_refused_configuration_is_a_readable_error_at_once(master: PyprofibusMaster) -> None:
    exchange, _ = _exchange(master, 5, ppo=Ppo("PPO9", has_pkw=True, pzd_words=3))
    started = time.monotonic()
    with pytest.raises(DpRefused, match=r"^DP station 5 refused parameterisation: .*configuration"):
        exchange.start()
    # DPM1's fault report ends the start-up, not the connect time-out it would otherwise wait out
    assert time.monotonic() - started < CONNECT_TIMEOUT / 2


def test_global_control_reaches_the_stations_in_data_exchange(master: PyprofibusMaster, line: ProfibusLine) -> None:
    exchange, _ = _exchange(master, 5, watchdog=None)
    exchange.start()
    try:
        station = line.slaves[5].station
        master.global_control(dp.SYNC | dp.FREEZE)
        eventually(lambda: station.sync and station.freeze)
        master.global_control(dp.UNSYNC | dp.UNFREEZE)
        eventually(lambda: not station.sync and not station.freeze)
    finally:
        exchange.stop()


def test_corrupted_telegrams_are_dropped_and_the_link_survives(master: PyprofibusMaster, pty: ProfibusPty) -> None:
    client = TtaProClient(master, 5, watchdog=1.0).start()  # a loaded host's stall is not what is judged here
    try:
        garbage = (
            bytes((0x10, 2, 5, 0x08, 0x00, 0x16)),  # SD1 with a wrong FCS
            b"\x68\x05\x06\x68" + bytes(9),  # LE != LEr
            bytes((0xA2, 2, 5, 0x08)) + bytes(8) + b"\x0d\x17",  # SD3 with a wrong end delimiter
            b"\x11\x22\x33",  # no start delimiter at all
        )
        for _ in range(2):
            for noise in garbage:
                os.write(pty._master, noise)  # bytes on the line towards the master, between the responses
                assert client.read(700, double=False, signed=False) == 4
        assert client.exchange.error is None
    finally:
        client.close()


def test_a_missing_slave_does_not_starve_the_others_of_the_line(pty: ProfibusPty, line: ProfibusLine) -> None:
    """While DPM1 tries to get station 9 back, station 5 keeps being served (times loosened ×3 and the watchdog
    to 1 s for a loaded test host: what is checked is that 9's reconnection windows leave the line to 5)."""
    master = PyprofibusMaster(pty.path, timeout=0.3)
    healthy, missing = TtaProClient(master, 5, watchdog=1.0).start(), TtaProClient(master, 9, watchdog=1.0).start()
    try:
        with line.lock:
            slave = line.slaves.pop(9)
        eventually(lambda: missing.exchange.error is not None)
        cycles = healthy.exchange.cycles
        time.sleep(1.0)
        assert healthy.exchange.error is None and healthy.exchange.cycles > cycles + 50
        assert line.slaves[5].station.state is StationState.DATA_EXCHANGE  # its watchdog never ran out
        with line.lock:
            line.slaves[9] = slave
        eventually(lambda: missing.exchange.error is None)
        assert missing.read(700, double=False, signed=False) == 4
    finally:
        healthy.close()
        missing.close()
        master.close()


def test_a_cut_line_is_reported_and_recovered(line: ProfibusLine, tmp_path: Path) -> None:
    """The port behind a stable name (an adapter's udev symlink) goes away and comes back."""
    port = tmp_path / "ttyPROFIBUS"
    first = ProfibusPty(line).start()
    port.symlink_to(first.path)
    master = PyprofibusMaster(str(port))
    client = TtaProClient(master, 5).start()
    second = None
    try:
        assert client.read(700, double=False, signed=False) == 4
        first.stop()  # the cable is pulled: the port fails
        eventually(lambda: isinstance(client.exchange.error, DpLinkError))
        assert str(port) in str(client.exchange.error)
        with pytest.raises(ProfibusLinkDown, match=f"PNU 700: .*PROFIBUS line {port}"):
            client.read(700, double=False, signed=False)
        second = ProfibusPty(line).start()  # plugged in again
        port.unlink()
        port.symlink_to(second.path)
        eventually(lambda: client.exchange.error is None)
        assert client.read(700, double=False, signed=False) == 4
    finally:
        client.close()
        master.close()
        if second is not None:
            second.stop()


def test_an_unopenable_line_is_an_error_naming_it(tmp_path: Path) -> None:
    with pytest.raises(DpLinkError, match=f"cannot open PROFIBUS line {tmp_path}/none") as caught:
        PyprofibusMaster(f"{tmp_path}/none")
    assert caught.value.outcome.http_status == 503


def test_the_bus_spec_chooses_pyprofibus_for_a_serial_line(line: ProfibusLine, pty: ProfibusPty) -> None:
    master = open_dp_line(parse_bus_spec(f"profibus:{pty.path}@19200?master=1"))
    try:
        assert isinstance(master, PyprofibusMaster)
        assert (master.port, master.baudrate, master.address) == (pty.path, 19200, 1)
        assert master.slave_diag(5).ident_number == IDENT
    finally:
        master.close()
    server = ProfibusTcpServer(line).start()
    try:
        own = open_dp_line(parse_bus_spec("profibus:tcp:{}:{}".format(*server.address)))  # pyprofibus has no TCP
        assert isinstance(own, DpMaster)
        own.close()
    finally:
        server.stop()


def test_without_the_extra_a_serial_line_names_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "servostudio.transport.profibus.pyprofibus_master", None)
    with pytest.raises(ProfibusExtraMissing, match=r"pip install 'servostudio\[profibus\]'") as caught:
        open_dp_line(parse_bus_spec("profibus:/dev/ttyUSB0"))
    assert caught.value.outcome.http_status == 503


def test_pyprofibus_prints_nothing_its_messages_go_to_the_log(
    pty: ProfibusPty, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    """The CLI's standard output carries JSON: pyprofibus's baud rate note and DPM1's fault reports are logged."""
    caplog.set_level(logging.INFO, logger="servostudio.transport.profibus.pyprofibus_master")
    master = PyprofibusMaster(pty.path)
    try:
        exchange, _ = _exchange(master, 5, ppo=Ppo("PPO9", has_pkw=True, pzd_words=3))
        with pytest.raises(DpRefused):
            exchange.start()
    finally:
        master.close()
    assert capsys.readouterr().out == ""
    assert "1500000 baud might not be supported" in caplog.text and "faulty configuration" in caplog.text
