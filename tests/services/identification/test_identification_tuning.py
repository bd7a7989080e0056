"""The tuning after a tool-side identification (docs/identification.md § Tuning): gains for a requested bandwidth
through the device profile's gain objects, or on the encoTRive the inertia setting Θi its speed controller is
computed from, verified by a recorded speed step whose bandwidth is measured from the recording (never from the
formula); the encoTRive's tuning is judged by a step of the true plant's shaft with the Θi written."""

from __future__ import annotations

from dataclasses import replace

import pytest
from tests.support.shaft_step import encotrive_bandwidth

from servostudio.services.audit import acting_as
from servostudio.services.cancel import Cancellation
from servostudio.services.frequency.speed_loop import NoSpeedLoop
from servostudio.services.identification import IdentificationRequest, check, identify
from servostudio.services.identification.tuning import BadTuning


def tuned(bench, bandwidth: float) -> dict:
    with acting_as(bench.controller()):
        request = IdentificationRequest({}, bandwidth)
        options = check(bench.manager.motion, bench.axis, request, bench.drive())
        return identify(bench.manager.motion, bench.axis, bench.drive(), options, lambda event: None, Cancellation(),
                        bandwidth)  # fmt: skip


def test_the_tuned_speed_loop_reaches_the_requested_bandwidth(id_bench):
    bench = id_bench("xtrapulspac", 3)
    tuning = tuned(bench, 75.0)["tuning"]
    assert tuning["gains"]["after"]["kp_a_per_rad_s"] != tuning["gains"]["before"]["kp_a_per_rad_s"]
    step = tuning["verification"]["speed_step"]
    assert step["bandwidth_hz"] == pytest.approx(75.0, rel=0.20), step


#: seed 3: rigid, load 3.1 × the rotor; seed 5: the heavy one, rigid, load 3.7 × the rotor (4.7 × in all)
@pytest.mark.parametrize(("seed", "bandwidth"), [(3, 50.0), (5, 75.0)])
def test_the_encotrive_inertia_setting_reaches_the_requested_bandwidth(id_bench, seed, bandwidth):
    bench = id_bench("encotrive", seed)
    plant = bench.plant()
    factory = bench.drive().read("speed_controller_inertia").raw
    assert factory == round(plant.motor_inertia / 1e-7)  # the rotor's own: the factory knows no load
    tuning = tuned(bench, bandwidth)["tuning"]
    written = bench.drive().read("speed_controller_inertia").raw
    assert tuning["gains"]["after"]["inertia_setting_kgm2"] == pytest.approx(written * 1e-7)
    assert tuning["gains"]["before"]["inertia_setting_kgm2"] == pytest.approx(factory * 1e-7)
    # the tool's verification: six speed steps recorded by TPDOs; on the simulator, which has no 0x1006 to lock its
    # cycle to the SYNC, a sample's time is only as good as the host's scheduling (docs/identification.md), so its
    # bandwidth is reported, and the loop is judged on the true plant's shaft with the Θi written (and the factory's)
    step = tuning["verification"]["speed_step"]
    assert len(step["bandwidth_steps_hz"]) == 6 and step["bandwidth_hz"] > 0, step
    assert encotrive_bandwidth(plant, written) == pytest.approx(bandwidth, rel=0.20)
    assert encotrive_bandwidth(plant) < 0.5 * bandwidth


def test_a_drive_without_gain_objects_or_a_bandwidth_out_of_range_is_refused_first(id_bench):
    bench = id_bench("encotrive", 4)
    with pytest.raises(BadTuning, match=r"20\.\.200 Hz"):
        tuned(bench, 500.0)
    drive = bench.drive()
    drive.profile = replace(drive.profile, speed_loop=None)  # a generic CiA 402 drive: no speed loop described
    with acting_as(bench.controller()), pytest.raises(NoSpeedLoop, match="no speed-loop gain objects"):
        check(bench.manager.motion, bench.axis, IdentificationRequest({}, 75.0), drive)
    assert drive.read("target_velocity").raw == 0  # nothing started
