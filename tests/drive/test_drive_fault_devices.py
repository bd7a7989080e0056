"""Faults of every supported drive, decoded from its own objects with its manual's texts: the CD1-k's 0x3020 word
(one coded power fault in bits 16-18) and 0x3021 warnings, the encoTRive's CiA codes, and the cause behind a failed
procedure that the tool can see; an encoTRive axis that could not move is not enabled."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator

import pytest
from tests.support.motion import controlling

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import fault_report, reset_faults, set_state
from servostudio.drive.faults import FaultInfo
from servostudio.drive.monitor import decode_emergency
from servostudio.drive.prerequisites import MoveBlocked, move_blockers
from servostudio.drive.profiles import profile_for
from servostudio.services.bus import BusConnection, ConnectionManager
from servostudio.services.scan import scan
from servostudio.sim.drive import errors

CD1K, ENCOTRIVE, XTRAPULSPAC = 1, 2, 3


@pytest.fixture(scope="module")
def manager() -> Iterator[ConnectionManager]:
    manager = ConnectionManager()
    yield manager
    manager.close_all()


@pytest.fixture(scope="module")
def bus(manager: ConnectionManager) -> BusConnection:
    connection = manager.open(f"sim:{CD1K}:cd1k,{ENCOTRIVE}:encotrive,{XTRAPULSPAC}:xtrapulspac", wait=5.0)
    assert connection.link.wait_connected(5.0)
    connection.engine.timeout = 1.0
    assert {info.node: info.device for info in scan(connection)} == {
        CD1K: "cd1k",
        ENCOTRIVE: "encotrive",
        XTRAPULSPAC: "xtrapulspac",
    }
    return connection


def in_sim(bus: BusConnection, node: int, action: Callable) -> None:
    """Run ``action(behaviour)`` inside the simulated drive (fault injection), then let a few periods pass."""
    behaviour = bus.simulation.node(node).behaviour
    bus.simulation.post(lambda: action(behaviour))
    time.sleep(0.1)


def wait_for(condition: Callable[[], bool], seconds: float = 3.0) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < deadline, "condition not met in time"
        time.sleep(0.02)


def names(faults: list[FaultInfo]) -> list[str]:
    return [fault.name for fault in faults]


def test_cd1k_faults_come_from_its_error_word_without_0x603f(bus: BusConnection) -> None:
    drive = bus.drive(CD1K)
    in_sim(bus, CD1K, lambda drive: drive.raise_error(errors.POSITION_FOLLOWING))
    try:
        report = fault_report(drive)
        assert report.state == "FAULT" and report.error_code == 0
        assert [(fault.code, fault.name) for fault in report.faults] == [(4, "Following error")]
        assert "6065h" in report.faults[0].remedy
        assert report.as_dict()["faults"][0]["remedy"]
    finally:
        reset_faults(drive)
    assert fault_report(drive).faults == []


def test_cd1k_power_fault_is_one_coded_fault_with_the_manuals_remedy(bus: BusConnection) -> None:
    drive = bus.drive(CD1K)
    in_sim(bus, CD1K, lambda drive: drive.raise_error(errors.MOTOR_BRAKE))
    try:
        report = fault_report(drive)
        assert names(report.faults) == ["Power fault: motor brake"]
        assert "60FEh/2 bit 0" in report.faults[0].remedy
    finally:
        reset_faults(drive)


def test_cd1k_emcy_decodes_the_coded_power_fault() -> None:
    word = 0b011 << 16 | 1 << 15  # 24 V error and overcurrent
    frame = bytes([0x00, 0x23, 0x01]) + word.to_bytes(4, "little") + b"\0"
    emergency = decode_emergency(4, frame, profile_for("cd1k"))
    assert names(list(emergency.faults)) == ["Overcurrent", "Power fault: 24 V error"]


def test_cd1k_warnings_come_from_0x3021(bus: BusConnection) -> None:
    profile = profile_for("cd1k")
    assert profile.warning_word == "warning_word" and profile.address("warning_word") == (0x3021, 0)
    assert names(fault_report(bus.drive(CD1K)).warnings) == []
    assert profile.warnings[11].name == "Limit switch +"  # bit 10


def test_encotrive_continuous_overcurrent_is_listed_with_its_manuals_texts(bus: BusConnection) -> None:
    drive = bus.drive(ENCOTRIVE)
    in_sim(bus, ENCOTRIVE, lambda drive: drive.raise_error(errors.OVERCURRENT))
    try:
        report = fault_report(drive)
        assert report.state == "FAULT" and report.error_code == 0x2310
        assert [(fault.cia402_code, fault.name) for fault in report.faults] == [(0x2310, "Continuous over current")]
        assert "control word bit 7" in report.faults[0].remedy and "1003h" in report.faults[0].remedy
    finally:
        reset_faults(drive)
    assert fault_report(drive).faults == []


def test_encotrive_emcy_without_a_manual_text_is_decoded_by_its_cia_name() -> None:
    emergency = decode_emergency(2, bytes([0x10, 0x23, 0x02, 0, 0, 0, 0, 0]), profile_for("encotrive"))
    assert names(list(emergency.faults)) == ["Continuous over current"]
    assert names(list(decode_emergency(2, bytes([0x11, 0x86, 0x20]), profile_for("encotrive")).faults)) == [
        "Following error"
    ]


def test_a_failed_auto_tuning_names_the_torque_constant_it_needed(bus: BusConnection) -> None:
    drive = bus.drive(XTRAPULSPAC)
    constant = drive.read("motor_torque_constant").raw
    drive.write("motor_torque_constant", 0)
    try:
        in_sim(bus, XTRAPULSPAC, lambda drive: drive.procedures.start("atun"))
        wait_for(lambda: fault_report(drive).faults != [])
        report = fault_report(drive)
        assert [fault.code for fault in report.faults] == [64]
        assert [(cause.label, cause.problem, cause.needed_by) for cause in report.causes] == [
            ("0x6410,11 Motor data.Torque constant", "is 0", "auto-tuning")
        ]
        assert report.as_dict()["causes"][0]["object"].startswith("0x6410,11")
    finally:
        drive.write("motor_torque_constant", constant)
        reset_faults(drive)
    assert fault_report(drive).causes == []


def _set(drive: Drive, values: dict[str, int]) -> dict[str, int]:
    before = {name: int(drive.read(name).raw) for name in values}
    for name, value in values.items():
        drive.write(name, value)
    return before


def test_encotrive_starts_with_the_manuals_ramps_and_limits(bus: BusConnection) -> None:
    drive = bus.drive(ENCOTRIVE)
    values = {name: drive.read(name).raw for name in drive.profile.mode_limits[3]}
    assert all(values.values()), values
    assert (values["max_deceleration"], drive.read("profile_velocity").raw) == (15000, 4400)
    assert move_blockers(drive, 3) == []


def test_enabling_an_encotrive_that_cannot_move_names_the_limit(manager: ConnectionManager, bus: BusConnection) -> None:
    drive = bus.drive(ENCOTRIVE)
    before = _set(drive, {"max_acceleration": 0})
    try:
        assert [cause.label for cause in move_blockers(drive, 3)] == ["0x60C5,0 Max acceleration"]
        with controlling(manager, bus.id, ENCOTRIVE):
            drive.write("modes_of_operation", 3)  # speed ramp (profile velocity)
            with pytest.raises(MoveBlocked, match=r"node 2: the axis could not move .*0x60C5,0 Max acceleration is 0"):
                set_state(drive, State.OPERATION_ENABLED)
        assert fault_report(drive).state == "SWITCH ON DISABLED"  # nothing was written
    finally:
        _set(drive, before)
