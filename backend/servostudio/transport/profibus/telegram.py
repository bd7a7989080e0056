"""FDL telegrams and their encoding (IEC 61158-4-3 / EN 50170 vol. 2, the PROFIBUS data link layer).

| delimiter | bytes |
|---|---|
| SD1 0x10 | SD1 DA SA FC FCS ED: no data unit |
| SD2 0x68 | SD2 LE LEr SD2 DA SA FC DU… FCS ED: LE = 3 + len(DU), 4..249 |
| SD3 0xA2 | SD3 DA SA FC DU(8) FCS ED: exactly 8 data-unit bytes |
| SD4 0xDC | SD4 DA SA: token, no check sum |
| SC 0xE5 | short acknowledge |

FCS is the sum of DA..DU modulo 256; ED = 0x16. Bit 7 of DA (SA) says that the data unit starts with a
destination (source) address extension, which DP uses for the service access point (SAP) of the service.
`Telegram` chooses SD1, SD3 or SD2 from the length of its data unit, as DP masters do.
"""

from __future__ import annotations

from dataclasses import dataclass

SD1 = 0x10
SD2 = 0x68
SD3 = 0xA2
SD4 = 0xDC
SC = 0xE5
ED = 0x16
ADDRESS_EXTENSION = 0x80
ADDRESS_MASK = 0x7F
BROADCAST = 127
SAP_MASK = 0x3F
FIXED_UNIT = 8
"""SD3 carries exactly this many data-unit bytes (address extensions included)."""
MAX_UNIT = 246
"""SD2: LE ≤ 249 = 3 + 246."""


@dataclass(frozen=True)
class Telegram:
    """An SD1/SD2/SD3 telegram: addresses 0..127, frame control, optional SAPs, the data after them."""

    destination: int
    source: int
    function: int
    data: bytes = b""
    destination_sap: int | None = None
    source_sap: int | None = None

    def __post_init__(self) -> None:
        for name in ("destination", "source"):
            if not 0 <= getattr(self, name) <= ADDRESS_MASK:
                raise ValueError(f"{name} address {getattr(self, name)} is outside 0..127")
        for name in ("destination_sap", "source_sap"):
            sap = getattr(self, name)
            if sap is not None and not 0 <= sap <= SAP_MASK:
                raise ValueError(f"{name} {sap} is outside 0..63")
        if not 0 <= self.function <= 0xFF:
            raise ValueError(f"frame control {self.function} is not a byte")
        if len(self.unit) > MAX_UNIT:
            raise ValueError(f"a data unit holds at most {MAX_UNIT} bytes, got {len(self.unit)}")

    @property
    def unit(self) -> bytes:
        """The data unit on the wire: address extension bytes, then the data."""
        extensions = bytes(sap for sap in (self.destination_sap, self.source_sap) if sap is not None)
        return extensions + bytes(self.data)

    @property
    def delimiter(self) -> int:
        length = len(self.unit)
        if length == 0:
            return SD1
        return SD3 if length == FIXED_UNIT else SD2


@dataclass(frozen=True)
class Token:
    """SD4: the token passed between masters (a slave ignores it)."""

    destination: int
    source: int


@dataclass(frozen=True)
class ShortAcknowledge:
    """SC: a slave's positive acknowledge without data (Set_Prm, Chk_Cfg)."""


Frame = Telegram | Token | ShortAcknowledge


def check_sum(body: bytes | bytearray) -> int:
    """FCS: arithmetic sum of DA, SA, FC and the data unit, modulo 256."""
    return sum(body) & 0xFF


def encode(frame: Frame) -> bytes:
    """The bytes of one telegram on the line."""
    if isinstance(frame, ShortAcknowledge):
        return bytes((SC,))
    if isinstance(frame, Token):
        return bytes((SD4, frame.destination, frame.source))
    return _encode_telegram(frame)


def _encode_telegram(telegram: Telegram) -> bytes:
    destination = telegram.destination | (ADDRESS_EXTENSION if telegram.destination_sap is not None else 0)
    source = telegram.source | (ADDRESS_EXTENSION if telegram.source_sap is not None else 0)
    body = bytes((destination, source, telegram.function)) + telegram.unit
    trailer = bytes((check_sum(body), ED))
    delimiter = telegram.delimiter
    if delimiter == SD2:
        length = len(body)
        return bytes((SD2, length, length, SD2)) + body + trailer
    return bytes((delimiter,)) + body + trailer
