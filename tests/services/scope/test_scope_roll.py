"""Live roll mode (docs/scope.md §8): 4 channels of an axis streamed through synchronous TPDOs at the server's SYNC,
sequence-numbered; every sample equals the simulator's values at consecutive SYNCs; a cut link is a gap that is
reported, and the roll goes on after it; a roll the bus cannot carry is refused before anything is written."""

from __future__ import annotations

import threading

import pytest
from tests.support.sync_probe import SyncProbe, moving, offset_of, tpdo_configuration

from servostudio.services.cancel import Cancellation
from servostudio.services.scope import CaptureDefinition, CaptureRefused
from servostudio.services.scope.roll import RollStream, roll_plan

FOUR = ("0x6064,0", "0x606C,0", "0x6041,0", "0x6078,0")
KEYS = [(0x6064, 0), (0x606C, 0), (0x6041, 0), (0x6078, 0)]


def rolled(bench_connection, node: int, seconds: float, events: list, on_event=None) -> RollStream:
    drive = bench_connection.drive(node)
    plan = roll_plan(drive, bench_connection.drive, CaptureDefinition(FOUR, period_us=1000), None, seconds)

    def feed(event: dict) -> None:
        events.append(event)
        if on_event is not None:
            on_event(event)

    stream = RollStream(plan, bench_connection.drive, drive.engine.link, feed, seconds, record=True)
    stream.run(lambda event: None, Cancellation())
    return stream


def samples_of(events: list) -> tuple[list[int], list[tuple]]:
    """The sequence numbers and the rows of the samples events."""
    numbers, rows = [], []
    for event in events:
        if event["type"] == "samples":
            numbers += range(event["seq"], event["seq"] + event["count"])
            rows += list(zip(*event["values"], strict=True))
    return numbers, rows


def test_a_roll_delivers_every_sample_in_sequence_equal_to_the_simulator(bench):
    moving(bench, 1, "xtrapulspac", 30 * 4096)
    before = tpdo_configuration(bench.drive(1))
    probe = SyncProbe(bench.network, 1, KEYS)
    events: list[dict] = []
    stream = rolled(bench.connection, 1, 3.0, events)
    numbers, rows = samples_of(events)
    assert numbers == list(range(3000)) and stream.summary()["gaps"] == []  # every sample, in order, none lost
    assert len({row[0] for row in rows}) > 100  # the axis moved: the values tell the samples apart
    raw = [tuple(info.raw_of(value) for info, value in zip(stream.channels, row, strict=True)) for row in rows]
    offset_of(probe.values(), raw)  # physical values of the raw ones the drive sampled at consecutive SYNCs
    assert next(zip(*stream.recorded, strict=True)) == tuple(row[0] for row in rows)  # recorded: every sample
    assert tpdo_configuration(bench.drive(1)) == before


def test_a_roll_the_bus_cannot_carry_is_refused_before_anything_is_written(bench):
    drive = bench.drive(1)
    before = tpdo_configuration(drive)
    two_axes = CaptureDefinition((*FOUR, *(f"{key}@2" for key in FOUR[:2])), period_us=1000)
    with pytest.raises(CaptureRefused, match=r"the bus allows .* at the fastest"):
        roll_plan(drive, bench.connection.drive, two_axes, 250_000, None)
    with pytest.raises(CaptureRefused, match="up to 4 channels per axis"):
        roll_plan(drive, bench.connection.drive, CaptureDefinition((*FOUR, "0x6062,0")), None, None)
    assert tpdo_configuration(drive) == before


def test_a_cut_link_is_a_reported_gap_and_the_roll_goes_on(connection, socketcand):
    events: list[dict] = []

    def cut_once(event: dict) -> None:
        if event["type"] == "samples" and event["seq"] > 500 and not cut:
            cut.append(event)
            socketcand.cut()
            threading.Timer(0.5, socketcand.restore).start()

    cut: list[dict] = []
    stream = rolled(connection, 1, 4.0, events, cut_once)
    gaps = [event for event in events if event["type"] == "gap"]
    # the link's loss, or (on a loaded host, when the SYNCs' silence is noticed first) the unanswered SYNCs
    assert len(gaps) == 1 and any(cause in gaps[0]["reason"] for cause in ("link lost", "SYNC unanswered")), gaps
    numbers, _ = samples_of(events)
    start, end = gaps[0]["from"], gaps[0]["to"]
    assert end - start >= 300  # the cut lasted 0.5 s at 1 kHz: those sequence numbers are missing, said so
    assert numbers == [n for n in range(numbers[-1] + 1) if not start <= n < end]  # nothing else missing
    assert numbers[-1] > end + 100  # the roll went on after the link came back
    assert stream.summary()["lost"] == end - start and stream.summary()["recorded"] == start
