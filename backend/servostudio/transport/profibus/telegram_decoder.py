"""Reading FDL telegrams back: one telegram with a precise reason when it is malformed, and a byte stream that
drops what is corrupted and resynchronises on the next telegram.

On a real line a receiver also uses the idle time between telegrams; a TCP stream or a pseudo-terminal has none,
so `TelegramDecoder.line_idle()` (called by the endpoint when no byte arrived for a while) discards a telegram whose
end never came, as the sync time does on the wire.
"""

from __future__ import annotations

from collections import deque

from servostudio.transport.profibus.telegram import (
    ADDRESS_EXTENSION,
    ADDRESS_MASK,
    ED,
    SAP_MASK,
    SC,
    SD1,
    SD2,
    SD3,
    SD4,
    Frame,
    ShortAcknowledge,
    Telegram,
    Token,
    check_sum,
)

FIXED_LENGTHS = {SC: 1, SD4: 3, SD1: 6, SD3: 14}
SD2_HEADER = 4
"""SD2 LE LEr SD2: the length is known once these four bytes are in."""
SD2_LENGTHS = range(4, 250)
FURTHER_EXTENSION = 0x80
SEGMENT_EXTENSION = 0x40
REASONS_KEPT = 100


class TelegramError(ValueError):
    """A byte sequence is not a well-formed telegram; the message says what is wrong."""


def telegram_length(data: bytes | bytearray) -> int | None:
    """Length of the telegram starting at data[0]; None until enough header bytes are in. Raises TelegramError
    for an unknown start delimiter or an impossible SD2 length."""
    if not data:
        return None
    delimiter = data[0]
    if delimiter in FIXED_LENGTHS:
        return FIXED_LENGTHS[delimiter]
    if delimiter != SD2:
        raise TelegramError(f"unknown start delimiter 0x{delimiter:02X}")
    if len(data) < SD2_HEADER:
        return None
    return _sd2_length(data)


def _sd2_length(data: bytes | bytearray) -> int:
    length, repeated = data[1], data[2]
    if length != repeated:
        raise TelegramError(f"SD2 length LE 0x{length:02X} differs from its repetition LEr 0x{repeated:02X}")
    if length not in SD2_LENGTHS:
        raise TelegramError(f"SD2 length LE {length} is outside 4..249")
    if data[3] != SD2:
        raise TelegramError(f"SD2 start delimiter is repeated as 0x{data[3]:02X}")
    return length + 6


def decode_telegram(data: bytes | bytearray) -> Frame:
    """Exactly one telegram; TelegramError names the first rule it breaks."""
    expected = telegram_length(data)
    if expected is None or len(data) != expected:
        raise TelegramError(f"telegram of {len(data)} bytes, its delimiter 0x{data[0]:02X} needs {expected or 'more'}")
    delimiter = data[0]
    if delimiter == SC:
        return ShortAcknowledge()
    if delimiter == SD4:
        return Token(data[1] & ADDRESS_MASK, data[2] & ADDRESS_MASK)
    body = data[4:-2] if delimiter == SD2 else data[1:-2]
    _check_trailer(data, body)
    return _telegram(bytes(body))


def _check_trailer(data: bytes | bytearray, body: bytes | bytearray) -> None:
    if data[-1] != ED:
        raise TelegramError(f"end delimiter 0x{data[-1]:02X}, expected 0x{ED:02X}")
    computed = check_sum(body)
    if data[-2] != computed:
        raise TelegramError(f"FCS 0x{data[-2]:02X} does not match the computed 0x{computed:02X}")


def _telegram(body: bytes) -> Telegram:
    destination, source, function, unit = body[0], body[1], body[2], body[3:]
    destination_sap, unit = _extension(unit, destination, "destination")
    source_sap, unit = _extension(unit, source, "source")
    return Telegram(destination & ADDRESS_MASK, source & ADDRESS_MASK, function, unit, destination_sap, source_sap)


def _extension(unit: bytes, address: int, which: str) -> tuple[int | None, bytes]:
    """The SAP byte an address with bit 7 announces (DP uses exactly one, without a segment address)."""
    if not address & ADDRESS_EXTENSION:
        return None, unit
    if not unit:
        raise TelegramError(f"{which} address announces an extension the data unit does not hold")
    if unit[0] & (FURTHER_EXTENSION | SEGMENT_EXTENSION):
        raise TelegramError(f"{which} address extension 0x{unit[0]:02X} chains or names a segment (DP uses one SAP)")
    return unit[0] & SAP_MASK, unit[1:]


class TelegramDecoder:
    """Bytes in, telegrams out. A byte that does not start a valid telegram is dropped with its reason and the
    scan goes on at the next byte, so one corrupted telegram costs that telegram only."""

    def __init__(self) -> None:
        self._buffer = bytearray()
        self.dropped_bytes = 0
        self.rejected: deque[str] = deque(maxlen=REASONS_KEPT)
        """The latest reasons for dropping bytes, oldest first."""

    @property
    def pending(self) -> int:
        """Bytes of a telegram still waiting for its end."""
        return len(self._buffer)

    def feed(self, data: bytes) -> list[Frame]:
        self._buffer += data
        frames: list[Frame] = []
        while self._buffer:
            try:
                length = telegram_length(self._buffer)
            except TelegramError as error:
                self._drop(1, str(error))
                continue
            if length is None or len(self._buffer) < length:
                break
            frame = self._take(length)
            if frame is not None:
                frames.append(frame)
        return frames

    def line_idle(self) -> None:
        """The line stayed quiet: a telegram that started and never ended is dropped."""
        if self._buffer:
            self._drop(len(self._buffer), f"incomplete telegram of {len(self._buffer)} bytes discarded on line idle")

    def _take(self, length: int) -> Frame | None:
        """The complete telegram at the buffer start, or None when it is malformed (its first byte is dropped)."""
        try:
            frame = decode_telegram(self._buffer[:length])
        except TelegramError as error:
            self._drop(1, str(error))
            return None
        del self._buffer[:length]
        return frame

    def _drop(self, count: int, reason: str) -> None:
        del self._buffer[:count]
        self.dropped_bytes += count
        self.rejected.append(reason)
