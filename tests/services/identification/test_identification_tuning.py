"""The tuning after a tool-side identification (docs/identification.md § Tuning): gains for a requested bandwidth
through the device profile's gain objects, verified by a recorded speed step whose bandwidth is measured from the
recording (never from the formula); the encoTRive, whose loops are set in the factory, is refused before anything
is written."""

from __future__ import annotations

import pytest

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


def test_a_drive_without_gain_objects_or_a_bandwidth_out_of_range_is_refused_first(id_bench):
    bench = id_bench("encotrive", 4)
    with pytest.raises(NoSpeedLoop, match="no speed-loop gain objects"):
        tuned(bench, 75.0)
    with pytest.raises(BadTuning, match=r"20\.\.200 Hz"):
        tuned(bench, 500.0)
    assert bench.drive().read("target_velocity").raw == 0  # nothing started
