"""CiA 301 data types and their little-endian wire encoding.

Every value that crosses the bus (SDO, PDO, drive files) goes through `encode`/`decode`, so the byte layout of a
type is defined once here. Python values: integers (and BOOLEAN, TIME_OF_DAY, TIME_DIFFERENCE) are `int`, REAL32/64
are `float`, VISIBLE_STRING and UNICODE_STRING are `str`, OCTET_STRING and DOMAIN are `bytes`.

TIME_OF_DAY / TIME_DIFFERENCE (6 bytes: 28-bit milliseconds, 4 reserved bits, 16-bit days) are represented as the
integer `days << 32 | milliseconds`, which is exactly their little-endian 48-bit layout.
"""

from __future__ import annotations

import enum
import math
import struct

from servostudio.errors import InvalidInput


class DataType(enum.IntEnum):
    """CiA 301 static data type codes (object index 0x0001–0x001B)."""

    BOOLEAN = 0x01
    INTEGER8 = 0x02
    INTEGER16 = 0x03
    INTEGER32 = 0x04
    UNSIGNED8 = 0x05
    UNSIGNED16 = 0x06
    UNSIGNED32 = 0x07
    REAL32 = 0x08
    VISIBLE_STRING = 0x09
    OCTET_STRING = 0x0A
    UNICODE_STRING = 0x0B
    TIME_OF_DAY = 0x0C
    TIME_DIFFERENCE = 0x0D
    DOMAIN = 0x0F
    INTEGER24 = 0x10
    REAL64 = 0x11
    INTEGER40 = 0x12
    INTEGER48 = 0x13
    INTEGER56 = 0x14
    INTEGER64 = 0x15
    UNSIGNED24 = 0x16
    UNSIGNED40 = 0x18
    UNSIGNED48 = 0x19
    UNSIGNED56 = 0x1A
    UNSIGNED64 = 0x1B

    @property
    def size(self) -> int | None:
        """Encoded size in bytes; None for variable-length types (strings, DOMAIN)."""
        return _SIZES.get(self)

    @property
    def fixed_size(self) -> int:
        """Encoded size in bytes of a number, BOOLEAN or TIME type, for code that has ruled out the others."""
        size = self.size
        if size is None:
            raise ValueError(f"{self.name} has no fixed size")
        return size

    @property
    def bits(self) -> int | None:
        """Width in bits as used in PDO mapping entries (BOOLEAN maps as 1 bit)."""
        if self is DataType.BOOLEAN:
            return 1
        size = self.size
        return None if size is None else size * 8

    @property
    def is_integer(self) -> bool:
        return self in _SIGNED or self in _UNSIGNED

    @property
    def is_signed(self) -> bool:
        return self in _SIGNED or self.is_float

    @property
    def is_float(self) -> bool:
        return self in (DataType.REAL32, DataType.REAL64)

    @property
    def is_numeric(self) -> bool:
        return self.is_integer or self.is_float

    @property
    def is_text(self) -> bool:
        return self in (DataType.VISIBLE_STRING, DataType.UNICODE_STRING)

    @property
    def is_binary(self) -> bool:
        return self in (DataType.OCTET_STRING, DataType.DOMAIN)

    @property
    def is_time(self) -> bool:
        return self in (DataType.TIME_OF_DAY, DataType.TIME_DIFFERENCE)

    @property
    def min_value(self) -> int | None:
        """Smallest integer value (BOOLEAN and TIME types included); None for non-integer types."""
        if self in _SIGNED:
            return -(1 << (self.fixed_size * 8 - 1))
        if self in _UNSIGNED or self.is_time:
            return 0
        return None

    @property
    def max_value(self) -> int | None:
        """Largest integer value (BOOLEAN and TIME types included); None for non-integer types."""
        if self is DataType.BOOLEAN:
            return 1
        if self in _SIGNED:
            return (1 << (self.fixed_size * 8 - 1)) - 1
        if self in _UNSIGNED or self.is_time:
            return (1 << (self.fixed_size * 8)) - 1
        return None

    @property
    def integer_range(self) -> tuple[int, int]:
        """``(min_value, max_value)`` of an integer, BOOLEAN or TIME type; ValueError for the others."""
        low, high = self.min_value, self.max_value
        if low is None or high is None:
            raise ValueError(f"{self.name} is not an integer type")
        return low, high


_SIGNED = frozenset(
    {
        DataType.INTEGER8,
        DataType.INTEGER16,
        DataType.INTEGER24,
        DataType.INTEGER32,
        DataType.INTEGER40,
        DataType.INTEGER48,
        DataType.INTEGER56,
        DataType.INTEGER64,
    }
)
_UNSIGNED = frozenset(
    {
        DataType.BOOLEAN,
        DataType.UNSIGNED8,
        DataType.UNSIGNED16,
        DataType.UNSIGNED24,
        DataType.UNSIGNED32,
        DataType.UNSIGNED40,
        DataType.UNSIGNED48,
        DataType.UNSIGNED56,
        DataType.UNSIGNED64,
    }
)
_SIZES: dict[DataType, int] = {
    DataType.BOOLEAN: 1,
    DataType.INTEGER8: 1,
    DataType.INTEGER16: 2,
    DataType.INTEGER24: 3,
    DataType.INTEGER32: 4,
    DataType.INTEGER40: 5,
    DataType.INTEGER48: 6,
    DataType.INTEGER56: 7,
    DataType.INTEGER64: 8,
    DataType.UNSIGNED8: 1,
    DataType.UNSIGNED16: 2,
    DataType.UNSIGNED24: 3,
    DataType.UNSIGNED32: 4,
    DataType.UNSIGNED40: 5,
    DataType.UNSIGNED48: 6,
    DataType.UNSIGNED56: 7,
    DataType.UNSIGNED64: 8,
    DataType.REAL32: 4,
    DataType.REAL64: 8,
    DataType.TIME_OF_DAY: 6,
    DataType.TIME_DIFFERENCE: 6,
}
_FLOAT_FORMATS = {DataType.REAL32: "<f", DataType.REAL64: "<d"}
_TIME_RESERVED_BITS = 0xF000_0000


class EncodingError(InvalidInput):
    """A value cannot be represented in (or decoded from) a CiA 301 data type."""


def encode(data_type: DataType, value: int | float | str | bytes) -> bytes:
    """Encode `value` as CANopen (little-endian) bytes of `data_type`; raises EncodingError when it does not fit."""
    data_type = DataType(data_type)
    if data_type.is_float:
        return _encode_float(data_type, value)
    if data_type.is_text:
        if not isinstance(value, str):
            raise EncodingError(f"{data_type.name} needs a str, got {type(value).__name__}")
        codec = "utf-16-le" if data_type is DataType.UNICODE_STRING else "latin-1"
        try:
            return value.encode(codec)
        except UnicodeEncodeError as exc:
            raise EncodingError(f"{data_type.name} cannot hold {value!r}: {exc.reason}") from exc
    if data_type.is_binary:
        if not isinstance(value, (bytes, bytearray)):
            raise EncodingError(f"{data_type.name} needs bytes, got {type(value).__name__}")
        return bytes(value)
    return _encode_integer(data_type, value)


def decode(data_type: DataType, raw: bytes) -> int | float | str | bytes:
    """Decode CANopen bytes of `data_type`; raises EncodingError on a wrong length."""
    data_type = DataType(data_type)
    raw = bytes(raw)
    size = data_type.size
    if size is not None and len(raw) != size:
        raise EncodingError(f"{data_type.name} needs {size} byte(s), got {len(raw)}")
    if data_type.is_float:
        return struct.unpack(_FLOAT_FORMATS[data_type], raw)[0]
    if data_type is DataType.VISIBLE_STRING:
        return raw.decode("latin-1")
    if data_type is DataType.UNICODE_STRING:
        if len(raw) % 2:
            raise EncodingError(f"UNICODE_STRING needs an even number of bytes, got {len(raw)}")
        return raw.decode("utf-16-le", errors="surrogatepass")
    if data_type.is_binary:
        return raw
    value = int.from_bytes(raw, "little", signed=data_type in _SIGNED)
    _check_integer(data_type, value)
    return value


def _encode_float(data_type: DataType, value: int | float | str | bytes) -> bytes:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise EncodingError(f"{data_type.name} needs a number, got {type(value).__name__}")
    fmt = _FLOAT_FORMATS[data_type]
    if data_type is DataType.REAL32 and math.isfinite(value) and abs(value) > 3.4028234663852886e38:
        raise EncodingError(f"{value} is outside the REAL32 range")
    try:
        return struct.pack(fmt, value)
    except (OverflowError, struct.error) as exc:
        raise EncodingError(f"{value} does not fit {data_type.name}") from exc


def _encode_integer(data_type: DataType, value: int | float | str | bytes) -> bytes:
    if isinstance(value, bool):
        value = int(value)
    if not isinstance(value, int):
        raise EncodingError(f"{data_type.name} needs an int, got {type(value).__name__}")
    _check_integer(data_type, value)
    return value.to_bytes(data_type.fixed_size, "little", signed=data_type in _SIGNED)


def _check_integer(data_type: DataType, value: int) -> None:
    low, high = data_type.integer_range
    if not low <= value <= high:
        raise EncodingError(f"{value} is outside the {data_type.name} range {low}..{high}")
    if data_type.is_time and value & _TIME_RESERVED_BITS:
        raise EncodingError(f"{data_type.name} value {value:#x} sets the reserved bits 28-31")
