"""The I/O service against the embedded simulated drives (docs/io.md): each device's configuration read through its
profile, a limit switch's function and polarity written through the motion guard and the drive reacting to it, a
change checked whole (nothing written on any problem), and the fail-safe check."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from tests.support.embedded_sim import open_sim
from tests.support.motion import controlling

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import set_state
from servostudio.errors import InvalidInput, RefusedForSafety
from servostudio.services import io
from servostudio.services.bus import BusConnection, ConnectionManager

REV = 4096  # user units per revolution (0x6093 at its default on the XtrapulsPac; increments on the CD1-k)
SPEC = "sim:1:xtrapulspac,2:cd1k,3:encotrive"
LS_PLUS = "INPUT0 / LS+"


@pytest.fixture(scope="module")
def manager() -> Iterator[ConnectionManager]:
    manager = ConnectionManager()
    open_sim(manager, SPEC)
    yield manager
    manager.close_all()


@pytest.fixture(scope="module")
def connection(manager: ConnectionManager) -> BusConnection:
    return manager.list()[0]


def wait_for(condition, what: str, seconds: float = 3.0) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < deadline, what
        time.sleep(0.01)


def limits(drive: Drive) -> tuple[bool, bool]:
    state = io.state(drive)
    return bool(state["negative_limit"]), bool(state["positive_limit"])


def travel(manager: ConnectionManager, connection: BusConnection, drive: Drive, speed: int) -> float:
    """Turns the axis makes in 0.3 s of profile velocity at ``speed`` (user units / s), as its armed controller."""
    with controlling(manager, connection.id, drive.node):
        drive.write("modes_of_operation", 3)
        drive.write("target_velocity", 0)
        set_state(drive, State.OPERATION_ENABLED)
        before = int(drive.read("position_actual").raw)
        drive.write("target_velocity", speed)
        time.sleep(0.3)
        after = int(drive.read("position_actual").raw)
        drive.write("target_velocity", 0)
        set_state(drive, State.SWITCH_ON_DISABLED)
    return (after - before) / REV


def test_each_device_reads_its_own_io(connection):
    xtrapulspac, cd1k, encotrive = (io.read(connection.drive(node), simulated=True) for node in (1, 2, 3))
    assert xtrapulspac["routing"] == "pointer" and [row["name"] for row in xtrapulspac["inputs"]][:2] == ["IN1", "IN2"]
    assert len(xtrapulspac["inputs"]) == 10 and xtrapulspac["inputs"][5]["physical"] is False
    assert {group["key"] for group in xtrapulspac["groups"]} >= {"analog_input_1", "encoder_emulation", "extension"}
    assert cd1k["routing"] == "dedicated" and cd1k["inputs"][0]["allowed"] == ["general", "positive_limit"]
    assert all(row["inverted"] is None for row in cd1k["inputs"])  # the CD1-k has no input polarity
    assert encotrive["routing"] == "fixed" and encotrive["inputs"] == [] and encotrive["simulated"] is None
    assert xtrapulspac["simulated"]["names"] == ["IN1", "IN2", "IN3", "IN4", "IN5"]


def test_xtrapulspac_inverted_limit_input_stops_positive_motion_until_24v(manager, connection):
    drive = connection.drive(1)
    io.set_sim_inputs(drive, 0, simulated=True)
    result = io.apply(drive, io.IoChange(inputs=[io.InputChange("IN3", "positive_limit", inverted=True)]))
    assert result["written"] == ["0x3051,0", "0x3050,3"]  # the polarity before the function
    assert int(drive.read("input_3_destination").raw) == 0x60FD0001
    wait_for(lambda: limits(drive) == (False, True), "no 24 V on an inverted limit input: the limit is active")
    assert abs(travel(manager, connection, drive, 2 * REV)) < 0.02
    assert travel(manager, connection, drive, -2 * REV) < -0.2
    io.set_sim_inputs(drive, 0b100, simulated=True)  # 24 V on IN3: a closed (normally closed) switch
    wait_for(lambda: limits(drive) == (False, False), "24 V releases the limit")
    assert travel(manager, connection, drive, 2 * REV) > 0.2
    io.apply(drive, io.IoChange(inputs=[io.InputChange("IN3", "none", inverted=False)]))


def test_a_normal_polarity_limit_switch_is_unsafe_and_says_why(connection):
    drive = connection.drive(1)
    io.apply(drive, io.IoChange(inputs=[io.InputChange("IN2", "negative_limit", inverted=False)]))
    try:
        findings = io.read(drive)["findings"]
        unsafe = [row for row in findings if row["severity"] == "unsafe"]
        assert [row["subject"] for row in unsafe] == ["IN2"]
        assert "broken wire" in unsafe[0]["text"] and "invert IN2" in unsafe[0]["text"]
        assert any(row["subject"] == "positive_limit" for row in findings)  # no positive limit switch at all
    finally:
        io.apply(drive, io.IoChange(inputs=[io.InputChange("IN2", "none")]))


def test_a_change_with_one_problem_writes_nothing(connection):
    drive = connection.drive(1)
    before = int(drive.read("input_4_destination").raw), int(drive.read("input_polarity").raw)
    change = io.IoChange(
        inputs=[io.InputChange("IN4", "home", inverted=True), io.InputChange("IN5", "home")],
        settings={"analog_input_1_filter": 3},
    )
    with pytest.raises(io.IoChangeRefused) as refused:
        io.apply(drive, change)
    assert "IN4 and IN5 would both be 'home'" in str(refused.value) and "outside 5..20000" in str(refused.value)
    assert (int(drive.read("input_4_destination").raw), int(drive.read("input_polarity").raw)) == before


def test_settings_are_range_checked_and_pointers_must_name_an_object(connection):
    drive = connection.drive(1)
    with pytest.raises(io.IoChangeRefused, match="points to no object"):
        io.apply(drive, io.IoChange(settings={"analog_output_source": 0x7ABC0100}))
    result = io.apply(drive, io.IoChange(settings={"analog_input_1_offset": 12, "analog_output_source": "0x30F80200"}))
    settings = {row["key"]: row["value"] for group in result["groups"] for row in group["settings"]}
    assert settings["analog_input_1_offset"] == 12 and settings["analog_output_source"] == 0x30F80200
    io.apply(drive, io.IoChange(settings={"analog_input_1_offset": 0, "analog_output_source": 0x30F80100}))


def test_the_guard_refuses_input_functions_of_an_axis_another_client_holds(manager, connection):
    drive = connection.drive(1)
    with controlling(manager, connection.id, drive.node, user="other"):
        drive.write("modes_of_operation", 3)
        drive.write("target_velocity", 0)
        set_state(drive, State.OPERATION_ENABLED)
    try:
        with pytest.raises(RefusedForSafety):
            io.apply(drive, io.IoChange(inputs=[io.InputChange("IN1", "enable")]))
        assert int(drive.read("input_1_destination").raw) == 0
    finally:
        with controlling(manager, connection.id, drive.node):
            set_state(drive, State.SWITCH_ON_DISABLED)


def test_cd1k_limit_switch_input_acts_only_while_dedicated(manager, connection):
    drive = connection.drive(2)
    io.set_sim_inputs(drive, 0b1, simulated=True)  # LS+ active
    try:
        wait_for(lambda: limits(drive) == (False, True), "a dedicated LS+ input gives the positive limit")
        assert abs(travel(manager, connection, drive, 2 * REV)) < 0.02
        result = io.apply(drive, io.IoChange(inputs=[io.InputChange(LS_PLUS, "general")]))
        assert result["written"] == ["0x30FD,0"] and int(drive.read("input_mask").raw) == 0x3E
        assert [row["severity"] for row in result["findings"] if row["subject"] == LS_PLUS] == ["unsafe"]
        wait_for(lambda: limits(drive) == (False, False), "a freed LS+ is a general input")
        assert result["inputs"][0]["active"] is True  # still seen in 0x60FD bit 16
        assert travel(manager, connection, drive, 2 * REV) > 0.2
        with pytest.raises(io.IoChangeRefused, match="has no polarity"):
            io.apply(drive, io.IoChange(inputs=[io.InputChange(LS_PLUS, inverted=True)]))
    finally:
        io.apply(drive, io.IoChange(inputs=[io.InputChange(LS_PLUS, "positive_limit")]))
        io.set_sim_inputs(drive, 0, simulated=True)


def test_encotrive_has_nothing_to_configure_and_no_test_bench(connection):
    drive = connection.drive(3)
    with pytest.raises(io.IoChangeRefused, match="no input 'IN1'"):
        io.apply(drive, io.IoChange(inputs=[io.InputChange("IN1", "positive_limit")]))
    with pytest.raises(io.NotSimulated):
        io.set_sim_inputs(drive, 1, simulated=True)
    with pytest.raises(io.NotSimulated):
        io.set_sim_inputs(connection.drive(1), 1, simulated=False)
    with pytest.raises(InvalidInput, match="5 bits"):
        io.set_sim_inputs(connection.drive(1), 0b100000, simulated=True)
