"""The one frame type the simulator passes around (kept independent of python-can, which only the adapters use)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Frame:
    """A classical CAN frame. For a remote frame (`rtr`), `data` is `dlc` zero bytes and is not sent on the wire."""

    can_id: int
    data: bytes = b""
    rtr: bool = False
    extended: bool = False

    def __post_init__(self) -> None:
        limit = 0x1FFFFFFF if self.extended else 0x7FF
        if not 0 <= self.can_id <= limit:
            raise ValueError(f"CAN identifier {self.can_id:#x} does not fit {'29' if self.extended else '11'} bits")
        if len(self.data) > 8:
            raise ValueError(f"a classical CAN frame carries at most 8 bytes, got {len(self.data)}")

    @property
    def dlc(self) -> int:
        return len(self.data)

    @classmethod
    def remote(cls, can_id: int, dlc: int = 0) -> Frame:
        return cls(can_id, bytes(dlc), rtr=True)
