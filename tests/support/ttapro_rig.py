"""The TTA-PRO rig: a simulated TTA-PRO driven in virtual time, PPO2 images straight into the slave, one positioner
cycle per exchange, without the FDL layer; its PKW instructions and the PZD control word that enables it."""

from __future__ import annotations

import struct
from collections.abc import Callable

from servostudio.od.pnu_model import ParameterDictionary
from servostudio.sim.plant import Plant
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.slave import TtaProSlave
from servostudio.transport.profibus.ppo import PPO2

ADDRESS = 5
CYCLE = 0.001
ENABLED = 0x043F


def request(ak: int, pnu: int, value: int = 0, index: int = 0) -> bytes:
    """A PKW instruction: PKE (AK, PNU), IND, reserved byte, PWE, big-endian."""
    return struct.pack(">HBxI", ak << 12 | pnu, index, value & 0xFFFFFFFF)


class Rig:
    def __init__(self, parameters: ParameterDictionary, plant: Plant | None = None, double_reply_ak: int = 1) -> None:
        self.slave = TtaProSlave(ADDRESS, parameters, plant or Plant.commissioned(), double_reply_ak)
        self.line = ProfibusLine([self.slave])
        assert self.slave.check_config(PPO2.identifiers)
        self.pzd = [0] * 6
        self.pkw_reply = (0, 0, 0, 0)
        self.words = [0] * 6

    @property
    def drive(self):
        return self.slave.drive

    def cycle(self, request: bytes = bytes(8), cycles: int = 1) -> list[int]:
        for _ in range(cycles):
            self.slave.apply_outputs(request + struct.pack(">6H", *(word & 0xFFFF for word in self.pzd)))
            self.line.advance(CYCLE)
            inputs = self.slave.read_inputs()
            pke, index, value = struct.unpack(">HBxI", inputs[:8])
            self.pkw_reply = (pke >> 12, pke & 0x7FF, index, value)
            self.words = list(struct.unpack(">6H", inputs[8:]))
        return self.words

    def transaction(self, ak: int, pnu: int, value: int = 0, index: int = 0) -> tuple[int, int, int, int]:
        """Separate with AK 0, then hold the request until its reply."""
        self.cycle(cycles=2)
        instruction = request(ak, pnu, value, index)
        for _ in range(50):
            self.cycle(instruction)
            if self.pkw_reply[0] and self.pkw_reply[1] == pnu:
                return self.pkw_reply
        raise AssertionError(f"no reply for PNU {pnu}")

    def run_procedure(self, pnu: int, value: int = 0, cycles: int = 200) -> int:
        """Start a procedure and hold its request until PWE leaves 0 (running); that final PWE."""
        self.transaction(2, pnu, value)
        for _ in range(cycles):
            if self.pkw_reply[3] != 0:
                return self.pkw_reply[3]
            self.cycle(request(2, pnu, value))
        raise AssertionError(f"procedure PNU {pnu} still running")

    def write(self, pnu: int, value: int, index: int = 0) -> tuple[int, int, int, int]:
        double = self.slave.memory.parameters[pnu].is_double
        return self.transaction(3 if double else 2, pnu, value, index)

    def read(self, pnu: int, index: int = 0) -> int:
        reply = self.transaction(1, pnu, index=index)
        assert reply[0] == 1, reply
        return reply[3]

    def control(self, word: int, cycles: int = 3) -> int:
        self.pzd[0] = word
        return self.cycle(cycles=cycles)[0]

    def enable(self) -> int:
        for word in (0x0400, 0x0406, 0x0407):
            self.control(word)
        return self.control(ENABLED, cycles=5)

    def run_until(self, condition: Callable[[], bool], seconds: float) -> None:
        for _ in range(round(seconds / CYCLE)):
            self.cycle()
            if condition():
                return
        raise AssertionError(f"condition not met within {seconds} s")

    def command_position(self, increments: int) -> None:
        """PZD5-6 of the PPO write: the position set point of the default command mapping (it overrides PNU 767)."""
        self.pzd[4:6] = struct.unpack(">2H", struct.pack(">i", increments))

    def position(self) -> int:
        """Motor position from PZD5-6 (default feedback mapping)."""
        return struct.unpack(">i", struct.pack(">2H", *self.words[4:6]))[0]
