"""The 128 sequences of the TTA-PRO as the PKW channel sees them (TTA-PRO Profibus Communication Profile,
Chapter 3, L1870-2365): an EEPROM image reached through a buffer (PNU 782-794 and 810), PNU 780 n copying
sequence n into the buffer, PNU 781 n copying the buffer into sequence n, PNU 781 = 128 storing the checksum, and
the RAM copy that PNU 795-807 and 815 modify directly with IND = sequence number.

The checksum is the simulator's: the sum of every EEPROM field as an unsigned 32-bit number, modulo 2^32. A table
written without the final 781 = 128 fails the check at the next power-up (error 2, "EEPROM sequences checksum").
"""

from __future__ import annotations

from servostudio.sim.profibus.parameters import NOT_IN_THIS_STATE, ParameterMemory, PkwRefusal, WriteHook

SEQUENCES = 128
CHECKSUM_REQUEST = 128
BUFFER_TO_RAM = {
    782: 795,
    783: 796,
    784: 797,
    785: 798,
    786: 799,
    787: 800,
    788: 801,
    789: 802,
    790: 803,
    791: 804,
    792: 805,
    793: 806,
    794: 807,
    810: 815,
}
SPEED_PAIRS = ((784, 810), (797, 815))
"""rpm and % of PNU 721: the same speed in two forms (PNU 810 / 815 notes)."""
CONTROL_RAM = 795
VALID = 0x0001
FULL_SCALE = 32767


class SequenceTable:
    def __init__(self, memory: ParameterMemory) -> None:
        self.memory = memory
        self.eeprom = [self._buffer() for _ in range(SEQUENCES)]
        self.stored_checksum = self.checksum()
        for ram in BUFFER_TO_RAM.values():
            memory.on_write(ram, self._ram_write_guard)
        for rpm, percent in SPEED_PAIRS:
            memory.on_write(rpm, self._speed_follower(percent, to_percent=True))
            memory.on_write(percent, self._speed_follower(rpm, to_percent=False))

    def _buffer(self) -> dict[int, int]:
        return {pnu: self.memory.get(pnu) for pnu in BUFFER_TO_RAM}

    def checksum(self) -> int:
        return sum(value & 0xFFFFFFFF for record in self.eeprom for value in record.values()) & 0xFFFFFFFF

    @property
    def checksum_valid(self) -> bool:
        return self.stored_checksum == self.checksum()

    def read_into_buffer(self, number: int) -> None:
        """PNU 780."""
        for pnu, value in self.eeprom[number].items():
            self.memory.set(pnu, value)

    def write(self, number: int) -> None:
        """PNU 781: a sequence number stores the buffer, 128 stores the checksum."""
        if number == CHECKSUM_REQUEST:
            self.stored_checksum = self.checksum()
            return
        self.eeprom[number] = self._buffer()
        self._copy_to_ram(number)

    def power_up(self) -> bool:
        """The RAM copy is loaded from the EEPROM; False when the checksum does not match."""
        for number in range(SEQUENCES):
            self._copy_to_ram(number)
        return self.checksum_valid

    def _copy_to_ram(self, number: int) -> None:
        for buffer_pnu, ram_pnu in BUFFER_TO_RAM.items():
            self.memory.set(ram_pnu, self.eeprom[number][buffer_pnu], number)

    def _ram_write_guard(self, index: int, value: int) -> None:
        """A RAM modification needs a valid sequence (the notes of PNU 795-807)."""
        if not self.memory.get(CONTROL_RAM, index) & VALID:
            raise PkwRefusal(NOT_IN_THIS_STATE, f"sequence {index} is not valid")

    def _speed_follower(self, other: int, to_percent: bool) -> WriteHook:
        """A hook keeping the rpm and % forms of one speed equal."""

        def follow(index: int, value: int) -> None:
            self.memory.set(other, self._convert(value, to_percent), index)

        return follow

    def _convert(self, value: int, to_percent: bool) -> int:
        max_speed = self.memory.get(721) or 1
        if to_percent:
            return max(-FULL_SCALE, min(FULL_SCALE, round(value * FULL_SCALE / max_speed)))
        return round(value * max_speed / FULL_SCALE)
