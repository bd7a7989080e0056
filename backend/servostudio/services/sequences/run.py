"""Running a program: sequence mode, the axis enabled, the number selected, the start and stop bits, the inputs.

Everything that can move the axis goes through the motion guard (``services.motion``): the caller must be the
axis's armed controller before anything is written (``MotionGuard.require_controller``), and every write — the mode
0x6060 = −3, the control words, the sequence number 0x3601,1, the conditional input 0x3601,3, the simulated
inputs — is judged by the guard as the drive's write gate (the profile lists them as motion objects).
"""

from __future__ import annotations

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import read_state, set_state
from servostudio.errors import InvalidInput
from servostudio.formats.numbers import parse_integer
from servostudio.services.audit import current_actor
from servostudio.services.motion import MotionGuard
from servostudio.services.sequences.memory import limits

#: 0x6060 of the XtrapulsPac's sequence mode
SEQUENCE_MODE = -3
START_BIT, STOP_BIT = 1 << 4, 1 << 5
CONDITION_WIDTH, SIM_INPUT_WIDTH = 16, 5


def parse_bits(text: str, width: int, current: int = 0) -> int:
    """A bit pattern as the CLI and the page give it: up to ``width`` characters of ``1``/``0``/``.`` MSB first,
    right-aligned (``"1......."`` sets bit 7, ``10000`` IN5; ``.`` keeps the bit of ``current``), or any other number
    (``0x80``, ``128``) as it is."""
    chars = text.strip().strip('"')
    if chars and not set(chars) - set("10."):
        if len(chars) > width:
            raise InvalidInput(f"bit pattern {text!r}: more than {width} characters")
        value = current
        for bit, char in enumerate(reversed(chars)):
            if char != ".":
                value = value & ~(1 << bit) | (int(char) << bit)
        return value
    number = parse_integer(chars)
    if number is None or not 0 <= number < 1 << width:
        raise InvalidInput(
            f'bit pattern {text!r}: up to {width} characters of 1, 0 and . (MSB first, e.g. "1.......") '
            f"or a number 0..{(1 << width) - 1}"
        )
    return number


def as_signed16(bits: int) -> int:
    """0x3601,3 is an Integer16: bit 15 is its sign."""
    return bits - (1 << 16) if bits & 0x8000 else bits


def set_conditional_input(drive: Drive, pattern: str) -> int:
    """0x3601,3 from a pattern (dots keep the bits it has); returns the bits written."""
    current = int(drive.read("sequence_conditional_input").raw) & 0xFFFF
    bits = parse_bits(pattern, CONDITION_WIDTH, current)
    drive.write("sequence_conditional_input", as_signed16(bits))
    return bits


def set_sim_inputs(drive: Drive, pattern: str) -> int:
    """The simulated drive's IN1..IN5 (0x5F00, simulator only, not in the EDS: a raw write the guard still judges)."""
    bits = parse_bits(pattern, SIM_INPUT_WIDTH)
    index, sub = drive.profile.address("sim_physical_inputs")
    drive.write_raw_bytes(index, sub, bits.to_bytes(2, "little"))
    return bits


def start(motion: MotionGuard, bus: str, drive: Drive, number: int) -> dict[str, object]:
    """Sequence mode, Operation enabled, 0x3601,1 = number, a rising edge of control word bit 4."""
    found = limits(drive)
    if not 0 <= number < found.count:
        raise InvalidInput(f"node {drive.node}: sequence {number} is outside 0..{found.count - 1} (0x3612)")
    motion.require_controller(current_actor(), (bus, drive.node), f"starting sequence {number} on node {drive.node}")
    if int(drive.read("modes_of_operation_display").raw) != SEQUENCE_MODE:
        drive.write("modes_of_operation", SEQUENCE_MODE)
    set_state(drive, State.OPERATION_ENABLED)
    drive.write("sequence_number_input", number)
    control = _controlword(drive) & ~(START_BIT | STOP_BIT)
    drive.write("controlword", control)
    drive.write("controlword", control | START_BIT)
    return {"node": drive.node, "sequence": number, "started": True}


def stop(drive: Drive) -> dict[str, object]:
    """Control word bit 5: the running sequence brakes with its own deceleration and the program ends."""
    drive.write("controlword", _controlword(drive) & ~START_BIT | STOP_BIT)
    state, _ = read_state(drive)
    return {"node": drive.node, "stopped": True, "state": state.value if state else None}


def _controlword(drive: Drive) -> int:
    return int(drive.read("controlword").raw)
