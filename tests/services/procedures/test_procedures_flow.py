"""The procedure flow against simulated drives: refusals before anything is written, abort, failure with the drive's
fault and the cause, the motion guard, the CD1-k through its own profile."""

from __future__ import annotations

import threading
from dataclasses import replace

import pytest

from servostudio.drive.cia402 import State
from servostudio.drive.control import read_state
from servostudio.services.audit import Actor, acting_as
from servostudio.services.cancel import Cancellation
from servostudio.services.motion import NoLiveClient
from servostudio.services.procedures import (
    BadOptions,
    PreconditionsUnmet,
    ProcedureFailed,
    ProcedureRequest,
    UnknownProcedure,
    describe,
)

APHA = int.from_bytes(b"apha", "little")


def test_the_list_reads_every_precondition_from_the_drive(bench_factory):
    bench = bench_factory(seed=7)
    listed = {item["name"]: item for item in describe(bench.drive())}
    assert list(listed) == ["auto_phasing", "motor_phasing", "current_loop", "current_limits", "auto_tuning"]
    tuning = listed["auto_tuning"]
    assert tuning["moves"] and tuning["status"] == "never" and not tuning["ready"]
    unmet = {item["name"]: item["reason"] for item in tuning["preconditions"] if not item["ok"]}
    assert "Torque constant" in unmet["value:motor_torque_constant"]  # an uncommissioned drive: motor data is 0
    assert "brake" in unmet["brake_released"]


def test_an_unmet_precondition_is_refused_with_its_reason_before_anything_is_written(bench_factory):
    bench = bench_factory(seed=7)
    before = bench.machine().read("0x3425,1").raw
    with pytest.raises(PreconditionsUnmet, match="Torque constant is 0") as refused:
        bench.run("auto_tuning", ProcedureRequest({"bandwidth": 100}))
    assert "nothing was written" in str(refused.value)
    assert bench.machine().read("0x3425,1").raw == before  # the bandwidth option was not written
    assert bench.machine().read("0x3426").raw == 0  # never executed


def test_bad_options_and_unknown_procedures_are_refused(bench_factory):
    bench = bench_factory()
    with pytest.raises(BadOptions, match="bandwidth '60' is not one of 50, 75, 100"):
        bench.run("auto_tuning", ProcedureRequest({"bandwidth": 60}))
    with pytest.raises(BadOptions, match="unknown option colour"):
        bench.run("current_loop", ProcedureRequest({"colour": "red"}))
    with pytest.raises(UnknownProcedure, match="no procedure 'sseq'"):
        bench.run("sseq")


def test_a_moving_procedure_needs_the_armed_controller(bench_factory):
    bench = bench_factory()
    stranger = Actor("someone", "administrator", None)
    with pytest.raises(NoLiveClient):
        bench.run("auto_phasing", actor=stranger)
    assert bench.machine().read("0x3413").raw == 0


def test_abort_leaves_the_drive_disabled_and_the_values_as_before(bench_factory):
    bench = bench_factory(speed=1.0)  # real time: the abort arrives while it runs
    before = {key: bench.machine().read(key).raw for key in ("0x3410,1", "0x3410,2", "0x3410,3")}
    cancellation = Cancellation()
    events: list = []
    started = threading.Event()

    def phase() -> None:
        events.append(("result", bench.run("auto_phasing", cancellation=cancellation, events=_noting(started))))

    runner = threading.Thread(target=phase)
    runner.start()
    assert started.wait(10.0)
    cancellation.cancel()
    runner.join(20.0)
    result = events[-1][1]
    assert result["status"] == "aborted"
    assert bench.machine().read("0x3413").raw == 3  # aborted
    assert read_state(bench.machine())[0] is not State.OPERATION_ENABLED
    assert {key: bench.machine().read(key).raw for key in before} == before


def _noting(started: threading.Event) -> list:
    class Seen(list):
        def append(self, event):
            if event.get("phase") == "running":
                started.set()
            super().append(event)

    return Seen()


def test_a_failed_procedure_names_the_drive_fault_and_the_cause(bench_factory):
    bench = bench_factory()
    network = bench.network
    with network.lock:
        behaviour = network.node(1).behaviour
        behaviour.plant = replace(behaviour.plant, has_brake=True, brake_torque=50.0)  # type: ignore[attr-defined]
        behaviour.physics.plant = behaviour.plant  # type: ignore[attr-defined]
    with pytest.raises(ProcedureFailed, match="Procedure error") as failed:
        bench.run("auto_phasing")
    assert "likely cause" in str(failed.value)


def test_the_cd1k_runs_its_own_auto_phasing(bench_factory):
    bench = bench_factory(nodes="1:cd1k")
    with acting_as(bench.controller()):
        listed = {item["name"] for item in describe(bench.drive())}
    assert listed == {"auto_phasing", "motor_phasing", "auto_tuning"}
    bench.machine().write("0x6510,5", 0x3FFF)  # max current: 100 % of the rating (0x3FFF)
    bench.machine().write("0x6510,6", 0x1FFF)  # rated current: 50 %
    result = bench.run("auto_phasing")
    plant = bench.plant()
    assert result["status"] == "done"
    assert result["pole_pairs"] == plant.pole_pairs
    assert bench.machine().read("0x3410").raw == 5  # the CD1-k's own trigger


def test_the_cd1k_runs_its_own_motor_phasing(bench_factory):
    """The offset entered 40° electrical off (the pole pairs and phase order right): the CD1-k's 'mcal' finds it
    again, through the CD1-k profile's objects (commutation in 0x6410,2..4, trigger 0x3414)."""
    bench = bench_factory(nodes="1:cd1k")
    plant = bench.plant()
    machine = bench.machine()
    for key, value in (("0x6510,5", 0x3FFF), ("0x6510,6", 0x1FFF), ("0x6410,2", plant.pole_pairs)):
        machine.write(key, value)
    machine.write("0x6410,4", (plant.sensor_offset + 65536 * 40 // 360) % 65536)
    result = bench.run("motor_phasing")
    assert result["status"] == "done" and machine.read("0x3414").raw == 5
    error = (int(result["sensor_offset"]) - plant.sensor_offset) % 65536
    assert min(error, 65536 - error) <= 65536 * 2 / 360
    assert result["before"]["sensor_offset"] == (plant.sensor_offset + 65536 * 40 // 360) % 65536


def test_the_cd1k_plant_is_reported_per_ampere_never_as_physical_units_it_cannot_know(bench_factory):
    """The CD1-k has no torque-constant object: its drive identifies J/Kt, B/Kt, …; the tool must not label those
    kg·m² and N·m·s/rad."""
    bench = bench_factory(nodes="1:cd1k")
    for key, value in (("0x6510,5", 0x3FFF), ("0x6510,6", 0x1FFF), ("0x60FE,2", 1), ("0x60FE,1", 0)):
        bench.machine().write(key, value)  # drive currents (% of the rating) and the brake released by hand
    result = bench.run("auto_tuning", ProcedureRequest({"bandwidth": 75}))
    plant = bench.plant()
    identified = result["identified"]
    assert identified["inertia_kgm2"] is None and identified["inertia_ratio"] is None
    per_ampere = identified["per_ampere"]
    assert per_ampere["inertia_as2_per_rad"] == pytest.approx(plant.total_inertia / plant.torque_constant, rel=0.10)
    assert per_ampere["viscous_friction_as_per_rad"] == pytest.approx(
        plant.viscous_friction / plant.torque_constant, rel=0.25
    )
