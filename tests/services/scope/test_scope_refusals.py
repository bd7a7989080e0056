"""What the drive cannot capture is refused with its reason before anything is written to the recorder."""

from __future__ import annotations

import pytest

from servostudio.errors import ErrorKind
from servostudio.services.scope import (
    CaptureDefinition,
    CaptureRefused,
    DefinitionError,
    NoRecorder,
    Trigger,
    capture,
    check,
    identity_of,
    parse_trigger,
)

FOUR_32_BIT = ("0x6064,0", "0x606C,0", "0x6062,0", "0x60F4,0")
#: every recorder object the service writes
RECORDER_WRITES = [
    *((0x5811, n) for n in (1, 2, 3, 4)),
    (0x5804, 2), (0x5804, 4), (0x5805, 0),
    *((0x5820, n) for n in (1, 2, 3, 4)),
    (0x5822, 1), (0x5822, 2), (0x5828, 0), (0x5840, 1), (0x5840, 2),
]  # fmt: skip


@pytest.fixture
def writes(bench) -> list:
    """The writes the recorder objects of node 1 receive from now on."""
    seen: list = []
    with bench.network.lock:
        store = bench.network.node(1).store
        for index, sub in RECORDER_WRITES:
            store.on_write(index, sub, lambda index, sub, value: seen.append((index, sub, value)))
    return seen


@pytest.mark.parametrize(
    ("definition", "reason"),
    [
        (CaptureDefinition(("0x1234,0",)), r"channel '0x1234,0': .*not in the xtrapulspac dictionary"),
        (CaptureDefinition(("0x306C",)), r"0x306C,0 Velocity measurement filter cannot be recorded"),
        (CaptureDefinition(("0x6041", "Statusword", "0x6064", "0x606C", "0x6078")), r"5 channels .* recorder has 4"),
        (CaptureDefinition(FOUR_32_BIT, samples=2049), r"32768 bytes hold 2048 samples of 16 bytes"),
        (CaptureDefinition(("0x6041",), period_us=300), r"period 300 µs: .* multiple of its 250 µs base period"),
        (CaptureDefinition(("0x6041",), period_us=250 * 70000), r"the longest is 16383750 µs"),
        (
            CaptureDefinition(("0x6041",), trigger=Trigger("0x6041", "rising", 70000)),
            r"trigger level 70000 on 0x6041,0 Statusword can never fire rising: the source takes 0..65535",
        ),
        (
            CaptureDefinition(("0x6041",), trigger=Trigger("0x6041", "falling", 65535)),
            r"can never fire falling",
        ),
        (
            CaptureDefinition(("0x6078",), trigger=Trigger("0x6078", "either", 4000)),
            r"trigger level 4000 % rated current .* the source takes -3276.8..3276.7 % rated current",
        ),
        (
            CaptureDefinition(("0x6041",), trigger=Trigger("0x60FD", "rising", 2**31)),
            r"beyond the recorder's signed 32-bit level",
        ),
        (CaptureDefinition(("0x6041",), trigger=Trigger("0x4242", "rising", 1)), r"trigger source '0x4242'"),
        (
            CaptureDefinition(("0x6041",), samples=10, trigger=Trigger("0x6041", "rising", 1), pre_trigger_pct=100),
            r"pre-trigger 100 % of 10 samples leaves no room for the trigger sample",
        ),
        (CaptureDefinition(("0x6041",), pre_trigger_pct=20), r"a pre-trigger needs a trigger"),
        (CaptureDefinition(("0x6041",), samples=1), r"at least 2 samples"),
        (CaptureDefinition(("0x6041",), auto_timeout_ms=0, mode="auto"), r"auto timeout 0 ms: use 1\.\.65535 ms"),
    ],
)
def test_refused_with_the_reason_and_nothing_written(bench, writes, definition, reason):
    drive = bench.drive()
    with pytest.raises(CaptureRefused, match=reason) as refused:
        capture(drive, identity_of(bench.connection, drive), definition)
    assert refused.value.kind is ErrorKind.INVALID_INPUT
    assert writes == []


def test_fewer_and_smaller_channels_allow_a_deeper_buffer(bench):
    assert check(bench.drive(), CaptureDefinition(("0x6041",), samples=16384)).depth == 16384
    assert check(bench.drive(), CaptureDefinition(FOUR_32_BIT)).depth == 2048  # the default: the full buffer


def test_a_trigger_on_a_channel_uses_the_channel_and_one_elsewhere_a_pointer(bench):
    on_channel = check(bench.drive(), CaptureDefinition(FOUR_32_BIT, trigger=Trigger("velocity_actual", "rising", 1)))
    elsewhere = check(bench.drive(), CaptureDefinition(FOUR_32_BIT, trigger=Trigger("0x60FF", "rising", 1)))
    assert on_channel.trigger_source == 2
    assert elsewhere.trigger_source == 0x60FF0020


def test_the_recorder_of_a_drive_without_one_is_refused(bench):
    drive = bench.drive(2)  # a CD1-k
    with pytest.raises(NoRecorder, match=r"node 2 \(cd1k\): no recorder; its captures go through TPDOs"):
        check(drive, CaptureDefinition(("0x6041",), source="recorder"))


@pytest.mark.parametrize(
    ("make", "reason"),
    [
        (lambda: CaptureDefinition(()), "at least one channel"),
        (lambda: CaptureDefinition(("0x6041",), mode="fast"), "mode 'fast'"),
        (lambda: Trigger("0x6041", "up", 1), "trigger edge 'up'"),
        (lambda: CaptureDefinition(("0x6041",), pre_trigger_pct=120), "pre-trigger 120 %"),
        (lambda: parse_trigger("0x606C,0:rising"), "write OBJECT:rising|falling|either:LEVEL"),
        (lambda: parse_trigger("0x606C,0:rising:fast"), "level 'fast' is not a number"),
        (lambda: CaptureDefinition.from_dict({"channels": ["0x6041"], "depth": 3}), "unknown capture definition keys"),
    ],
)
def test_malformed_definitions_are_refused_before_a_drive_is_asked(make, reason):
    with pytest.raises(DefinitionError, match=reason):
        make()


def test_the_cli_trigger_syntax_takes_an_object_with_a_colon():
    assert parse_trigger("60FF:0:falling:-2.5") == Trigger("60FF:0", "falling", -2.5)
