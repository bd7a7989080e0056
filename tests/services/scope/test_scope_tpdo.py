"""Captures without the recorder (docs/scope.md §7): the simulated CD1-k through synchronous TPDOs at the server's
SYNC, two axes in one capture, polling, and the refusals. The reference is the simulator itself: a probe on its
thread notes, at every SYNC a drive receives, the virtual time and the values the drive's TPDO is built from."""

from __future__ import annotations

import itertools

import pytest
from tests.support.sync_probe import (
    POSITION,
    STATUS_WORD,
    VELOCITY,
    SyncProbe,
    moving,
    offset_of,
    rows_of,
    tpdo_configuration,
)

from servostudio.services.scope import CaptureDefinition, CaptureRefused, Trigger, capture, capture_csv, check
from servostudio.services.scope import identity_of as identity


def test_a_cd1k_capture_through_tpdos_equals_the_simulators_values_at_each_sync(bench):
    moving(bench, 2, "cd1k", 50_000)
    cd1k = bench.drive(2)
    before = tpdo_configuration(cd1k)
    definition = CaptureDefinition(("0x6064,0", "0x606C,0", "0x6041,0"), period_us=1000, samples=300, timeout_s=10)
    plan = check(cd1k, definition, bench.connection.drive)
    preview = plan.describe()
    assert preview["source"] == "tpdo" and preview["rate_hz"] == 1000 and preview["frames_per_s"] == 3000
    assert preview["bus_load"] == pytest.approx((135 + 75 + 55) / 1000)  # worst-case bits of 8-, 2- and 0-byte frames
    probe = SyncProbe(bench.network, 2, [POSITION, VELOCITY, STATUS_WORD])
    made = capture(cd1k, identity(bench.connection, cd1k), definition, axes=bench.connection.drive)
    captured = rows_of(made)
    assert made.source == "tpdo" and made.samples == 300 and made.period_ns == 1_000_000
    assert len({position for position, _, _ in captured}) > 30  # the axis moved: the values tell the samples apart
    offset_of(probe.values(), captured)
    assert "# source: tpdo" in capture_csv(made) and made.alignment_ns is not None
    assert tpdo_configuration(cd1k) == before  # the drive's PDO configuration is back
    with bench.network.lock:
        assert bench.network.node(2).state.name == "PRE_OPERATIONAL"  # as it was before the capture


def test_a_tpdo_capture_with_a_trigger_and_pre_trigger(bench):
    moving(bench, 2, "cd1k", 200_000)
    cd1k = bench.drive(2)
    with bench.network.lock:
        level = bench.network.node(2).store.read_value(bench.network.node(2).store.od[POSITION]) + 40_000
    definition = CaptureDefinition(("0x6064,0",), period_us=1000, samples=100, pre_trigger_pct=25, timeout_s=20,
                                   trigger=Trigger("0x6064,0", "rising", level))  # fmt: skip
    probe = SyncProbe(bench.network, 2, [POSITION])
    made = capture(cd1k, identity(bench.connection, cd1k), definition, axes=bench.connection.drive)
    values = made.columns[0]
    assert made.trigger_index == 25 and values[24] < level <= values[25]
    offset_of(probe.values(), [(value,) for value in values])


def test_two_axes_in_one_capture_are_aligned_to_the_same_sync(bench):
    moving(bench, 2, "cd1k", 50_000)
    moving(bench, 1, "xtrapulspac", 30 * 4096)
    cd1k = bench.drive(2)
    definition = CaptureDefinition(("0x6064,0", "0x6064,0@1", "0x6041,0@1"), period_us=2000, samples=200)
    assert check(cd1k, definition, bench.connection.drive).describe()["nodes"] == [2, 1]
    probes = {node: SyncProbe(bench.network, node, [POSITION, STATUS_WORD]) for node in (1, 2)}
    made = capture(cd1k, identity(bench.connection, cd1k), definition, axes=bench.connection.drive)
    assert [channel.key for channel in made.channels] == ["0x6064,0", "0x6064,0@1", "0x6041,0@1"]
    cd1k_at = offset_of([values[:1] for values in probes[2].values()], [(v,) for v in made.columns[0]])
    xtrapulspac_at = offset_of(probes[1].values(), list(zip(made.columns[1], made.columns[2], strict=True)))
    assert cd1k_at == xtrapulspac_at  # the same SYNC: aligned to the sample (not within one: exactly)
    times = [probes[node].times()[cd1k_at : cd1k_at + 200] for node in (1, 2)]
    assert times[0] == times[1]  # both drives took each sample at the same virtual instant
    assert 'time_s,"0x6064,0","0x6064,0@1","0x6041,0@1"' in capture_csv(made)


def test_a_polled_capture_is_labelled_poll(bench):
    moving(bench, 2, "cd1k", 50_000)
    cd1k = bench.drive(2)
    definition = CaptureDefinition(("0x6064,0",), period_us=200_000, samples=5, source="poll")
    assert check(cd1k, definition, bench.connection.drive).describe()["source"] == "poll"
    made = capture(cd1k, identity(bench.connection, cd1k), definition, axes=bench.connection.drive)
    assert made.source == "poll" and "# source: poll" in capture_csv(made)
    positions = made.columns[0]
    assert all(later > earlier for earlier, later in itertools.pairwise(positions))


@pytest.mark.parametrize(
    ("definition", "reason"),
    [
        (CaptureDefinition(("0x6064,0",), period_us=250), "SYNC producer sets the rate, every 1000 µs at the fastest"),
        (CaptureDefinition(("0x6064,0",), period_us=1000, trigger=Trigger("0x606C,0", "rising", 1)),
         "the trigger must be one of the channels"),
        (CaptureDefinition(("0x6064,0", "0x6064,0@1"), source="recorder"), "node 2 \\(cd1k\\): no recorder"),
        (CaptureDefinition(("0x6064,0",), period_us=1000, mode="normal"), "need the drive's recorder"),
        (CaptureDefinition(("0x6064,0",) * 7, period_us=1000, source="tpdo"), "do not fit the TPDOs"),
    ],
)  # fmt: skip
def test_refused_before_anything_is_written(bench, definition, reason):
    cd1k = bench.drive(2)
    before = tpdo_configuration(cd1k)
    with pytest.raises(CaptureRefused, match=reason):
        capture(cd1k, identity(bench.connection, cd1k), definition, axes=bench.connection.drive)
    assert tpdo_configuration(cd1k) == before
