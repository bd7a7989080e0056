"""The shape of a device profile and the CiA 301/402 objects every profile starts from."""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from servostudio.drive.faults import CodedBits, FaultInfo, cia402_error_text
from servostudio.drive.profiles.procedures import NO_PROCEDURES, ProcedureSet
from servostudio.drive.profiles.sequence_buffer import SequenceBuffer
from servostudio.drive.profiles.speed_loop import SpeedLoopDescription
from servostudio.errors import NotFound
from servostudio.od.model import SaveType

if TYPE_CHECKING:  # the recorder module builds on this one's ProfileError
    from servostudio.drive.profiles.io import IoDescription
    from servostudio.drive.profiles.recorder import RecorderDescription

#: Objects every CiA 301 device has, and those of a CiA 402 drive, by semantic name.
CIA301_OBJECTS: dict[str, tuple[int, int]] = {
    "device_type": (0x1000, 0),
    "error_register": (0x1001, 0),
    "device_name": (0x1008, 0),
    "hardware_version": (0x1009, 0),
    "software_version": (0x100A, 0),
    "store_parameters": (0x1010, 1),
    "restore_parameters": (0x1011, 1),
    "heartbeat_time": (0x1017, 0),
    "vendor_id": (0x1018, 1),
    "product_code": (0x1018, 2),
    "revision": (0x1018, 3),
    "serial_number": (0x1018, 4),
}
CIA402_OBJECTS: dict[str, tuple[int, int]] = {
    "error_code": (0x603F, 0),
    "controlword": (0x6040, 0),
    "statusword": (0x6041, 0),
    "modes_of_operation": (0x6060, 0),
    "modes_of_operation_display": (0x6061, 0),
    "position_actual": (0x6064, 0),
    "velocity_actual": (0x606C, 0),
    "following_error_actual": (0x60F4, 0),
    "dc_link_voltage": (0x6079, 0),
    "target_position": (0x607A, 0),
    "target_velocity": (0x60FF, 0),
    "target_torque": (0x6071, 0),
    "vl_target_velocity": (0x6042, 0),
    "max_profile_velocity": (0x607F, 0),
    "profile_velocity": (0x6081, 0),
    "end_velocity": (0x6082, 0),
    "profile_acceleration": (0x6083, 0),
    "profile_deceleration": (0x6084, 0),
    "homing_speed_fast": (0x6099, 1),
    "homing_speed_slow": (0x6099, 2),
    "homing_method": (0x6098, 0),
    "homing_acceleration": (0x609A, 0),
    "home_offset": (0x607C, 0),
    "position_offset": (0x60B0, 0),
    "velocity_offset": (0x60B1, 0),
    "torque_offset": (0x60B2, 0),
    "interpolation_data": (0x60C1, 1),
}
#: The CiA 402 torque and current objects (a drive family whose currents are shares of something else, the CD1-k,
#: does not name them)
CIA402_TORQUE_OBJECTS: dict[str, tuple[int, int]] = {
    "velocity_demand": (0x606B, 0),
    "max_torque": (0x6072, 0),
    "max_current": (0x6073, 0),
    "rated_current": (0x6075, 0),
    "rated_torque": (0x6076, 0),
    "torque_actual": (0x6077, 0),
    "current_actual": (0x6078, 0),
}
#: The CiA 402 digital inputs and outputs (the families with an I/O description name them in their own profiles)
CIA402_IO_OBJECTS: dict[str, tuple[int, int]] = {"digital_inputs": (0x60FD, 0), "digital_outputs": (0x60FE, 1)}
#: The CiA 402 objects that set an axis moving or change how it moves: the control word, the mode, the targets
#: and offsets, the motion profile.  Only the axis's controller may write them (``services.motion``).
CIA402_MOTION_OBJECTS: frozenset[str] = frozenset(
    {
        "controlword",
        "modes_of_operation",
        "target_position",
        "target_velocity",
        "target_torque",
        "vl_target_velocity",
        "max_profile_velocity",
        "profile_velocity",
        "end_velocity",
        "profile_acceleration",
        "profile_deceleration",
        "homing_speed_fast",
        "homing_speed_slow",
        "homing_method",
        "homing_acceleration",
        "home_offset",
        "position_offset",
        "velocity_offset",
        "torque_offset",
        "interpolation_data",
    }
)


CANOPEN = "CANopen"


class EmcyLayout(enum.StrEnum):
    """How a device fills the manufacturer bytes 3..7 of its EMCY frames."""

    CODE_BYTE = "code_byte"  # byte 3 = the manufacturer error code (bit number + 1)
    BITFIELD = "bitfield"  # bytes 3..6 = the manufacturer error word (U32), bit b = code b + 1
    UNUSED = "unused"


@dataclass(frozen=True)
class Addressing:
    """The node IDs a device can take, and why (the text goes into error messages)."""

    node_ids: range = range(1, 128)
    reason: str = "CANopen node IDs are 1-127"
    #: the device also serves SDO as node n + offset: no other node on its bus may use that ID
    redirect_offset: int | None = None


@dataclass(frozen=True)
class ManualMotions:
    """Moves and homing started by control-word edges instead of CiA 402 profile position and homing mode (the
    TTA-PRO's CW12 / CW13 toggles and CW11 rising edge, docs/profibus.md §12): the bits, and the objects (semantic
    names) of the target, the speed in rpm and the homing configuration the homing "method" is written to."""

    absolute: int
    relative: int
    homing: int
    #: status bits: toggles when the drive takes a command; the position reached; the home found
    acknowledge: int
    position_reached: int
    home_found: int
    target: str = "target_position"
    speed: str = "profile_velocity"
    homing_configuration: str = "homing_configuration"


@dataclass(frozen=True)
class ProcedureAfterChange:
    """A procedure the drive needs after some of its parameters changed, before they take effect (the TTA-PRO's motor
    feedback programming, PNU 894, after its feedback selection 890-893/898): a restore that changes one of
    ``objects`` (semantic names) runs ``procedure`` (a name ``DeviceProfile.signature`` knows) right after them."""

    procedure: str
    objects: tuple[str, ...]
    #: seconds the procedure may take on the real drive, with margin
    timeout: float


class ProfileError(NotFound, KeyError):
    """The device has no object or signature of that semantic name."""

    def __str__(self) -> str:
        return str(self.args[0])


def signature_value(text: str) -> int:
    """A 4-character procedure signature as the U32 a drive expects ("save" → 0x65766173, little-endian ASCII)."""
    raw = text.encode("ascii")
    if len(raw) != 4:
        raise ValueError(f"a signature has 4 ASCII characters, not {text!r}")
    return int.from_bytes(raw, "little")


@dataclass(frozen=True)
class DeviceProfile:
    """What one drive family does differently."""

    device: str
    objects: Mapping[str, tuple[int, int]]
    #: procedure name → (semantic object name, 4-character signature)
    signatures: Mapping[str, tuple[str, str]] = field(default_factory=dict)
    #: manufacturer error words: (semantic object name, code of bit 0)
    error_words: tuple[tuple[str, int], ...] = ()
    warning_word: str | None = None
    errors: Mapping[int, FaultInfo] = field(default_factory=dict)
    warnings: Mapping[int, FaultInfo] = field(default_factory=dict)
    #: bit fields of the error words that hold one code each (not one fault per bit), e.g. the CD1-k's power fault
    coded_error_bits: tuple[CodedBits, ...] = ()
    #: EMCY error codes with a device-specific meaning
    emcy_codes: Mapping[int, FaultInfo] = field(default_factory=dict)
    #: the manual's remedy for an error code it gives no text of its own (0x603F, EMCY): shown with the CiA name
    error_code_remedy: str = ""
    #: the manufacturer code of "a procedure failed", whose cause the tool looks for in ``procedure_inputs``
    procedure_fault: int | None = None
    #: procedure trigger (semantic name) → the objects it needs non-zero and in range (semantic names)
    procedure_inputs: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    #: mode of operation (0x6060 value) → the limits that keep the axis still when they are 0 (semantic names)
    mode_limits: Mapping[int, tuple[str, ...]] = field(default_factory=dict)
    emcy_layout: EmcyLayout = EmcyLayout.UNUSED
    #: the drive refuses to store parameters unless its power stage is disabled
    save_needs_disabled: bool = False
    #: backup files and the save type of the objects each one holds
    parameter_files: Mapping[str, SaveType] = field(default_factory=lambda: {"DRIVEPAR.TXT": SaveType.DRIVEPAR})
    #: the sequence file is read through the sequence objects (XtrapulsPac)
    has_sequences: bool = False
    #: a sequence table kept in EEPROM behind a buffer, backed up in a file of its own (the TTA-PRO's)
    sequence_buffer: SequenceBuffer | None = None
    #: objects (semantic names) a restore writes before the rest of a file, in this order: those the others are
    #: scaled by or depend on (the TTA-PRO's maximum speed, position resolution and feedback selection); the rest
    #: follow in the file's order
    restore_first: tuple[str, ...] = ()
    #: procedures a restore runs after writing objects whose value it changed (the TTA-PRO's feedback programming)
    procedures_after_change: tuple[ProcedureAfterChange, ...] = ()
    addressing: Addressing = Addressing()
    #: objects (semantic names) that set the axis moving or change how it moves: the controller's alone
    motion_objects: frozenset[str] = CIA402_MOTION_OBJECTS
    #: procedures that turn the motor by themselves, even with the power stage off (phasing, auto-tuning):
    #: semantic name of the trigger object → the signature that starts it
    moving_procedures: Mapping[str, str] = field(default_factory=dict)
    #: homing methods (0x6098) the drive supports → the manual's description (``drive/profiles/homing.py``)
    homing_methods: Mapping[int, str] = field(default_factory=dict)
    #: the in-drive oscilloscope recorder (XtrapulsPac); None: the drive has none
    recorder: RecorderDescription | None = None
    #: the signature-started procedures (phasing, current loop, auto-tuning) as the procedure service runs them
    procedures: ProcedureSet = NO_PROCEDURES
    #: the speed loop's gain and filter objects and their scalings; None: the drive has no gain objects
    speed_loop: SpeedLoopDescription | None = None
    #: the logic inputs, outputs, analog I/O, encoder emulation and I/O extension (``drive/profiles/io.py``)
    io: IoDescription | None = None
    #: rad/s of one speed unit (0x606C, 0x60FF, 0x607F) and rad/s² of one acceleration unit (0x6083, 0x6084) when the
    #: drive does not count them in position units per second (encoTRive: rpm and rpm/s); None: position units
    speed_unit_rad_s: float | None = None
    acceleration_unit_rad_s2: float | None = None
    #: the fieldbus the drive speaks: CANopen (SDO, PDO, SYNC, NMT), or PROFIBUS-DP (PKW parameters and PZD control
    #: words: none of CANopen's streams, ``drive/profibus/``)
    fieldbus: str = "CANopen"
    #: procedures started by writing a number instead of a 4-character signature: name → (semantic object, value)
    procedure_values: Mapping[str, tuple[str, int]] = field(default_factory=dict)
    #: the object whose value (in A, physical) the ‰ of the current actual value 0x6078 refer to
    current_reference: str = "rated_current"
    #: bits every device-control command carries besides CiA 402's bits 0-3 and 7 (``drive.control``): the TTA-PRO's
    #: 0x0430 (control by PROFIBUS, no stop, no intermediate stop: without them it stays in local mode or stops)
    controlword_fixed: int = 0
    #: a CiA 402 command (``drive.cia402.Command`` value) → the bits 0-3 and 7 the device needs for it instead: the
    #: TTA-PRO's OFF1 outranks OFF3 (L596-599), so its quick stop keeps ON set (0x0003, still Quick stop to CiA 402)
    controlword_commands: Mapping[int, int] = field(default_factory=dict)
    #: control-word bits that jog the axis + and − at ``jog_speed`` rpm while set (the TTA-PRO's CW8 / CW9); None:
    #: the quick test jogs in CiA 402 profile velocity (``services.motion.jog``)
    jog_bits: tuple[int, int] | None = None
    #: moves and homing by control-word edges (the TTA-PRO's); None: CiA 402 profile position and homing mode
    manual_motions: ManualMotions | None = None

    @property
    def canopen(self) -> bool:
        """The drive has CANopen's PDOs, SYNC, NMT and SDO block transfers."""
        return self.fieldbus == CANOPEN

    def address(self, name: str) -> tuple[int, int]:
        try:
            return self.objects[name]
        except KeyError:
            raise ProfileError(f"{self.device}: no object '{name}' in this device profile") from None

    def has(self, name: str) -> bool:
        return name in self.objects

    def code_fault(self, code: int) -> FaultInfo | None:
        """The fault an error code (0x603F, EMCY bytes 0-1) stands for: the device's own text, else the CiA 301/402
        name with the manual's general remedy; None for code 0 (no error)."""
        if not code:
            return None
        known = self.emcy_codes.get(code)
        return known or FaultInfo(0, code, cia402_error_text(code).capitalize(), self.error_code_remedy)

    def signature(self, procedure: str) -> tuple[tuple[int, int], int]:
        """``((index, sub), value)`` to write to start a procedure such as "save"."""
        if procedure in self.procedure_values:
            object_name, value = self.procedure_values[procedure]
            return self.address(object_name), value
        try:
            object_name, text = self.signatures[procedure]
        except KeyError:
            raise ProfileError(f"{self.device}: no procedure '{procedure}' in this device profile") from None
        return self.address(object_name), signature_value(text)


def generic_profile(device: str) -> DeviceProfile:
    """Plain CiA 301 + 402: standard objects and the standard 'save' signature."""
    return DeviceProfile(
        device=device,
        objects={**CIA301_OBJECTS, **CIA402_OBJECTS, **CIA402_TORQUE_OBJECTS, **CIA402_IO_OBJECTS},
        signatures={"save": ("store_parameters", "save"), "load": ("restore_parameters", "load")},
    )
