"""The TTA-PRO's PPO seen as a request/response API: PNU reads and writes through the PKW handshake, the control
word out and the status word in through PZD, all riding the cyclic Data_Exchange of a DP master
(`servostudio.transport.profibus.interface.DpLine`: pyprofibus's DPM1 or the project's own; docs/profibus.md §7).

`read`/`write` block until their reply, like an SDO upload/download; a reply that does not come in time, or a link
lost meanwhile, abandons the request (AK 0 goes out, so a late reply cannot answer the next one) and raises.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from servostudio.drive.profibus.pkw import PkwMessage, read_request, write_request
from servostudio.drive.profibus.pkw_handshake import PkwChannel, reply_value
from servostudio.drive.profibus.pzd import pack_words, unpack_words
from servostudio.errors import ServoStudioError, Timeout, Unavailable
from servostudio.transport.profibus.cyclic import PERIOD, WATCHDOG
from servostudio.transport.profibus.interface import DataExchange, DpLine
from servostudio.transport.profibus.ppo import PKW_WORDS, PPO2, WORD_BYTES, Ppo

PKW_TIMEOUT = 1.0
"""Seconds a parameter reply may take (a save to EEPROM is a procedure and polls longer: `procedure_timeout`)."""
PROCEDURE_TIMEOUT = 5.0
PKW_BYTES = PKW_WORDS * WORD_BYTES


class PkwTimeout(Timeout, TimeoutError):
    """The drive did not reply to a parameter request in time."""


class ProfibusLinkDown(Unavailable, ConnectionError):
    """The slave is not in data exchange (not answering, or refusing the parameterisation)."""


class TtaProClient:
    """One TTA-PRO in data exchange with this master."""

    def __init__(
        self, master: DpLine, address: int, ppo: Ppo = PPO2, period: float = PERIOD, watchdog: float | None = WATCHDOG
    ) -> None:
        if not ppo.has_pkw:
            raise ValueError(f"{ppo.name} has no PKW channel: the tool needs PPO1 or PPO2")
        self.address = address
        self.ppo = ppo
        self._condition = threading.Condition()
        self._channel = PkwChannel()
        self._reply: PkwMessage | None = None
        self._outputs = [0] * ppo.pzd_words
        self._inputs: tuple[int, ...] = (0,) * ppo.pzd_words
        self._link_error: ServoStudioError | None = None
        self._sent = 0  # output images composed so far
        self._answered = 0  # the output image the latest input image answered
        self._on_status: Callable[[int], None] | None = None
        self.exchange: DataExchange = master.exchange(
            address, ppo, self._output_image, self._input_image, self._on_link, period, watchdog
        )

    def start(self) -> TtaProClient:
        self.exchange.start()
        return self

    def close(self) -> None:
        self.exchange.stop()

    # -- process data -----------------------------------------------------------------------------------------

    def on_status_word(self, listener: Callable[[int], None]) -> None:
        """Call ``listener(status_word)`` on the exchange's thread whenever the status word (PZD1 in) changes; it
        must not block (an event hub's publish)."""
        self._on_status = listener

    @property
    def status_word(self) -> int:
        with self._condition:
            return self._inputs[0]

    @property
    def inputs(self) -> tuple[int, ...]:
        """PZD1.. of the latest input image."""
        with self._condition:
            return self._inputs

    def set_output(self, word: int, value: int) -> None:
        """PZD `word` (0 = STW) of every following output image."""
        with self._condition:
            self._outputs[word] = value & 0xFFFF

    def output(self, word: int) -> int:
        """PZD `word` as the following output images carry it."""
        with self._condition:
            return self._outputs[word]

    def send_output(self, word: int, value: int, timeout: float = PKW_TIMEOUT) -> None:
        """Set PZD `word` and return once the slave answered the Data_Exchange after the first one that carried it
        (a master may hand over one exchange's reply late): two writes in a row (a fault acknowledge's edge, an
        enabling step) each reach the drive, none is lost between two cycles."""
        with self._condition:
            self._outputs[word] = value & 0xFFFF
            carried_by = self._sent + 2
            self._wait_process_data(lambda: self._answered >= carried_by, f"PZD{word + 1} output", timeout)

    def current_input(self, word: int, timeout: float = PKW_TIMEOUT) -> int:
        """PZD `word` of the latest input image, waiting for the first one after the exchange started."""
        with self._condition:
            self._wait_process_data(lambda: self._answered > 0, f"PZD{word + 1} input", timeout)
            return self._inputs[word]

    def _wait_process_data(self, done: Callable[[], bool], what: str, timeout: float) -> None:
        ready = self._condition.wait_for(lambda: done() or self._link_error is not None, timeout)
        if self._link_error is not None:
            raise ProfibusLinkDown(f"{what}: {self._link_error}")
        if not ready:
            raise PkwTimeout(f"{what}: no Data_Exchange with station {self.address} within {timeout:g} s")

    # -- parameters -------------------------------------------------------------------------------------------

    def read(self, pnu: int, *, double: bool, signed: bool, index: int = 0) -> int:
        request = read_request(pnu, index)
        return reply_value(request, self.transaction(request), double=double, signed=signed)

    def write(self, pnu: int, value: int, *, double: bool, index: int = 0) -> None:
        request = write_request(pnu, value, double, index)
        reply_value(request, self.transaction(request), double=double, signed=value < 0)

    def run_procedure(self, pnu: int, value: int = 0, timeout: float = PROCEDURE_TIMEOUT) -> None:
        """A procedure PNU (save, sequence read/write): its request stays until PWE says done or failed."""
        request = write_request(pnu, value, double=False)
        reply = self.transaction(request, procedure=True, timeout=timeout)
        reply_value(request, reply, double=False, signed=False, procedure=True)

    def transaction(self, request: PkwMessage, procedure: bool = False, timeout: float = PKW_TIMEOUT) -> PkwMessage:
        """Submit, wait for the completing reply; raises when the link is down or the reply is late."""
        with self._condition:
            self._wait(lambda: not self._channel.busy, request, timeout)
            self._reply = None
            self._channel.submit(request, procedure)
            try:
                self._wait(lambda: self._reply is not None, request, timeout)
            except ServoStudioError:
                self._channel.abandon()
                raise
            reply, self._reply = self._reply, None
        assert reply is not None
        return reply

    def _wait(self, done: Callable[[], bool], request: PkwMessage, timeout: float) -> None:
        ready = self._condition.wait_for(lambda: done() or self._link_error is not None, timeout)
        if self._link_error is not None:
            raise ProfibusLinkDown(f"PNU {request.pnu}: {self._link_error}")
        if not ready:
            raise PkwTimeout(f"PNU {request.pnu}: no PKW reply from station {self.address} within {timeout:g} s")

    # -- the cyclic exchange's callbacks ------------------------------------------------------------------------

    def _output_image(self) -> bytes:
        with self._condition:
            self._sent += 1
            return self._channel.output().encode() + pack_words(self._outputs)

    def _input_image(self, data: bytes) -> None:
        reply = PkwMessage.decode(data[:PKW_BYTES])
        with self._condition:
            previous = self._inputs[0] if self._answered else None
            self._inputs = unpack_words(data[self.ppo.pzd_offset :])
            self._answered = self._sent
            self._condition.notify_all()
            completed = self._channel.receive(reply)
            if completed is not None:
                self._reply = completed
                self._condition.notify_all()
            status, listener = self._inputs[0], self._on_status
        if listener is not None and status != previous:  # outside the lock: the listener publishes an event
            listener(status)

    def _on_link(self, error: ServoStudioError | None) -> None:
        with self._condition:
            self._link_error = error
            if error is not None and self._channel.busy:
                self._channel.abandon()
            self._condition.notify_all()
