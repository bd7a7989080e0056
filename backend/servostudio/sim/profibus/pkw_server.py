"""The slave side of the PKW mailbox (TTA-PRO Profibus Communication Profile, Chapter 1 §3, L269-395).

Every Data_Exchange brings the master's 8 PKW bytes; the drive serves a request once, in its next positioner cycle
(1 ms), when the bytes differ from the request it last served, and presents the reply until the next instruction.
So a master repeating its request until the reply comes never has it executed twice, and the same procedure twice
in a row needs a PKE = 0 instruction in between, as the manual requires. AK 0 is answered with an all-zero reply.
A procedure's reply shows PWE 0 while it runs, then 1 or 2. A double word value is answered with AK 1, as printed
(L311-318); `double_reply_ak=2` gives the PROFIdrive code instead.
"""

from __future__ import annotations

import struct

from servostudio.od.pnu_model import Parameter
from servostudio.sim.profibus.parameters import OTHER_ERROR, ParameterMemory, PkwRefusal, check_range, is_signed
from servostudio.sim.profibus.procedures import ProcedureRunner

LAYOUT = struct.Struct(">HBxI")
NO_REQUEST = bytes(LAYOUT.size)
READ = 1
WRITE_WORD = 2
WRITE_DOUBLE = 3
VALUE = 1
REFUSED = 7


def pke(ak: int, pnu: int) -> int:
    return ak << 12 | pnu


class PkwServer:
    def __init__(self, memory: ParameterMemory, procedures: ProcedureRunner, double_reply_ak: int = VALUE) -> None:
        self.memory = memory
        self.procedures = procedures
        self.double_reply_ak = double_reply_ak
        self._latest = NO_REQUEST
        self._served: bytes | None = None
        self._reply = NO_REQUEST
        self._procedure: tuple[int, int] | None = None  # (pnu, index) whose progress the reply shows

    @property
    def reply(self) -> bytes:
        return self._reply

    def receive(self, request: bytes) -> None:
        """The PKW bytes of the latest Data_Exchange."""
        self._latest = bytes(request)

    def cycle(self) -> None:
        """One positioner cycle: serve a new request, or refresh a running procedure's progress."""
        if self._latest != self._served:
            self._serve(self._latest)
        elif self._procedure is not None:
            pnu, index = self._procedure
            self._reply = LAYOUT.pack(pke(VALUE, pnu), index, self.procedures.status(pnu))

    def _serve(self, request: bytes) -> None:
        self._served = request
        self._procedure = None
        word, index, pwe = LAYOUT.unpack(request)
        ak, pnu = word >> 12, word & 0x07FF
        if ak == 0:
            self._reply = NO_REQUEST
            return
        try:
            self._reply = self._answer(ak, pnu, index, pwe)
        except PkwRefusal as refusal:
            self._reply = LAYOUT.pack(pke(REFUSED, pnu), index, refusal.error)

    def _answer(self, ak: int, pnu: int, index: int, pwe: int) -> bytes:
        if ak == READ:
            return self._value_reply(pnu, index, self.memory.read(pnu, index))
        if ak not in (WRITE_WORD, WRITE_DOUBLE):
            raise PkwRefusal(OTHER_ERROR, f"AK {ak} is not an instruction")
        parameter = self.memory.parameter(pnu, index)
        value = pwe_value(parameter, pwe, ak == WRITE_DOUBLE)
        if parameter.procedure:
            return self._start(parameter, index, value, ak == WRITE_DOUBLE)
        self.memory.write(pnu, index, value, ak == WRITE_DOUBLE)
        return self._value_reply(pnu, index, self.memory.get(pnu, index))

    def _start(self, parameter: Parameter, index: int, value: int, double: bool) -> bytes:
        if parameter.is_double != double:
            raise PkwRefusal(5, f"PNU {parameter.pnu} is a {'double word' if parameter.is_double else 'word'}")
        check_range(parameter, value)
        self.procedures.start(parameter.pnu, value)
        self._procedure = (parameter.pnu, index)
        return LAYOUT.pack(pke(VALUE, parameter.pnu), index, self.procedures.status(parameter.pnu))

    def _value_reply(self, pnu: int, index: int, value: int) -> bytes:
        parameter = self.memory.parameters[pnu]
        ak = self.double_reply_ak if parameter.is_double else VALUE
        bits = 32 if parameter.is_double else 16
        return LAYOUT.pack(pke(ak, pnu), index, value & ((1 << bits) - 1))


def pwe_value(parameter: Parameter, pwe: int, double: bool) -> int:
    """PWE as the parameter's value: a word from bytes 7-8 only, signed PNUs in two's complement of their width."""
    bits = 32 if double else 16
    raw = pwe & ((1 << bits) - 1)
    if is_signed(parameter) and raw >= 1 << (bits - 1):
        return raw - (1 << bits)
    return raw
