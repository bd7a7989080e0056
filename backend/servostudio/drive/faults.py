"""Fault decoding: error words, CiA 402 error codes and EMCY frames → the manual's name and remedy.

Device tables live in the profiles (``drive/profiles``); this module holds the shapes and the CiA 301/402 generic
error-code classes used when a device table does not know a code.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping
from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class FaultInfo:
    """One fault or warning of a device: its manufacturer code (bit number + 1), CiA 402 code, name and remedy."""

    code: int
    cia402_code: int
    name: str
    remedy: str

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


@dataclass(frozen=True)
class Emergency:
    """A decoded EMCY frame."""

    node: int
    cia402_code: int
    error_register: int
    manufacturer: bytes
    faults: tuple[FaultInfo, ...]

    @property
    def cleared(self) -> bool:
        """Error code 0x0000 is sent when the drive's faults were reset."""
        return self.cia402_code == 0

    def as_dict(self) -> dict[str, object]:
        return {
            "node": self.node,
            "cia402_code": self.cia402_code,
            "cia402_text": cia402_error_text(self.cia402_code),
            "error_register": self.error_register,
            "manufacturer": self.manufacturer.hex(),
            "cleared": self.cleared,
            "faults": [fault.as_dict() for fault in self.faults],
        }


_CIA402_CLASSES = [
    (0x0000, 0x00FF, "no error / error reset"),
    (0x1000, 0x10FF, "generic error"),
    (0x2000, 0x2FFF, "current"),
    (0x3000, 0x3FFF, "voltage"),
    (0x4000, 0x4FFF, "temperature"),
    (0x5000, 0x5FFF, "device hardware"),
    (0x6000, 0x6FFF, "device software"),
    (0x7000, 0x7FFF, "additional modules"),
    (0x8000, 0x8FFF, "monitoring"),
    (0x9000, 0x9FFF, "external error"),
    (0xF000, 0xFEFF, "additional functions"),
    (0xFF00, 0xFFFF, "device specific"),
]
_CIA402_KNOWN = {
    0x2310: "continuous over current",
    0x2350: "load level fault (I²t, thermal state)",
    0x3210: "DC link overvoltage",
    0x3220: "DC link undervoltage",
    0x4210: "excess temperature device",
    0x4290: "motor temperature",
    0x5112: "supply low voltage",
    0x6320: "parameter error",
    0x7303: "resolver fault",
    0x7305: "incremental sensor fault",
    0x8130: "life guard error or heartbeat error",
    0x8400: "velocity speed controller",
    0x8611: "following error",
    0x8680: "software position limit",
}


def cia402_error_text(code: int) -> str:
    """A generic description of a CiA 301/402 error code (class, and the standard name when known)."""
    if code in _CIA402_KNOWN:
        return _CIA402_KNOWN[code]
    for low, high, text in _CIA402_CLASSES:
        if low <= code <= high:
            return text
    return "unknown error class"


@dataclass(frozen=True)
class CodedBits:
    """Bits ``first``..``last`` of an error word that hold one code rather than one fault per bit (the CD1-k's power
    fault in bits 16-18 of 0x3020): the fault of each value, 0 meaning none."""

    first: int
    last: int
    faults: Mapping[int, FaultInfo]
    #: the first code of the error word the field is in (``DeviceProfile.error_words``); None: in every word (the
    #: CD1-k has one); the TTA-PRO's code in bits 0-2 of PNU 778 is not in its PNU 773
    word: int | None = None

    @property
    def mask(self) -> int:
        return ((1 << (self.last - self.first + 1)) - 1) << self.first

    def decode(self, word: int) -> list[FaultInfo]:
        value = (word & self.mask) >> self.first
        if not value:
            return []
        code = (self.word if self.word is not None else 1) + self.first  # the code of the field's first bit
        unknown = FaultInfo(code, 0, f"coded fault {value:#b} in bits {self.first}-{self.last}", "")
        return [self.faults.get(value, unknown)]


def faults_from_words(
    table: Mapping[int, FaultInfo], words: list[tuple[int, int]], coded: tuple[CodedBits, ...] = ()
) -> list[FaultInfo]:
    """Active faults of error words given as ``(value, first_code)``: bit b of a word is code first_code + b, except
    the ``coded`` bit fields, which hold one code each."""
    active = []
    for value, first_code in words:
        fields = [field for field in coded if field.word in (None, first_code)]
        coded_mask = sum(field.mask for field in fields)
        for bit in range(32):
            if value >> bit & 1 and not coded_mask >> bit & 1:
                code = first_code + bit
                active.append(table.get(code, FaultInfo(code, 0, f"error code {code} (not in the manual)", "")))
        active.extend(fault for field in fields for fault in field.decode(value))
    return active


def unpack_emergency(data: bytes) -> tuple[int, int, bytes]:
    """``(CiA 402 error code, error register, manufacturer bytes 3..7)`` of an EMCY frame."""
    padded = bytes(data).ljust(8, b"\0")
    code, register = struct.unpack_from("<HB", padded)
    return code, register, padded[3:8]
