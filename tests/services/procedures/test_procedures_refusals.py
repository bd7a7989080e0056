"""The manual's reasons a procedure cannot run, each made true on the simulated drive (a limit switch the axis stands
on, the DC bus switched off, a procedure the drive already runs) and refused by the tool before anything is written;
and a procedure that outlives its timeout, aborted with the drive left disabled and its values as before."""

from __future__ import annotations

from dataclasses import replace

import pytest

from servostudio.drive.cia402 import State
from servostudio.drive.control import read_state
from servostudio.services.procedures import PreconditionsUnmet, ProcedureTimeout, service

APHA = int.from_bytes(b"apha", "little")
COMMUTATION = ("0x3410,1", "0x3410,2", "0x3410,3")


def test_a_limit_switch_the_axis_stands_on_refuses_the_phasing(bench_factory):
    bench = bench_factory(seed=7)
    with bench.network.lock:
        behaviour = bench.network.node(1).behaviour
        here = behaviour.physics.load_turns  # type: ignore[attr-defined]
        behaviour.plant = replace(behaviour.plant, negative_limit_switch=here + 0.5)  # type: ignore[attr-defined]
        behaviour.physics.plant = behaviour.plant  # type: ignore[attr-defined]
    with pytest.raises(PreconditionsUnmet, match="the negative limit switch is active") as refused:
        bench.run("auto_phasing")
    assert "nothing was written" in str(refused.value)
    assert bench.machine().read("0x3413").raw == 0  # never started


def test_no_dc_bus_refuses_the_phasing(bench_factory):
    bench = bench_factory(seed=7)
    with bench.network.lock:
        physics = bench.network.node(1).behaviour.physics  # type: ignore[attr-defined]
        physics.mains_on, physics.dc_bus = False, 0.0  # the power supply switched off, the capacitor empty
    with pytest.raises(PreconditionsUnmet, match=r"the DC bus is at 0 V .*switch the power supply on"):
        bench.run("auto_phasing")
    assert bench.machine().read("0x3413").raw == 0


def test_a_procedure_the_drive_already_runs_refuses_a_second(bench_factory):
    bench = bench_factory(speed=1.0)  # a commissioned drive: its auto-phasing runs for seconds
    machine = bench.machine()
    machine.write("0x3413", APHA)  # started by someone else (another tool, the drive's own terminal)
    try:
        with pytest.raises(PreconditionsUnmet, match=r"a procedure .* is running"):
            bench.run("current_loop")
        assert machine.read("0x3411").raw == 0  # 'calc' never started
    finally:
        machine.write("0x3413", 0)


def test_a_procedure_past_its_timeout_is_aborted_and_leaves_the_drive_as_before(bench_factory, monkeypatch):
    bench = bench_factory(speed=1.0)  # a commissioned drive in real time: auto-phasing runs for seconds
    before = {key: bench.machine().read(key).raw for key in COMMUTATION}
    described = service.description_of

    def short(drive, name):
        return replace(described(drive, name), timeout_s=0.5)

    monkeypatch.setattr(service, "description_of", short)
    with pytest.raises(ProcedureTimeout, match=r"still running after 0\.5 s: aborted"):
        bench.run("auto_phasing")
    machine = bench.machine()
    assert machine.read("0x3413").raw == 3  # aborted (0 written to the trigger)
    assert read_state(machine)[0] is not State.OPERATION_ENABLED
    assert {key: machine.read(key).raw for key in COMMUTATION} == before
