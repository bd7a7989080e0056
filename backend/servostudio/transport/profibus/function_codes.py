"""The FDL frame control byte (FC): request or response, function, frame count bit (FCB) and its valid flag (FCV).

A master sets bit 6 (request) and a request function in bits 0..3; with FCV set, an unchanged FCB tells the
station the request is a repetition, which it answers with its previous response instead of executing again.
"""

from __future__ import annotations

REQUEST = 0x40
FRAME_COUNT_BIT = 0x20
FRAME_COUNT_VALID = 0x10
FUNCTION_MASK = 0x0F
STATION_TYPE_MASK = 0x30

# request functions (REQUEST set)
SDA_LOW = 0x03
SDN_LOW = 0x04
SDA_HIGH = 0x05
SDN_HIGH = 0x06
FDL_STATUS = 0x09
SRD_LOW = 0x0C
SRD_HIGH = 0x0D
IDENT = 0x0E
LSAP_STATUS = 0x0F

# response functions (REQUEST clear); bits 4..5 are the station type, 0 = slave
OK = 0x00
USER_ERROR = 0x01
NO_RESOURCE = 0x02
NO_SERVICE = 0x03
DATA_LOW = 0x08
NO_RESPONSE = 0x09
DATA_HIGH = 0x0A


def is_request(function_code: int) -> bool:
    return bool(function_code & REQUEST)


def function_of(function_code: int) -> int:
    return function_code & FUNCTION_MASK


def frame_count_bit(function_code: int) -> int:
    return 1 if function_code & FRAME_COUNT_BIT else 0


def frame_count_valid(function_code: int) -> bool:
    """FCV clear: the station takes the request as new whatever its FCB (the master's first request after a reset)."""
    return bool(function_code & FRAME_COUNT_VALID)


def request_code(function: int, frame_count_bit: int | None = None) -> int:
    """FC of a request; `frame_count_bit` 0/1 sets FCV and FCB, None leaves both clear."""
    code = REQUEST | function
    if frame_count_bit is not None:
        code |= FRAME_COUNT_VALID | (FRAME_COUNT_BIT if frame_count_bit else 0)
    return code
