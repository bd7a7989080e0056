"""Recorder captures of two axes of one bus (docs/scope.md §8): two simulated XtrapulsPacs armed together by one
broadcast RPDO frame, judged against the simulator's own time — the virtual instant each drive took the arm and the
values it had after each control period (the probe of tests/support/recorder_peer.py) — and the sequential fallback
whose stated alignment must bound the true offset."""

from __future__ import annotations

import contextvars
import threading
from collections.abc import Iterator
from dataclasses import replace

import pytest
from tests.support.embedded_sim import open_sim
from tests.support.motion import controlling
from tests.support.recorder_peer import ARM, POSITION, REV, last_write, sample_grid
from tests.support.scope_bench import ScopeBench, until_booted

from servostudio.drive.rpdo import last_rpdo, read_rpdo
from servostudio.drive.tpdo import read_tpdo, tpdo_slots
from servostudio.services.bus import ConnectionManager
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope import CaptureDefinition, CaptureRefused, Trigger, capture, check, identity_of

CONTROL = (0x5828, 0)
PERIOD_NS = 250_000
SAMPLES = 200
TWO_AXES = CaptureDefinition(("0x6064,0", "0x6064,0@2"), period_us=250, samples=SAMPLES, source="recorder")
RELAY, STATUS = (0x23A0, 0), (0x5829, 0)
LEVEL_STEP = 200  # user units beyond node 2's position at rest: crossed once it turns


@pytest.fixture
def axes() -> Iterator[ScopeBench]:
    manager = ConnectionManager()
    open_sim(manager, "sim:1,2")
    try:
        two = ScopeBench(manager.get("sim"))
        for node in (1, 2):
            until_booted(two.drive(node))
        with controlling(manager, "sim", (1, 2)):  # the NMT start of the enabled axes needs their controller
            yield two
    finally:
        manager.close_all()


def moving(axes: ScopeBench, still: int | None = None) -> list:
    """Both axes turning (positions that change every control period; ``still`` enabled but standing), each node
    probed."""
    probes = []
    for node in (1, 2):
        probe = axes.probe([POSITION], node)
        probe.watch(CONTROL)
        probes.append(probe)
        axes.enable_profile_velocity(node)
        if node != still:
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


def test_a_two_axis_capture_triggered_on_one_axis_covers_the_same_control_periods_on_both(axes):
    """Node 2 (another axis than the capture's) triggers on its position; node 1 follows through node 2's TPDO. The
    truth is the simulator's: node 2's crossing at the configured pre-trigger sample, node 1's samples from the very
    same control periods, and every borrowed PDO and the relay object back as they were."""
    probes = moving(axes, still=2)
    before = pdo_state(axes)
    level = axes.machine(2).read("0x6064").raw + LEVEL_STEP
    triggered = replace(TWO_AXES, trigger=Trigger("0x6064,0@2", "rising", level), pre_trigger_pct=20, timeout_s=20)
    events: list[dict] = []
    armed = threading.Event()

    def report(event: dict) -> None:
        events.append(event)
        if event["stage"] == "armed":
            armed.set()

    result: list = []
    worker = threading.Thread(target=contextvars.copy_context().run, args=(_capture, axes, triggered, report, result))
    worker.start()
    assert armed.wait(10), events
    axes.machine(2).write("0x60FF", 5 * REV)  # node 2 starts turning: its position crosses the level
    worker.join(30)
    made = result[0]
    assert not isinstance(made, Exception), made

    pre = round(SAMPLES * 20 / 100)
    node2 = made.columns[1]
    assert made.trigger_index == pre and node2[pre - 1] < level <= node2[pre]  # the crossing at its sample, exactly
    grid = _crossing_grid(axes.rows(probes[1]), level, pre, probes[1])
    assert probes[1].column(POSITION, grid) == list(node2)
    periods = {row.period: row for row in axes.rows(probes[0])}
    assert list(made.columns[0]) == [periods[row.period].values[0] for row in grid]  # node 1: the same periods
    relay = next(event for event in events if event["stage"] == "armed")
    assert relay["arm"] == "relay" and made.alignment_ns == PERIOD_NS and "node 2's recorder triggered" in relay["note"]
    assert made.trigger == f"0x6064,0@2 rising {level} {made.channels[1].unit}".strip()
    assert pdo_state(axes) == before  # TPDO, RPDO and relay object written back


def test_a_triggered_two_axis_capture_cancelled_while_waiting_writes_every_borrowed_pdo_back(axes):
    moving(axes, still=2)
    before = pdo_state(axes)
    level = axes.machine(2).read("0x6064").raw + LEVEL_STEP  # never reached: node 2 stands still
    triggered = replace(TWO_AXES, trigger=Trigger("0x6064,0@2", "rising", level))
    cancellation, armed, result = Cancellation(), threading.Event(), []
    report = lambda event: armed.set() if event["stage"] == "armed" else None  # noqa: E731
    worker = threading.Thread(target=contextvars.copy_context().run,
                              args=(_capture, axes, triggered, report, result, cancellation))  # fmt: skip
    worker.start()
    assert armed.wait(10)
    cancellation.cancel()
    worker.join(20)
    assert isinstance(result[0], Cancelled), result
    assert pdo_state(axes) == before
    assert [axes.drive(node).read(STATUS).raw for node in (1, 2)] == [0, 0]  # no recorder left armed


def _capture(axes: ScopeBench, definition: CaptureDefinition, report, result: list,
             cancellation: Cancellation | None = None) -> None:  # fmt: skip
    drive = axes.drive(1)
    try:
        result.append(capture(drive, identity_of(axes.connection, drive), definition, report, cancellation,
                              axes=axes.connection.drive))  # fmt: skip
    except Exception as error:  # noqa: BLE001 -- the test reads what ended the capture
        result.append(error)


def _crossing_grid(rows: list, level: int, pre: int, probe) -> list:
    """The probe's control periods of the recording: the first at or above the level is the trigger sample."""
    values = probe.column(POSITION, rows)
    crossing = next(n for n in range(1, len(values)) if values[n - 1] < level <= values[n])
    return rows[crossing - pre : crossing - pre + SAMPLES]


def pdo_state(axes: ScopeBench) -> list:
    """What a triggered capture borrows: node 2's last TPDO with its timing, node 1's last RPDO and relay object."""
    trigger, follower = axes.drive(2), axes.drive(1)
    slot = tpdo_slots(trigger.dictionary)[-1]
    timing = [
        trigger.read((slot.communication, sub)).raw for sub in (3, 5) if trigger.dictionary.get(slot.communication, sub)
    ]
    return [read_tpdo(trigger, slot), timing, read_rpdo(follower, last_rpdo(follower)), follower.read(RELAY).raw]


def test_a_capture_of_two_axes_in_normal_mode_or_on_a_foreign_trigger_is_refused_before_anything_is_written(axes):
    normal = CaptureDefinition(("0x6064,0", "0x606C,0@2"), period_us=250, samples=SAMPLES, source="recorder",
                               trigger=Trigger("0x6064,0", "rising", 1), mode="normal")  # fmt: skip
    with pytest.raises(CaptureRefused, match="each recorder re-arms by itself"):
        check(axes.drive(1), normal, axes.connection.drive)
    foreign = CaptureDefinition(("0x6064,0", "0x606C,0@2"), period_us=250, samples=SAMPLES, source="recorder",
                                trigger=Trigger("0x6064,0@3", "rising", 1))  # fmt: skip
    with pytest.raises(CaptureRefused, match="node 3 has no channel in this capture"):
        check(axes.drive(1), foreign, axes.connection.drive)
    late = CaptureDefinition(("0x6064,0", "0x606C,0@2"), period_us=250, samples=SAMPLES, source="recorder",
                             trigger=Trigger("0x6064,0", "rising", 1), pre_trigger_pct=99.5)  # fmt: skip
    with pytest.raises(CaptureRefused, match="one sample more before it"):
        check(axes.drive(1), late, axes.connection.drive)
    assert check(axes.drive(1), TWO_AXES, axes.connection.drive).nodes == (1, 2)
