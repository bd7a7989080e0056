"""The 12-byte frame codec of the XtrapulsPac RS-232 link (decisions.md §1).

One CAN data frame travels as ``header, 0x80|cob_id>>8, cob_id&0xFF, 8 data bytes, XOR(bytes 1..10)``.
The host sends ``'M'`` frames, the drive answers with ``'S'`` frames.  There is no acknowledge, so a
receiver must find frame boundaries on its own: :class:`FrameDecoder` scans for a header byte whose
12-byte candidate carries a valid XOR and a well-formed identifier byte, and skips one byte at a time
otherwise.  This module is the single definition of the wire format (the simulator imports it too).
"""

from __future__ import annotations

HOST_HEADER = 0x4D  # 'M', host -> drive
DRIVE_HEADER = 0x53  # 'S', drive -> host
FRAME_LENGTH = 12
DATA_LENGTH = 8
MAX_COB_ID = 0x7FF
_ID_FLAG = 0x80


def _checksum(body: bytes | bytearray) -> int:
    """XOR of the identifier and data bytes (frame bytes 1..10)."""
    value = 0
    for byte in body:
        value ^= byte
    return value


def encode_frame(header: int, cob_id: int, data: bytes) -> bytes:
    """Build one frame; ``data`` (at most 8 bytes) is padded with zeros to 8 bytes."""
    if header not in (HOST_HEADER, DRIVE_HEADER):
        raise ValueError(f"frame header must be 0x4D ('M') or 0x53 ('S'), not {header:#x}")
    if not 0 <= cob_id <= MAX_COB_ID:
        raise ValueError(f"COB-ID {cob_id:#x} is not an 11-bit identifier")
    if len(data) > DATA_LENGTH:
        raise ValueError(f"a CAN frame carries at most 8 data bytes, got {len(data)}")
    body = bytes((_ID_FLAG | (cob_id >> 8), cob_id & 0xFF)) + bytes(data).ljust(DATA_LENGTH, b"\0")
    return bytes((header,)) + body + bytes((_checksum(body),))


def _valid_frame(candidate: bytes | bytearray) -> bool:
    """A candidate is a frame when its identifier byte is well-formed and the XOR matches."""
    id_high = candidate[1]
    return id_high & 0xF8 == _ID_FLAG and _checksum(candidate[1:11]) == candidate[11]


class FrameDecoder:
    """Turns a byte stream into frames, resynchronising after garbage or corruption.

    Bytes that cannot start a valid frame are dropped one at a time (counted in :attr:`dropped_bytes`);
    an incomplete tail is kept for the next :meth:`feed`.
    """

    def __init__(self, header: int) -> None:
        if header not in (HOST_HEADER, DRIVE_HEADER):
            raise ValueError(f"frame header must be 0x4D ('M') or 0x53 ('S'), not {header:#x}")
        self.header = header
        self.dropped_bytes = 0
        self._buffer = bytearray()

    def feed(self, chunk: bytes) -> list[tuple[int, bytes]]:
        """Add received bytes; return the complete valid frames as ``(cob_id, 8 data bytes)``."""
        self._buffer += chunk
        frames: list[tuple[int, bytes]] = []
        buffer = self._buffer
        start = 0
        while len(buffer) - start >= FRAME_LENGTH:
            if buffer[start] == self.header and _valid_frame(buffer[start : start + FRAME_LENGTH]):
                cob_id = ((buffer[start + 1] & 0x07) << 8) | buffer[start + 2]
                frames.append((cob_id, bytes(buffer[start + 3 : start + 11])))
                start += FRAME_LENGTH
                continue
            next_header = buffer.find(self.header, start + 1)
            stop = next_header if next_header != -1 else len(buffer)
            self.dropped_bytes += stop - start
            start = stop
        del buffer[:start]
        if buffer and buffer[0] != self.header:
            next_header = buffer.find(self.header)
            stop = next_header if next_header != -1 else len(buffer)
            self.dropped_bytes += stop
            del buffer[:stop]
        return frames

    @property
    def bytes_wanted(self) -> int:
        """How many more bytes complete the frame being received (a reader can ask for exactly that many)."""
        return FRAME_LENGTH - len(self._buffer) if self._buffer else FRAME_LENGTH
