"""The master-side PKW codec and handshake (TTA-PRO Profibus Communication Profile, Chapter 1 §3, L269-395)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.drive.profibus.pkw import (
    IDLE,
    Instruction,
    PkwMessage,
    Reply,
    from_pwe,
    read_request,
    to_pwe,
    write_request,
)
from servostudio.drive.profibus.pkw_errors import PkwInhibited, PkwRefused, ProcedureFailed
from servostudio.drive.profibus.pkw_handshake import PkwChannel, reply_value

messages = st.builds(
    PkwMessage, st.integers(0, 15), st.integers(0, 0x7FF), st.integers(0, 255), st.integers(0, 2**32 - 1), st.booleans()
)


def test_the_manuals_examples_have_its_bytes() -> None:
    speed = write_request(797, 1000, double=False, index=2)  # sequence 2 speed := 1000 rpm
    assert speed.pke == 0x231D and speed.encode() == bytes.fromhex("23 1D 02 00 00 00 03 E8")
    position = write_request(796, 200, double=True, index=5)  # sequence 5 position := 200
    assert position.pke == 0x331C and position.encode() == bytes.fromhex("33 1C 05 00 00 00 00 C8")


@given(messages)
def test_a_pkw_module_reads_back(message: PkwMessage) -> None:
    assert PkwMessage.decode(message.encode()) == message


@given(st.booleans(), st.booleans(), st.data())
def test_values_travel_in_their_width(double: bool, signed: bool, data) -> None:
    bits = 32 if double else 16
    low, high = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    value = data.draw(st.integers(low, high))
    pwe = to_pwe(value, double)
    assert pwe < 1 << bits
    assert from_pwe(pwe, double, signed) == value


def test_a_word_comes_from_bytes_7_and_8_only() -> None:
    assert from_pwe(0xABCD1234, double=False, signed=False) == 0x1234
    with pytest.raises(ValueError, match="does not fit a word"):
        to_pwe(70000, double=False)


def test_refusals_are_readable_and_name_the_parameter() -> None:
    request = read_request(795, index=5)
    with pytest.raises(PkwRefused, match=r"^PNU 795\[5\]: index error \(PKW error 3\)$"):
        reply_value(request, PkwMessage(Reply.REFUSED, 795, 5, 3), double=False, signed=False)
    with pytest.raises(PkwRefused, match=r"^PNU 700: lower or upper limit exceeded \(PKW error 2\)$"):
        reply_value(read_request(700), PkwMessage(Reply.REFUSED, 700, 0, 2), double=False, signed=False)
    with pytest.raises(PkwInhibited, match="PNU 700: PKW interface inhibited"):
        reply_value(read_request(700), PkwMessage(Reply.INHIBITED, 700), double=False, signed=False)
    with pytest.raises(ProcedureFailed, match="PNU 729: procedure ended with an error"):
        reply_value(
            write_request(729, 0, False), PkwMessage(Reply.VALUE, 729, 0, 2), double=False, signed=False, procedure=True
        )


class Slave:
    """A scripted slave: serves a request one cycle after it first sees it, then keeps the reply."""

    def __init__(self, procedure_cycles: int = 0) -> None:
        self.reply = PkwMessage(Reply.VALUE, 721, 0, 4000)  # a stale reply from before the master came
        self.seen: PkwMessage | None = None
        self.procedure_cycles = procedure_cycles
        self.served = 0

    def exchange(self, request: PkwMessage) -> PkwMessage:
        reply = self.reply
        if request != self.seen:
            self.seen = request
            self.served += request.ak != Instruction.NONE
            self.reply = IDLE if request.ak == Instruction.NONE else self._answer(request)
        elif self.procedure_cycles and self.reply.value == 0:
            self.procedure_cycles -= 1
            if not self.procedure_cycles:
                self.reply = PkwMessage(Reply.VALUE, request.pnu, 0, 1)
        return reply

    def _answer(self, request: PkwMessage) -> PkwMessage:
        if self.procedure_cycles:
            return PkwMessage(Reply.VALUE, request.pnu, request.index, 0)
        return PkwMessage(
            Reply.VALUE, request.pnu, request.index, 4000 if request.ak == Instruction.READ else request.value
        )


def run(channel: PkwChannel, slave: Slave, cycles: int = 30) -> tuple[PkwMessage, int]:
    for cycle in range(cycles):
        reply = channel.receive(slave.exchange(channel.output()))
        if reply is not None:
            return reply, cycle
    raise AssertionError("no reply")


def test_the_channel_separates_before_its_first_request_so_a_stale_reply_does_not_count() -> None:
    channel, slave = PkwChannel(), Slave()
    channel.submit(read_request(721))
    reply, cycles = run(channel, slave)
    assert reply == PkwMessage(Reply.VALUE, 721, 0, 4000)
    assert cycles >= 2 and slave.served == 1


def test_two_identical_reads_are_two_transactions() -> None:
    channel, slave = PkwChannel(), Slave()
    for _ in range(2):
        channel.submit(read_request(721))
        run(channel, slave)
    assert slave.served == 2


def test_a_running_procedure_keeps_its_request_on_the_bus() -> None:
    channel, slave = PkwChannel(), Slave(procedure_cycles=5)
    request = write_request(729, 0, double=False)
    channel.submit(request, procedure=True)
    reply, _ = run(channel, slave)
    assert reply.value == 1 and slave.served == 1
    assert reply_value(request, reply, double=False, signed=False, procedure=True) == 1


def test_one_request_at_a_time() -> None:
    channel = PkwChannel()
    channel.submit(read_request(700))
    with pytest.raises(RuntimeError, match="one request at a time"):
        channel.submit(read_request(701))
