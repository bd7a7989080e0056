"""The speed-loop model against simulated drives: physical values as the simulated loop uses them (its own
conversion of the raw objects, `sim.drive.behaviour`), writes through the server's gate, refusals before the bus."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import pytest
from tests.support.procedure_bench import open_bench

from servostudio.drive.access import Drive
from servostudio.errors import InvalidInput
from servostudio.services.bus import BusConnection
from servostudio.services.frequency.speed_loop import (
    BadSpeedLoop,
    NoSpeedLoop,
    raw_writes,
    read_speed_loop,
    write_speed_loop,
)
from servostudio.sim.network import SimulatedNetwork


@pytest.fixture
def bus() -> Iterator[tuple[BusConnection, SimulatedNetwork]]:
    bench = open_bench("1:xtrapulspac,2:cd1k,3:encotrive", None, 1.0)
    yield bench.connection, bench.network
    bench.manager.close_all()


def _loops(network: SimulatedNetwork, node: int):
    with network.lock:
        return network.node(node).behaviour.loops  # type: ignore[attr-defined]


def test_read_gives_the_gains_the_simulated_loop_runs_with(bus: tuple[BusConnection, SimulatedNetwork]) -> None:
    connection, network = bus
    loop = read_speed_loop(connection.drive(1))
    truth = _loops(network, 1)
    assert loop["kp_a_per_rad_s"] == pytest.approx(truth.kpv, rel=1e-9) and truth.kpv > 0
    assert loop["ki_a_per_rad"] == pytest.approx(truth.kiv, rel=1e-9) and truth.kiv > 0
    assert loop["control_period_s"] == 250e-6 and len(loop["current_filters_hz"]) == 3
    assert loop["torque_constant_nm_per_a"] is not None and loop["torque_constant_nm_per_a"] > 0
    assert {"kp_a_per_rad_s", "ki_a_per_rad", "current_filter_1_hz", "speed_filter_s"} <= set(loop["writable"])


def test_write_sets_the_physical_gains_and_keeps_the_others(bus: tuple[BusConnection, SimulatedNetwork]) -> None:
    connection, network = bus
    drive = connection.drive(1)
    before = read_speed_loop(drive)
    kb_before = _loops(network, 1).kbv
    kp = before["kp_a_per_rad_s"] * 1.7
    result = write_speed_loop(drive, {"kp_a_per_rad_s": kp, "current_filter_1_hz": 400, "speed_filter_s": 1e-3})
    truth = _loops(network, 1)
    assert truth.kpv == pytest.approx(kp, rel=1e-3)
    assert truth.kiv == pytest.approx(before["ki_a_per_rad"], rel=1e-3) and truth.kbv == pytest.approx(kb_before)
    assert result["after"]["current_filters_hz"][0] == 400.0 and result["after"]["speed_filter_s"] == 1e-3
    assert result["before"]["kp_a_per_rad_s"] == before["kp_a_per_rad_s"]


def test_a_gain_beyond_the_multiplier_rescales_every_scaled_gain(
    bus: tuple[BusConnection, SimulatedNetwork],
) -> None:
    connection, network = bus
    drive = connection.drive(1)
    before = read_speed_loop(drive)
    truth = _loops(network, 1)
    ki_before, ka_before = truth.kiv, truth.kav
    kp = 65535 * 1e-4 * before["gain_multiplier"] * 3  # three times what the present multiplier can hold
    after = write_speed_loop(drive, {"kp_a_per_rad_s": kp})["after"]
    truth = _loops(network, 1)
    assert after["gain_multiplier"] == 4 * before["gain_multiplier"]
    assert truth.kpv == pytest.approx(kp, rel=1e-3)
    assert truth.kiv == pytest.approx(ki_before, rel=0.01, abs=0.02) and truth.kav == pytest.approx(ka_before, abs=1e-3)


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"kp_a_per_rad_s": 0.5, "kq": 1.0}, "kq not writable"),
        ({"kp_a_per_rad_s": -0.1}, "≥ 0"),
        ({"ki_a_per_rad": float("nan")}, "finite"),
        ({"speed_filter_s": 0.7e-3}, "one of 0.0005, 0.001, 0.002"),
        ({"kp_a_per_rad_s": 1.0, "current_filter_2_hz": 5000}, "1000"),
        ({"kd_a_per_rad_s2": 1.0}, "out of range"),
        ({"ki_a_per_rad": 1.2e308}, "out of range even with the largest multiplier"),  # found by schemathesis
        ({"kd_a_per_rad_s2": 1.7e308}, "out of range"),
    ],
)
def test_bad_values_are_refused_before_anything_is_written(
    bus: tuple[BusConnection, SimulatedNetwork], values: dict[str, float], message: str
) -> None:
    connection, _ = bus
    drive = connection.drive(1)
    before = read_speed_loop(drive)["raw"]
    with pytest.raises(InvalidInput, match=message):  # BadSpeedLoop, or the dictionary's range (DriveAccessError)
        write_speed_loop(drive, values)
    assert read_speed_loop(drive)["raw"] == before


def test_cd1k_has_no_multiplier_filters_or_torque_constant(bus: tuple[BusConnection, SimulatedNetwork]) -> None:
    connection, network = bus
    drive = connection.drive(2)
    loop = read_speed_loop(drive)
    assert loop["kp_a_per_rad_s"] == pytest.approx(_loops(network, 2).kpv)
    assert loop["torque_constant_nm_per_a"] is None and loop["current_filters_hz"] == []
    assert loop["speed_filter_s"] == 0.5e-3 and "speed_filter_s" not in loop["writable"]
    assert raw_writes(drive, {"ki_a_per_rad": 1.5}) == [("ki_speed", 150)]
    with pytest.raises(BadSpeedLoop, match="current_filter_1_hz not writable"):
        raw_writes(drive, {"current_filter_1_hz": 100})


def test_the_encotrive_reads_as_the_gains_it_derives_from_its_inertia_setting(
    bus: tuple[BusConnection, SimulatedNetwork],
) -> None:
    connection, network = bus
    drive: Drive = connection.drive(3)
    loop = read_speed_loop(drive)
    kpv, kiv = _loops(network, 3).kpv, _loops(network, 3).kiv
    assert loop["writable"] == ["inertia_setting_kgm2"] and loop["inertia_setting_kgm2"] > 0
    assert loop["kp_a_per_rad_s"] == pytest.approx(kpv, rel=1e-6) and kpv > 0
    assert loop["ki_a_per_rad"] == pytest.approx(kiv, rel=1e-6)
    with pytest.raises(BadSpeedLoop, match="kp_a_per_rad_s not writable"):
        raw_writes(drive, {"kp_a_per_rad_s": 1.0})
    written = write_speed_loop(drive, {"inertia_setting_kgm2": 2 * loop["inertia_setting_kgm2"]})
    assert written["written"] == [["speed_controller_inertia", 2 * loop["raw"]["speed_controller_inertia"]]]
    assert _loops(network, 3).kpv == pytest.approx(2 * kpv, rel=1e-3)  # the simulated drive follows Θi
    assert written["after"]["kp_a_per_rad_s"] == pytest.approx(2 * loop["kp_a_per_rad_s"], rel=1e-3)


def test_a_drive_without_a_speed_loop_description_says_so(bus: tuple[BusConnection, SimulatedNetwork]) -> None:
    connection, _ = bus
    drive: Drive = connection.drive(3)
    drive.profile = replace(drive.profile, speed_loop=None)  # a generic CiA 402 drive
    with pytest.raises(NoSpeedLoop, match="encotrive has no speed-loop gain objects"):
        read_speed_loop(drive)
    with pytest.raises(NoSpeedLoop):
        raw_writes(drive, {"kp_a_per_rad_s": 1.0})
