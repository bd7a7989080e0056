"""The quick test's moves and homing of a TTA-PRO through PZD (docs/profibus.md §12), over the unchanged REST
routes, judged on the simulated slave: an absolute and a held relative move (CW12 / CW13 toggled, the target in
PZD5-6, the speed in PNU 760) end when ZSW10 says the position is reached, at the target; homing by a PNU 766
configuration (CW11 rising) ends when ZSW11 says home found, the counter set to the homing offset; a held move
whose keepalives stop is quick-stopped. Through the project's own DP master (the held motions: see
``test_api_profibus_motion.own_master_only``)."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager

import pytest
from tests.support.jobs_api import armed, holding
from tests.support.profibus_line import tool_on_line, ttapro_line
from tests.support.waits import eventually

from servostudio.sim.drive.statemachine import State
from servostudio.sim.profibus.faults import FOLLOWING_ERROR

SWITCH_POSITIVE = 0x10  # PNU 766: search the home switch, positive direction
MARKER_RESET = 0xA0  # PNU 766: search the marker pulse, positive, set the counter to PNU 768
HERE_RESET = 0x80  # PNU 766: home on the current position, counter set to PNU 768
NODE = "/api/buses/pb/nodes/5"
MOTION = f"{NODE}/motion"


@pytest.fixture(scope="module")
def line():
    with ttapro_line(5) as line:
        yield line


@pytest.fixture(scope="module")
def client(tmp_path_factory, line):
    with tool_on_line(tmp_path_factory.mktemp("api-profibus-moves"), line) as test_client:
        yield test_client


@pytest.fixture(autouse=True)
def stopped(client):
    yield
    client.post(f"{MOTION}/stop")
    client.put(f"{NODE}/state", json={"target": "switch-on-disabled"})


def counter(line) -> int:
    """The simulated drive's position counter (PNU 774's value)."""
    with line.line.lock:
        drive = line.slaves[5].drive
        return drive.units.position(drive.axis.position)


def finished(client, timeout: float = 3.0) -> dict:
    eventually(lambda: client.get(MOTION).json()["state"] != "running", timeout=timeout)
    return client.get(MOTION).json()


def test_an_absolute_move_ends_at_its_target_when_the_drive_reports_it_reached(client, line):
    target = counter(line) + 2048  # half a revolution (PNU 870: 4096 per revolution)
    with armed(client, NODE, "motion") as (_, header):
        body = {"distance": target, "absolute": True, "velocity": 120}
        started = client.post(f"{MOTION}/move", json=body, headers=header)
        assert started.status_code == 200, started.text
        ended = finished(client)
        assert ended["state"] == "done", ended["reason"]
        assert ended["statusword"] & 0x0400  # ZSW10 position reached
        assert abs(counter(line) - target) <= 5
        assert int(client.get(f"{NODE}/objects/profile_velocity").json()["raw"]) == 120  # PNU 760, rpm
        assert int(client.get(f"{NODE}/objects/target_position").json()["raw"]) == target  # PNU 767 from PZD5-6
        with line.line.lock:
            assert line.slaves[5].drive.device.state is State.OPERATION_ENABLED  # a move leaves the axis enabled


def test_a_held_relative_move_goes_its_distance_backwards(client, line):
    before = counter(line)
    with armed(client, NODE, "motion") as (socket, header), holding(socket, "pb", 5):
        started = client.post(f"{MOTION}/move", json={"distance": -1024, "hold": True}, headers=header)
        assert started.status_code == 200, started.text
        ended = finished(client)
    assert ended["state"] == "done", ended["reason"]
    assert abs(counter(line) - (before - 1024)) <= 5


def test_a_held_move_whose_keepalives_stop_is_quick_stopped(client, line):
    with armed(client, NODE, "motion") as (socket, header):
        with holding(socket, "pb", 5):
            body = {"distance": 4000, "hold": True, "velocity": 30}  # 2 s at 30 rpm: still running when released
            assert client.post(f"{MOTION}/move", json=body, headers=header).status_code == 200
        ended = finished(client, timeout=1.0)
        assert ended["state"] == "stopped" and "no keepalive" in ended["reason"]
        assert client.get(f"{NODE}/state").json()["state"] in {"SWITCH ON DISABLED", "QUICK STOP ACTIVE"}


@pytest.mark.parametrize("configuration", [HERE_RESET, MARKER_RESET])
def test_homing_sets_the_counter_to_the_homing_offset_when_the_drive_reports_home_found(client, line, configuration):
    assert client.put(f"{NODE}/objects/home_offset", json={"value": 1000}).status_code == 200  # PNU 768
    with armed(client, NODE, "motion") as (_, header):
        body = {"method": configuration, "velocity": 120}
        started = client.post(f"{MOTION}/home", json=body, headers=header)
        assert started.status_code == 200, started.text
        ended = finished(client, timeout=4.0)
        assert ended["state"] == "done", ended["reason"]
        assert ended["statusword"] & 0x0800  # ZSW11 home found
        assert int(client.get(f"{NODE}/objects/homing_configuration").json()["raw"]) == configuration
        if configuration == HERE_RESET:
            assert abs(counter(line) - 1000) <= 2
        else:  # stopped past the marker pulse, where the counter read 1000
            assert 1000 < counter(line) < 1000 + 4096


def test_the_homing_methods_of_a_ttapro_are_its_homing_configurations(client):
    methods = {entry["method"]: entry["description"] for entry in client.get("/api/homing-methods/ttapro").json()}
    assert "home switch then marker pulse, negative direction" in methods[0x38 | 0x80]
    refused = client.post(f"{MOTION}/home", json={"method": 0x08})  # a direction with nothing to search
    assert refused.status_code in (409, 422)


def test_state_changes_on_the_line_are_drive_state_events_and_the_state_has_no_nmt_fields(client, line):
    state = client.get(f"{NODE}/state").json()  # the station is in data exchange from here on
    assert state == {"node": 5, "state": "SWITCH ON DISABLED", "statusword": state["statusword"]}  # no NMT
    with client.websocket_connect("/api/ws/events?types=drive_state") as events:
        events.receive_json()  # the socket's hello
        with line.line.lock:  # changed on the drive itself: no request of the tool reads the status word
            line.slaves[5].drive.faults.raise_fault(FOLLOWING_ERROR)
        event = events.receive_json()
        assert (event["type"], event["bus"], event["node"], event["state"]) == ("drive_state", "pb", 5, "FAULT")
        assert event["statusword"] & 0x0008
        assert client.post(f"{NODE}/faults/reset").status_code == 200
        assert events.receive_json()["state"] == "SWITCH ON DISABLED"


@contextmanager
def no_home_switch_between_close_limits(line) -> Iterator[None]:
    """The simulated machine with its limit switches half a turn either side of the axis and no home switch (what
    the plant has is swapped while the line is locked, and put back)."""
    with line.line.lock:
        physics = line.slaves[5].drive.axis.physics
        plant, turns = physics.plant, physics.load_turns
        physics.plant = dataclasses.replace(
            plant, home_switch=None, negative_limit_switch=turns - 0.5, positive_limit_switch=turns + 0.5
        )
    try:
        yield
    finally:
        with line.line.lock:
            physics.plant = plant


def test_a_homing_the_drive_fails_ends_failed_with_the_drives_fault_in_the_manuals_words(client, line):
    with no_home_switch_between_close_limits(line), armed(client, NODE, "motion") as (_, header):
        body = {"method": SWITCH_POSITIVE, "velocity": 120}  # 2 turns/s: the second limit switch after ≈ 0.8 s
        started = client.post(f"{MOTION}/home", json=body, headers=header)
        assert started.status_code == 200, started.text
        ended = finished(client, timeout=4.0)
    assert ended["state"] == "failed", ended
    assert ended["reason"] == "the drive faulted: HOME: homing procedure timeout error"  # PNU 773 bit 16
    assert client.get(f"{NODE}/state").json()["state"] == "FAULT"
    assert client.post(f"{NODE}/faults/reset").status_code == 200
