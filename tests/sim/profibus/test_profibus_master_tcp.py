"""Acceptance of the simulated TTA-PRO through an independent DP master over the TCP byte stream: parameterise,
read and write PNUs through PKW (refusals included), walk the PZD state machine through an enabling, a positioner
move and a disabling, and survive corrupted telegrams (TTA-PRO Profibus Communication Profile, Chapters 1-2)."""

from __future__ import annotations

import struct
import time
from collections.abc import Iterator

import pytest
from tests.sim.profibus.dp_test_master import ENABLING, TestMaster, pkw, sd1

from servostudio.od.pnu import builtin_parameter_list
from servostudio.sim.plant import Plant
from servostudio.sim.profibus.endpoints import ProfibusTcpServer
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.slave import TtaProSlave

ADDRESS = 5
REFUSED = 7
ZSW_ENABLED_MASK, ZSW_ENABLED = 0x033F, 0x0337
POSITION_REACHED, ACKNOWLEDGE = 0x0400, 0x1000
STAGE = 0x004F
"""ZSW bits 0-3 and 6: the enabling stage."""
ABSOLUTE_MOVE = 0x1000


@pytest.fixture
def line() -> Iterator[ProfibusLine]:
    line = ProfibusLine([TtaProSlave(ADDRESS, builtin_parameter_list(), Plant.commissioned())])
    line.start()
    yield line
    line.stop()


@pytest.fixture
def master(line: ProfibusLine) -> Iterator[TestMaster]:
    server = ProfibusTcpServer(line).start()
    master = TestMaster(*server.address, slave=ADDRESS)
    yield master
    master.close()
    server.stop()


def test_an_unparameterised_slave_asks_for_parameters_and_names_its_ident_number(master: TestMaster) -> None:
    diag = master.diagnosis()
    assert diag[0] & 0x02  # station not ready
    assert diag[1] & 0x05 == 0x05  # Prm_Req and the bit that is always 1
    assert diag[3] == 0xFF  # no master yet
    assert diag[4:6] == b"\x00\xc7"


def test_a_wrong_ident_number_or_configuration_is_reported_and_nothing_is_exchanged(master: TestMaster) -> None:
    assert master.set_prm(ident=0x1234) == "SC"
    assert master.diagnosis()[0] & 0x40  # Prm_Fault
    assert master.set_prm() == "SC"
    assert master.chk_cfg(bytes((0xF3, 0xF7))) == "SC"  # PPO5-like: not supported
    assert master.diagnosis()[0] & 0x04  # Cfg_Fault
    assert master.request(bytes(20))[:2] == ("SD1", 0x03)  # Data_Exchange refused: no service


def test_pkw_reads_and_writes_parameters(master: TestMaster) -> None:
    master.parameterise()
    assert master.read(700) == (1, 700, 0, 4)  # pole pairs of the commissioned axis
    assert master.read(771)[3] == 0x0301  # PROFIBUS software version
    assert master.write(760, 1000) == (1, 760, 0, 1000)
    assert master.read(760)[3] == 1000
    assert master.write(767, -4096 & 0xFFFFFFFF, double=True)[3] == 0xFFFFF000
    assert master.read(828, index=2) == (1, 828, 2, 0x2306)  # default feedback mapping slot 2: motor position


@pytest.mark.parametrize(
    ("request_bytes", "error"),
    [
        (pkw(1, 999), 0),  # illegal PNU
        (pkw(2, 774, 0, 1), 1),  # read-only
        (pkw(2, 700, 0, 40), 2),  # pole pairs 1..32
        (pkw(1, 700, 3), 3),  # index on a plain PNU
        (pkw(3, 700, 0, 4), 5),  # a double word for a word
    ],
)
def test_pkw_refusals_carry_the_manuals_error_numbers(master: TestMaster, request_bytes: bytes, error: int) -> None:
    master.parameterise()
    reply = master.transaction(request_bytes)
    assert (reply[0], reply[3]) == (REFUSED, error)


def test_the_pzd_state_machine_enables_moves_and_disables(master: TestMaster) -> None:
    master.parameterise()
    master.write(760, 1500)  # manual move speed, rpm
    master.write(761, 100)
    master.write(762, 100)
    master.write(757, 8, double=True)  # INPOS window ...
    master.write(742, 1 << 13)  # ... enabled: "position reached" means within 8 increments
    master.status_after(ENABLING[0], STAGE, 0x0040)  # ENABLE inhibited
    master.status_after(ENABLING[1], STAGE, 0x0001)  # Ready for ENABLE
    master.status_after(ENABLING[2], STAGE, 0x0003)  # Ready
    enabled = master.status_after(ENABLING[3], ZSW_ENABLED_MASK, ZSW_ENABLED)  # Operation enabled
    master.pzd[4:6] = struct.unpack(">2H", struct.pack(">i", 8192))  # two revolutions, PZD5 = MSW
    acknowledged = (enabled & ACKNOWLEDGE) ^ ACKNOWLEDGE
    master.status_after(ENABLING[3] | ABSOLUTE_MOVE, ACKNOWLEDGE, acknowledged)
    words = _wait_for_position_reached(master)
    assert abs(struct.unpack(">i", struct.pack(">2H", *words[4:6]))[0] - 8192) <= 8  # PZD5-6 motor position
    master.status_after(ENABLING[1], STAGE, 0x0001)  # OFF1: ramp stop, back to Ready for ENABLE


def _wait_for_position_reached(master: TestMaster) -> list[int]:
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline:
        _, words = master.exchange(pkw(0, 0))
        if words[0] & POSITION_REACHED:
            return words
        time.sleep(0.002)
    raise AssertionError("the move never reached its position")


def test_corrupted_telegrams_are_dropped_and_the_link_survives(master: TestMaster, line: ProfibusLine) -> None:
    master.parameterise()
    good = sd1(ADDRESS, 0x49)  # FDL status request
    for corrupted in (
        good[:4] + bytes(((good[4] + 1) & 0xFF,)) + good[5:],  # FCS
        good[:5] + b"\x17",  # end delimiter
        b"\x68\x05\x06\x68" + bytes(9),  # LE and its repetition differ
        b"\x11" + good[1:],  # start delimiter
    ):
        master.send(corrupted)
        assert master.receive(timeout=0.05) is None
    assert master.read(700)[3] == 4
    rejected = [reason for port in line._ports for reason in port.decoder.rejected]
    assert any("FCS" in reason for reason in rejected)
    assert any("end delimiter" in reason for reason in rejected)


def test_a_silent_master_loses_the_slave_and_an_enabled_drive_trips_on_a_bus_error(master: TestMaster) -> None:
    master.parameterise(watchdog_ms=100)
    for control, value in zip(ENABLING, (0x0040, 0x0001, 0x0003, 0x0007), strict=True):
        master.status_after(control, STAGE, value)
    time.sleep(0.4)
    assert master.diagnosis()[1] & 0x01  # back in Wait_Prm: Prm_Req
    master.parameterise(watchdog_ms=100)
    master.status_after(0x0400, 0x0008, 0x0008)  # error
    assert master.read(755)[3] == 13  # bus error
    assert master.read(773)[3] & 1 << 5  # 773 byte 1 bit 5: BUS
