"""The DP-V0 slave station of the simulated TTA-PRO, telegram by telegram (EN 50170 vol. 2; TTA-PRO Profibus
Communication Profile, Chapter 1): parameterisation, the frame count bit repetition, the master lock, Global_Control
SYNC / FREEZE / CLEAR_DATA, and the watchdog."""

from __future__ import annotations

import struct

import pytest

from servostudio.od.pnu_model import ParameterDictionary
from servostudio.sim.plant import Plant
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.slave import TtaProSlave
from servostudio.sim.profibus.station import StationState
from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus import function_codes as fc
from servostudio.transport.profibus.ppo import PPO2, PPO3
from servostudio.transport.profibus.telegram import BROADCAST, Frame, ShortAcknowledge, Telegram, encode
from servostudio.transport.profibus.telegram_decoder import TelegramDecoder

ADDRESS, MASTER, OTHER_MASTER = 5, 2, 3


class Line:
    """The line through one port, with the project's codec (the TCP acceptance uses an independent one)."""

    def __init__(self, parameters: ParameterDictionary) -> None:
        self.slave = TtaProSlave(ADDRESS, parameters, Plant.commissioned())
        self.line = ProfibusLine([self.slave])
        self._out: list[bytes] = []
        self.port = self.line.open_port(self._out.append)
        self.fcb = {MASTER: 0, OTHER_MASTER: 0}

    def send(self, telegram: Telegram) -> Frame | None:
        self._out.clear()
        self.port.feed(encode(telegram))
        frames = TelegramDecoder().feed(b"".join(self._out))
        return frames[0] if frames else None

    def srd(
        self, data: bytes = b"", sap: int | None = None, master: int = MASTER, repeat: bool = False
    ) -> Frame | None:
        if not repeat:
            self.fcb[master] ^= 1
        function = fc.request_code(fc.SRD_HIGH, self.fcb[master])
        source_sap = None if sap is None else dp.MASTER_SAP
        return self.send(Telegram(ADDRESS, master, function, data, sap, source_sap))

    def diag(self, master: int = MASTER) -> dp.SlaveDiag:
        response = self.srd(sap=dp.SLAVE_DIAG_SAP, master=master)
        assert isinstance(response, Telegram)
        return dp.SlaveDiag.decode(response.data)

    def parameterise(self, ppo=PPO2, status: int = dp.STATUS_LOCK, group: int = 0) -> None:
        prm = dp.SetPrm(status, 1, 1, 0, 0x00C7, group)
        assert isinstance(self.srd(prm.encode(), dp.SET_PRM_SAP), ShortAcknowledge)
        assert isinstance(self.srd(ppo.identifiers, dp.CHK_CFG_SAP), ShortAcknowledge)

    def exchange(self, data: bytes, repeat: bool = False) -> Telegram:
        response = self.srd(data, repeat=repeat)
        assert isinstance(response, Telegram) and response.function == fc.DATA_LOW, response
        return response

    def global_control(self, command: int, group: int = 0) -> None:
        control = dp.GlobalControl(command, group).encode()
        function = fc.request_code(fc.SDN_HIGH)
        assert self.send(Telegram(BROADCAST, MASTER, function, control, dp.GLOBAL_CONTROL_SAP, dp.MASTER_SAP)) is None


@pytest.fixture
def bus(parameters: ParameterDictionary) -> Line:
    return Line(parameters)


def ppo3(control: int, command: int = 0) -> bytes:
    return struct.pack(">2H", control, command)


def test_fdl_status_is_answered_by_a_slave(bus: Line) -> None:
    response = bus.send(Telegram(ADDRESS, MASTER, fc.request_code(fc.FDL_STATUS)))
    assert response == Telegram(MASTER, ADDRESS, fc.OK)


def test_parameterisation_takes_the_slave_to_data_exchange(bus: Line) -> None:
    before = bus.diag()
    assert before.status_2 & dp.DIAG_PRM_REQUEST and not before.ready_for_data_exchange
    bus.parameterise()
    after = bus.diag()
    assert after.ready_for_data_exchange and after.master_address == MASTER and after.ident_number == 0x00C7
    assert bus.slave.station.state is StationState.DATA_EXCHANGE
    config = bus.srd(sap=dp.GET_CONFIG_SAP)
    assert isinstance(config, Telegram) and config.data == PPO2.identifiers


def test_a_repeated_request_gets_the_previous_response_without_being_executed(bus: Line) -> None:
    bus.parameterise(PPO3)
    first = bus.exchange(ppo3(0x0400))
    bus.line.advance(0.01)
    repeated = bus.exchange(ppo3(0x0406), repeat=True)  # same FCB: the slave keeps its answer, ignores the data
    assert repeated == first
    assert bus.slave.drive.words[0] == 0x0400


def test_another_master_is_locked_out(bus: Line) -> None:
    bus.parameterise()
    assert bus.diag(OTHER_MASTER).status_1 & dp.DIAG_MASTER_LOCK
    refused = bus.srd(bytes(PPO2.length), master=OTHER_MASTER)
    assert isinstance(refused, Telegram) and refused.function == fc.NO_SERVICE


def test_data_of_the_wrong_length_is_refused(bus: Line) -> None:
    bus.parameterise(PPO3)
    refused = bus.srd(bytes(6))
    assert isinstance(refused, Telegram) and refused.function == fc.NO_SERVICE


def test_sync_holds_the_outputs_until_the_next_sync(bus: Line) -> None:
    bus.parameterise(PPO3)
    bus.exchange(ppo3(0x0400))
    bus.global_control(dp.SYNC)
    bus.exchange(ppo3(0x0406))
    assert bus.slave.drive.words[0] == 0x0400
    assert bus.diag().status_2 & dp.DIAG_SYNC_MODE
    bus.global_control(dp.SYNC)
    assert bus.slave.drive.words[0] == 0x0406
    bus.exchange(ppo3(0x0407))
    bus.global_control(dp.UNSYNC)
    assert bus.slave.drive.words[0] == 0x0407


def test_freeze_holds_the_inputs_until_the_next_freeze(bus: Line) -> None:
    bus.parameterise(PPO3)
    bus.exchange(ppo3(0x0400))
    bus.line.advance(0.01)
    bus.global_control(dp.FREEZE)
    frozen = bus.exchange(ppo3(0x0406)).data
    bus.line.advance(0.01)
    assert bus.exchange(ppo3(0x0406)).data == frozen
    bus.global_control(dp.UNFREEZE)
    assert bus.exchange(ppo3(0x0406)).data != frozen  # Ready for ENABLE now shows


def test_global_control_for_another_group_is_ignored(bus: Line) -> None:
    bus.parameterise(PPO3, group=0x01)
    bus.exchange(ppo3(0x0400))
    bus.global_control(dp.CLEAR_DATA, group=0x02)
    assert bus.slave.drive.words[0] == 0x0400
    bus.global_control(dp.CLEAR_DATA, group=0x01)
    assert bus.slave.drive.words[0] == 0


def test_the_watchdog_returns_a_silent_masters_slave_to_wait_prm(bus: Line) -> None:
    bus.parameterise(PPO3, status=dp.STATUS_LOCK | dp.STATUS_WATCHDOG)  # 10 ms × 1 × 1
    bus.exchange(ppo3(0x0400))
    bus.line.advance(0.005)
    assert bus.slave.station.state is StationState.DATA_EXCHANGE
    bus.line.advance(0.02)
    assert bus.slave.station.state is StationState.WAIT_PRM
    assert bus.diag().status_2 & dp.DIAG_PRM_REQUEST


def test_unlock_releases_the_slave(bus: Line) -> None:
    bus.parameterise()
    bus.srd(dp.SetPrm(dp.STATUS_UNLOCK, 1, 1, 0, 0x00C7, 0).encode(), dp.SET_PRM_SAP)
    diag = bus.diag(OTHER_MASTER)
    assert diag.master_address == dp.NO_MASTER and not diag.status_1 & dp.DIAG_MASTER_LOCK
