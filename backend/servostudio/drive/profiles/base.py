"""The shape of a device profile and the CiA 301/402 objects every profile starts from."""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field

from servostudio.drive.faults import FaultInfo
from servostudio.errors import NotFound
from servostudio.od.model import SaveType

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
}


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
    #: EMCY error codes with a device-specific meaning
    emcy_codes: Mapping[int, FaultInfo] = field(default_factory=dict)
    emcy_layout: EmcyLayout = EmcyLayout.UNUSED
    #: the drive refuses to store parameters unless its power stage is disabled
    save_needs_disabled: bool = False
    #: backup files and the save type of the objects each one holds
    parameter_files: Mapping[str, SaveType] = field(default_factory=lambda: {"DRIVEPAR.TXT": SaveType.DRIVEPAR})
    #: the sequence file is read through the sequence objects (XtrapulsPac)
    has_sequences: bool = False
    addressing: Addressing = Addressing()

    def address(self, name: str) -> tuple[int, int]:
        try:
            return self.objects[name]
        except KeyError:
            raise ProfileError(f"{self.device}: no object '{name}' in this device profile") from None

    def has(self, name: str) -> bool:
        return name in self.objects

    def signature(self, procedure: str) -> tuple[tuple[int, int], int]:
        """``((index, sub), value)`` to write to start a procedure such as "save"."""
        try:
            object_name, text = self.signatures[procedure]
        except KeyError:
            raise ProfileError(f"{self.device}: no procedure '{procedure}' in this device profile") from None
        return self.address(object_name), signature_value(text)


def generic_profile(device: str) -> DeviceProfile:
    """Plain CiA 301 + 402: standard objects and the standard 'save' signature."""
    return DeviceProfile(
        device=device,
        objects={**CIA301_OBJECTS, **CIA402_OBJECTS},
        signatures={"save": ("store_parameters", "save"), "load": ("restore_parameters", "load")},
    )
