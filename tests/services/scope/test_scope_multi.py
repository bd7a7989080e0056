"""Recorder captures of two axes of one bus (docs/scope.md §8): two simulated XtrapulsPacs armed together by one
broadcast RPDO frame, judged against the simulator's own time — the virtual instant each drive took the arm and the
values it had after each control period (the probe of tests/sim/recorder_peer.py) — and the sequential fallback
whose stated alignment must bound the true offset."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.services.scope.conftest import ScopeBench, _until_booted
from tests.sim.recorder_peer import ARM, POSITION, REV, last_write, sample_grid
from tests.support.embedded_sim import open_sim

from servostudio.drive.rpdo import last_rpdo, read_rpdo
from servostudio.services.bus import ConnectionManager
from servostudio.services.scope import CaptureDefinition, CaptureRefused, Trigger, capture, check, identity_of

CONTROL = (0x5828, 0)
PERIOD_NS = 250_000
SAMPLES = 200
TWO_AXES = CaptureDefinition(("0x6064,0", "0x6064,0@2"), period_us=250, samples=SAMPLES, source="recorder")


@pytest.fixture
def axes() -> Iterator[ScopeBench]:
    manager = ConnectionManager()
    open_sim(manager, "sim:1,2")
    try:
        two = ScopeBench(manager.get("sim"))
        for node in (1, 2):
            _until_booted(two.drive(node))
        yield two
    finally:
        manager.close_all()


def moving(axes: ScopeBench) -> list:
    """Both axes turning (positions that change every control period), each node probed."""
    probes = []
    for node in (1, 2):
        probe = axes.probe([POSITION], node)
        probe.watch(CONTROL)
        probes.append(probe)
        axes.enable_profile_velocity(node)
        axes.machine(node).write("0x60FF", (3 + node) * REV)
    return probes


def instants(axes: ScopeBench, probe, column) -> list:
    """The simulator's control periods the recording was taken at: from the arm it received (its own clock), and
    the recorded values must be its values there."""
    grid = sample_grid(axes.rows(probe), last_write(probe, CONTROL, ARM), 1)[:SAMPLES]
    assert probe.column(POSITION, grid) == list(column)
    return grid


def rpdo_state(axes: ScopeBench) -> list:
    return [read_rpdo(axes.drive(node), last_rpdo(axes.drive(node))) for node in (1, 2)]


def test_a_two_axis_capture_armed_by_one_broadcast_frame_is_aligned_within_one_sample(axes):
    probes = moving(axes)
    before = rpdo_state(axes)
    events: list[dict] = []
    drive = axes.drive(1)
    made = capture(drive, identity_of(axes.connection, drive), TWO_AXES, events.append, axes=axes.connection.drive)

    first, second = (instants(axes, probe, column) for probe, column in zip(probes, made.columns, strict=True))
    assert abs(first[0].time - second[0].time) < PERIOD_NS / 1e9  # the same control period: within one sample
    assert [row.time for row in first] == [row.time for row in second]
    armed = next(event for event in events if event["stage"] == "armed")
    assert armed["arm"] == "broadcast" and made.alignment_ns == PERIOD_NS
    assert [channel.key for channel in made.channels] == ["0x6064,0", "0x6064,0@2"] and made.source == "recorder"
    assert rpdo_state(axes) == before  # the borrowed RPDOs are written back


def test_a_drive_that_misses_the_broadcast_is_armed_sequentially_and_the_stated_alignment_bounds_the_truth(axes):
    """Said OPERATIONAL while it is not, no drive acts on the RPDO: the capture falls back and says so."""
    probes = moving(axes)
    events: list[dict] = []
    drive = axes.drive(1)
    made = capture(drive, identity_of(axes.connection, drive), TWO_AXES, events.append, axes=axes.connection.drive,
                   operational=lambda node: True)  # fmt: skip

    first, second = (instants(axes, probe, column) for probe, column in zip(probes, made.columns, strict=True))
    armed = next(event for event in events if event["stage"] == "armed")
    assert armed["arm"] == "sequential" and "did not take the broadcast arm" in str(armed["note"])
    assert made.alignment_ns is not None and made.alignment_ns > PERIOD_NS
    assert abs(first[0].time - second[0].time) * 1e9 <= made.alignment_ns


def test_a_triggered_recorder_capture_of_two_axes_is_refused_before_anything_is_written(axes):
    triggered = CaptureDefinition(("0x6064,0", "0x606C,0@2"), period_us=250, samples=SAMPLES, source="recorder",
                                  trigger=Trigger("0x6064,0", "rising", 1))  # fmt: skip
    with pytest.raises(CaptureRefused, match="immediate trigger and single mode only"):
        check(axes.drive(1), triggered, axes.connection.drive)
    assert check(axes.drive(1), TWO_AXES, axes.connection.drive).nodes == (1, 2)
