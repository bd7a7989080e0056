"""Captures through the capture service (``services.scope``) from a simulated XtrapulsPac, compared with the
simulator's own signals at the recorder's sample instants (the probe of tests/support/recorder_peer.py)."""

from __future__ import annotations

import itertools

import pytest
from tests.support.recorder_peer import (
    ARM,
    CURRENT,
    POSITION,
    REV,
    STATUS_WORD,
    TARGET_VELOCITY,
    VELOCITY,
    last_write,
    sample_grid,
)

from servostudio.services.cancel import Cancelled
from servostudio.services.scope import CaptureDefinition, NoTrigger, Trigger, capture, identity_of

CHANNELS = ("0x6064,0", "0x606C,0", "0x6078,0", "0x6041,0")
KEYS = [POSITION, VELOCITY, CURRENT, STATUS_WORD]
CONTROL = (0x5828, 0)
LEVEL = 5 * REV  # the velocity crossing that triggers: 5 rev/s in user units per second


def speed_step(period_us: int) -> CaptureDefinition:
    return CaptureDefinition(
        channels=CHANNELS,
        period_us=period_us,
        samples=400,
        trigger=Trigger("0x606C,0", "rising", LEVEL),
        pre_trigger_pct=20,
    )


@pytest.mark.parametrize("period_us", [250, 1000])
def test_speed_step_trigger_position_spacing_and_values_are_the_simulators(bench, period_us):
    """Issue #12, done when: a PV speed step with pre-trigger 20 %."""
    multiplier, pre_trigger = period_us // 250, 80
    probe = bench.probe([*KEYS, TARGET_VELOCITY])
    probe.watch(CONTROL)
    bench.enable_profile_velocity()
    running = bench.in_background(speed_step(period_us))
    running.wait_stage("waiting")
    bench.machine().write("0x60FF", 20 * REV)
    made = running.outcome()

    grid = sample_grid(bench.rows(probe), last_write(probe, CONTROL, ARM), multiplier)
    velocity = probe.column(VELOCITY, grid)
    fired = next(k for k in range(pre_trigger, len(grid)) if velocity[k - 1] < LEVEL <= velocity[k])
    instants = grid[fired - pre_trigger : fired - pre_trigger + 400]
    assert abs(made.trigger_index - pre_trigger) <= 1 and made.time_ns(made.trigger_index) == 0
    assert made.period_ns == period_us * 1000
    assert {later.period - earlier.period for earlier, later in itertools.pairwise(instants)} == {multiplier}
    assert list(zip(*made.columns, strict=True)) == probe.values(instants, KEYS)
    assert made.physical(2) == [raw / 10 for raw in probe.column(CURRENT, instants)]  # 0.1 % rated current
    assert made.channels[1].unit == "user unit/s" and made.trigger == f"0x606C,0 rising {LEVEL} user unit/s"
    stages = [event["stage"] for event in running.stages]
    assert stages[0] == "armed" and "waiting" in stages and stages.index("waiting") < stages.index("uploading")
    assert running.stages[-1] == {"stage": "uploading", "done": 400 * 12, "total": 400 * 12}


def test_immediate_capture_starts_at_the_arm_with_time_zero_first(bench):
    probe = bench.probe(KEYS)
    probe.watch(CONTROL)
    drive = bench.drive()
    made = capture(drive, identity_of(bench.connection, drive), CaptureDefinition(CHANNELS, samples=100))
    grid = sample_grid(bench.rows(probe), last_write(probe, CONTROL, ARM), 1)
    assert made.trigger_index == 0 and made.times_s()[:3] == [0.0, 0.00025, 0.0005]
    assert list(zip(*made.columns, strict=True)) == probe.values(grid[:100], KEYS)
    assert made.drive.device == "xtrapulspac" and made.drive.vendor_id is not None


def test_depth_by_duration_fills_the_time_asked(bench):
    drive = bench.drive()
    definition = CaptureDefinition(("0x6041,0",), period_us=500, duration_s=0.1)
    made = capture(drive, identity_of(bench.connection, drive), definition)
    assert made.samples == 200 and made.period_ns == 500_000


def test_force_while_waiting_makes_the_next_sample_the_trigger(bench):
    never = CaptureDefinition(CHANNELS, samples=50, trigger=Trigger("0x6064,0", "rising", 10**9), pre_trigger_pct=20)
    running = bench.in_background(never)
    running.wait_stage("waiting")
    bench.drive().write("0x5828", 2)
    made = running.outcome()
    assert made.trigger_index == 10 and made.samples == 50


def test_no_trigger_within_the_timeout_stops_the_recorder(bench):
    never = CaptureDefinition(CHANNELS, samples=50, trigger=Trigger("0x6064,0", "rising", 10**9), timeout_s=0.3)
    drive = bench.drive()
    with pytest.raises(NoTrigger, match=r"no complete recording within 0.3 s \(recorder waiting\)"):
        capture(drive, identity_of(bench.connection, drive), never)
    assert drive.read("0x5829").raw == 0


def test_cancel_while_waiting_stops_the_recorder(bench):
    never = CaptureDefinition(CHANNELS, samples=50, trigger=Trigger("0x6064,0", "rising", 10**9))
    running = bench.in_background(never)
    running.wait_stage("waiting")
    running.cancellation.cancel()
    assert isinstance(running.outcome(), Cancelled)
    assert bench.drive().read("0x5829").raw == 0


def test_normal_mode_capture_takes_the_first_recording_and_freezes_the_recorder(bench):
    drive = bench.drive()
    definition = CaptureDefinition(("0x6064,0", "0x6041,0"), samples=40, mode="normal")
    made = capture(drive, identity_of(bench.connection, drive), definition)
    assert made.samples == 40 and drive.read("0x5829").raw == 0  # stopped for the upload
