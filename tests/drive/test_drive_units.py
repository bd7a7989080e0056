"""Pure units of the drive layer: CiA 402 decoding and paths, NMT names, typed values, faults, EMCY."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.drive.cia402 import Command, State, apply_command, decode_state, next_command
from servostudio.drive.faults import cia402_error_text, faults_from_words
from servostudio.drive.monitor import decode_emergency
from servostudio.drive.nmt import NmtCommand
from servostudio.drive.object_values import ObjectValue, ValueInputError, decode_raw, parse_input
from servostudio.drive.profiles import profile_for, signature_value
from servostudio.od.datatypes import DataType, encode
from servostudio.od.model import Access, BitField, Variable


@pytest.mark.parametrize(
    "statusword, state",
    [
        (0x0240, State.SWITCH_ON_DISABLED),
        (0x0221, State.READY_TO_SWITCH_ON),
        (0x0223, State.SWITCHED_ON),
        (0x0227, State.OPERATION_ENABLED),
        (0x0207, State.QUICK_STOP_ACTIVE),
        (0x0208, State.FAULT),
        (0x020F, State.FAULT_REACTION_ACTIVE),
        (0x0200, State.NOT_READY_TO_SWITCH_ON),
        (0x8227, State.OPERATION_ENABLED),  # busy bit and warnings do not change the state
    ],
)
def test_manual_status_words_decode(statusword, state):
    assert decode_state(statusword) is state


def _simulate_path(start: State, target: State) -> list[Command]:
    """Follow next_command through the standard transitions."""
    result_of = {
        (State.SWITCH_ON_DISABLED, Command.SHUTDOWN): State.READY_TO_SWITCH_ON,
        (State.READY_TO_SWITCH_ON, Command.SWITCH_ON): State.SWITCHED_ON,
        (State.SWITCHED_ON, Command.ENABLE_OPERATION): State.OPERATION_ENABLED,
        (State.OPERATION_ENABLED, Command.DISABLE_OPERATION): State.SWITCHED_ON,
        (State.SWITCHED_ON, Command.SHUTDOWN): State.READY_TO_SWITCH_ON,
        (State.READY_TO_SWITCH_ON, Command.DISABLE_VOLTAGE): State.SWITCH_ON_DISABLED,
        (State.OPERATION_ENABLED, Command.QUICK_STOP): State.QUICK_STOP_ACTIVE,
        (State.QUICK_STOP_ACTIVE, Command.DISABLE_VOLTAGE): State.SWITCH_ON_DISABLED,
        (State.FAULT, Command.FAULT_RESET): State.SWITCH_ON_DISABLED,
    }
    commands, state = [], start
    while (command := next_command(state, target)) is not None:
        commands.append(command)
        state = result_of[(state, command)]
        assert len(commands) < 8
    return commands


reachable = [
    State.SWITCH_ON_DISABLED,
    State.READY_TO_SWITCH_ON,
    State.SWITCHED_ON,
    State.OPERATION_ENABLED,
    State.QUICK_STOP_ACTIVE,
]


@given(st.sampled_from([*reachable, State.FAULT]), st.sampled_from(reachable))
def test_every_reachable_target_is_reached(start, target):
    _simulate_path(start, target)


def test_enable_sequence_of_the_manual():
    assert _simulate_path(State.SWITCH_ON_DISABLED, State.OPERATION_ENABLED) == [
        Command.SHUTDOWN,
        Command.SWITCH_ON,
        Command.ENABLE_OPERATION,
    ]
    assert apply_command(0x0070, Command.ENABLE_OPERATION) == 0x007F  # mode bits 4-6 kept


def test_state_and_nmt_names():
    assert State.parse("operation-enabled") is State.OPERATION_ENABLED
    assert NmtCommand.parse("reset-communication") is NmtCommand.RESET_COMMUNICATION
    assert NmtCommand.parse("pre-operational") is NmtCommand.PRE_OPERATIONAL
    with pytest.raises(ValueError, match="unknown NMT command 'jump'"):
        NmtCommand.parse("jump")


def test_signatures_are_little_endian_ascii():
    assert signature_value("save") == 0x65766173
    assert profile_for("xtrapulspac").signature("load_user") == ((0x1011, 1), 0x7273756C)


def _variable(data_type=DataType.INTEGER16, **extra) -> Variable:
    return Variable(index=0x2002, subindex=0, name="Test", data_type=data_type, access=Access.RW, **extra)


@given(st.integers(-32768, 32767))
def test_integer_input_round_trip(value):
    variable = _variable()
    for text in (str(value), hex(value) if value >= 0 else str(value)):
        raw = parse_input(variable, text)
        assert raw == value
        assert decode_raw(variable, encode(DataType.INTEGER16, raw)) == value


@given(st.integers(-10_000, 10_000))
def test_physical_input_uses_scale_and_offset(value):
    variable = _variable(DataType.INTEGER32, scale=0.5, offset=10.0, unit="rpm")
    raw = parse_input(variable, value * 0.5 + 10.0, physical=True)
    assert raw == value
    assert ObjectValue(1, variable, raw).physical == pytest.approx(value * 0.5 + 10.0)


def test_inputs_refused_with_the_object_named():
    variable = _variable(low=-5, high=5, enum={1: "On", 0: "Off"})
    assert parse_input(variable, "on") == 1
    with pytest.raises(ValueInputError, match=r"0x2002,0 Test: 6 is outside -5..5"):
        parse_input(variable, 6)
    with pytest.raises(ValueInputError, match="one of: On, Off"):
        parse_input(variable, "maybe")
    with pytest.raises(ValueInputError, match="needs an integer"):
        parse_input(variable, 1.5)


def test_wider_answer_is_accepted_but_garbage_is_not():
    variable = _variable(DataType.UNSIGNED8)
    assert decode_raw(variable, b"\x07\x00\x00\x00") == 7
    with pytest.raises(ValueInputError):
        decode_raw(variable, b"\x07\x01")


def test_bits_and_enumeration_text():
    variable = _variable(
        DataType.UNSIGNED16, bits=(BitField(3, 3, "Fault"), BitField(8, 9, "Pair")), enum={0x0308: "special"}
    )
    value = ObjectValue(1, variable, 0x0308)
    assert value.text == "special"
    assert [(bit["name"], bit["value"]) for bit in value.bits()] == [("Fault", 1), ("Pair", 3)]


def test_xtrapulspac_error_words_and_emcy():
    profile = profile_for("xtrapulspac")
    faults = faults_from_words(dict(profile.errors), [(0x4, 1), (0x4, 33)])
    assert [(fault.code, fault.name) for fault in faults] == [
        (3, "Undervoltage (temporized)"),
        (35, "Position following error"),
    ]
    assert "0x6065" in faults[1].remedy
    emergency = decode_emergency(4, bytes([0x11, 0x86, 0x81, 35, 0, 0, 0, 0]), profile)
    assert emergency.cia402_code == 0x8611 and emergency.error_register == 0x81
    assert emergency.faults[0].name == "Position following error"
    assert emergency.as_dict()["cia402_text"] == "following error"
    assert decode_emergency(4, bytes(8), profile).cleared


def test_cd1k_emcy_bitfield_and_unknown_codes():
    emergency = decode_emergency(2, bytes([0x00, 0xFF, 0x01, 0x08, 0x00, 0x00, 0x00, 0x00]), profile_for("cd1k"))
    assert [fault.name for fault in emergency.faults] == ["Following error"]
    assert cia402_error_text(0x7123) == "additional modules"
    assert faults_from_words({}, [(1 << 5, 1)])[0].name == "error code 6 (not in the manual)"


def test_every_xtrapulspac_code_has_a_row():
    profile = profile_for("xtrapulspac")
    assert sorted(profile.errors) == list(range(1, 65))
    assert all(info.cia402_code for info in profile.errors.values())


@pytest.mark.parametrize("start", [State.SWITCH_ON_DISABLED, State.READY_TO_SWITCH_ON, State.SWITCHED_ON, State.FAULT])
def test_quick_stop_never_walks_a_stopped_axis_up(start):
    """A drive whose quick-stop option code ends in SWITCH ON DISABLED is stopped, not re-enabled."""
    assert next_command(start, State.QUICK_STOP_ACTIVE) is None
    assert next_command(State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE) is Command.QUICK_STOP
