"""Device control on a Drive: CiA 402 state changes, fault reading and fault reset."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import Command, State, apply_command, decode_state, next_command
from servostudio.drive.faults import FaultInfo, cia402_error_text, faults_from_words
from servostudio.drive.prerequisites import Unmet, check_move, procedure_causes
from servostudio.errors import Conflict

STEP_TIMEOUT = 1.0
POLL_PERIOD = 0.01


class StateChangeError(Conflict, RuntimeError):
    """The drive did not reach the requested state; names node, state reached and status word."""


def read_state(drive: Drive) -> tuple[State | None, int]:
    statusword = int(drive.read("statusword").raw)
    return decode_state(statusword), statusword


def set_state(drive: Drive, target: State, step_timeout: float = STEP_TIMEOUT) -> State:
    """Walk the CiA 402 state machine to ``target`` one command at a time, checking each step.

    A drive in FAULT is not reset on the way: resetting a fault is the user's decision (``reset_faults``), so the
    error names the active faults instead.  An axis that could not move once enabled (a limit of its mode is 0) is
    not enabled: the error names the objects that stop it.
    """
    if target is State.OPERATION_ENABLED:
        check_move(drive)
    for _ in range(8):
        state, statusword = read_state(drive)
        if state is None:
            raise StateChangeError(f"node {drive.node}: status word 0x{statusword:04X} is no CiA 402 state")
        if state in (State.FAULT, State.FAULT_REACTION_ACTIVE):
            raise StateChangeError(f"node {drive.node}: in {state.value}{_fault_names(drive)}; reset the fault first")
        command = next_command(state, target)
        if command is None:
            return state
        controlword = int(drive.read("controlword").raw) if drive.variable("controlword").access.readable else 0
        drive.write("controlword", command_word(drive, controlword, command))
        _wait_for_change(drive, state, step_timeout)
    state, statusword = read_state(drive)
    raise StateChangeError(
        f"node {drive.node}: stuck in {state.value if state else '?'} "
        f"(status word 0x{statusword:04X}) on the way to {target.value}"
    )


def _wait_for_change(drive: Drive, previous: State, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state, statusword = read_state(drive)
        if state is not previous:
            return
        time.sleep(POLL_PERIOD)
    state, statusword = read_state(drive)
    raise StateChangeError(
        f"node {drive.node}: still {state.value if state else '?'} (status word "
        f"0x{statusword:04X}) {timeout:.1f} s after the command"
    )


def _fault_names(drive: Drive) -> str:
    faults = fault_report(drive).faults
    return f" ({', '.join(fault.name for fault in faults)})" if faults else ""


def command_word(drive: Drive, controlword: int, command: Command) -> int:
    """The control word that gives ``command``: its bits as the device needs them (``controlword_commands``), the
    device's fixed bits (``controlword_fixed``: the TTA-PRO's control by PROFIBUS, no stop, no intermediate stop),
    the other bits kept."""
    profile = drive.profile
    bits = profile.controlword_commands.get(int(command), int(command))
    others = apply_command(controlword, Command.DISABLE_VOLTAGE)  # the command bits cleared, the others kept
    return others | bits | profile.controlword_fixed


def quick_stop_word(drive: Drive) -> int:
    """The quick stop as one control word, written without reading the control word first (lost controller)."""
    return command_word(drive, 0, Command.QUICK_STOP)


def reset_faults(drive: Drive) -> None:
    """Rising edge of control word bit 7, then bit 7 cleared again (the manual: the host must clear it)."""
    controlword = int(drive.read("controlword").raw) & ~0x80
    drive.write("controlword", controlword)
    drive.write("controlword", command_word(drive, controlword, Command.FAULT_RESET))
    drive.write("controlword", (controlword & ~0x8F) | drive.profile.controlword_fixed)


@dataclass
class FaultReport:
    node: int
    state: str | None
    statusword: int
    error_code: int
    error_text: str
    faults: list[FaultInfo] = field(default_factory=list)
    warnings: list[FaultInfo] = field(default_factory=list)
    #: what the tool sees behind the faults: objects a failed procedure needed, at 0 or out of range
    causes: list[Unmet] = field(default_factory=list)

    def as_dict(self) -> dict[str, object]:
        return {
            "node": self.node,
            "state": self.state,
            "statusword": self.statusword,
            "fault": bool(self.statusword & 8),
            "error_code": self.error_code,
            "error_text": self.error_text,
            "faults": [item.as_dict() for item in self.faults],
            "warnings": [item.as_dict() for item in self.warnings],
            "causes": [item.as_dict() for item in self.causes],
        }


def fault_report(drive: Drive) -> FaultReport:
    """Status word, 0x603F and the device's error/warning words decoded with the manual's texts, and for a failed
    procedure the inputs it needed that the tool sees at 0 or out of range (the drive itself only says "failed")."""
    profile = drive.profile
    state, statusword = read_state(drive)
    error_code = int(drive.read("error_code").raw) if profile.has("error_code") else 0
    known = profile.emcy_codes.get(error_code)
    text = (known.name if known else cia402_error_text(error_code)) if profile.has("error_code") else ""
    faults = _word_faults(drive) or [fault for fault in [profile.code_fault(error_code)] if fault]
    failed = profile.procedure_fault is not None and any(fault.code == profile.procedure_fault for fault in faults)
    return FaultReport(
        drive.node,
        state.value if state else None,
        statusword,
        error_code,
        text,  # "" for a drive without an error-code object (the TTA-PRO: its faults are its error words)
        faults,
        _warnings(drive),
        procedure_causes(drive) if failed else [],
    )


def _word_faults(drive: Drive) -> list[FaultInfo]:
    profile = drive.profile
    words = [(int(drive.read(name).raw), first) for name, first in profile.error_words]
    return faults_from_words(profile.errors, words, profile.coded_error_bits)


def _warnings(drive: Drive) -> list[FaultInfo]:
    name = drive.profile.warning_word
    return faults_from_words(drive.profile.warnings, [(int(drive.read(name).raw), 1)]) if name else []
