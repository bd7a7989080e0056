"""A class-1 DP master over one byte stream: a pyserial URL (`socket://HOST:PORT`, the simulated line's TCP
stream) or a serial port (an RS-485 adapter, the simulator's pseudo-terminal). Our own, on the project's codec
(docs/profibus.md §6): one SRD request and its response at a time, under a lock, so a scan and a cyclic exchange
share the line safely.

Frame count bit (EN 50170 vol. 2, FDL): the first request to a station goes with FCV clear; after that FCV is set
and FCB toggles with every answered request. A request that got no answer is repeated with the same FCB, so a
station that did answer (its response was lost) replies again without executing twice. A station that stays
silent through the retries is forgotten: the next request starts again with FCV clear.
"""

from __future__ import annotations

import threading
import time
from typing import NoReturn

import serial

from servostudio.errors import CommunicationError, Timeout, Unavailable
from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus import function_codes as fc
from servostudio.transport.profibus.cyclic import CyclicExchange
from servostudio.transport.profibus.interface import Inputs, LinkReport, Outputs
from servostudio.transport.profibus.ppo import Ppo
from servostudio.transport.profibus.telegram import BROADCAST, Frame, ShortAcknowledge, Telegram, encode
from servostudio.transport.profibus.telegram_decoder import TelegramDecoder

DEFAULT_MASTER = 2
DEFAULT_BAUDRATE = 1_500_000
RESPONSE_TIMEOUT = 0.1
"""Seconds a station has to answer (a generous slot time: the TCP stream and the OS add latency)."""
RETRIES = 1
READ_SLICE = 0.005
_REFUSALS = {
    fc.USER_ERROR: "user error (UE)",
    fc.NO_RESOURCE: "no resource (RR)",
    fc.NO_SERVICE: "service not activated (RS)",
}


class DpLinkError(Unavailable, ConnectionError):
    """The line cannot be opened or was lost (cable, adapter, TCP connection)."""


class DpNoResponse(Timeout, TimeoutError):
    """A station did not answer a request within the slot time, retries included."""

    def __init__(self, address: int, service: str) -> None:
        self.address = address
        super().__init__(f"DP station {address} did not answer {service}")


class DpRefused(CommunicationError):
    """A station answered a request with a refusal (UE, RR, RS) or with a response of the wrong shape."""

    def __init__(self, address: int, service: str, reason: str) -> None:
        self.address = address
        super().__init__(f"DP station {address} refused {service}: {reason}")


class ByteLink:
    """The line as bytes: write a telegram, read what arrived within a time slice. A port that failed is closed;
    the next write opens it again, so a line that comes back (a TCP server restarted, an adapter plugged in again)
    is used again without a new link."""

    def __init__(self, url: str, baudrate: int = DEFAULT_BAUDRATE) -> None:
        self.url = url
        self.baudrate = baudrate
        self._port: serial.Serial | None = self._open()

    def _open(self) -> serial.Serial:
        try:
            return serial.serial_for_url(
                self.url, baudrate=self.baudrate, parity=serial.PARITY_EVEN, timeout=READ_SLICE
            )
        except (serial.SerialException, ValueError, OSError) as error:
            raise DpLinkError(f"cannot open PROFIBUS line {self.url}: {error}") from error

    def _opened(self) -> serial.Serial:
        if self._port is None:
            self._port = self._open()
        return self._port

    def write(self, data: bytes) -> None:
        try:
            self._opened().write(data)
        except (serial.SerialException, OSError) as error:
            self._lost(error)

    def read(self) -> bytes:
        """What came in within one slice (possibly nothing)."""
        try:
            port = self._opened()
            first = port.read(1)
            return first + port.read(port.in_waiting) if first else b""
        except (serial.SerialException, OSError) as error:
            self._lost(error)

    def discard_input(self) -> None:
        try:
            self._opened().reset_input_buffer()
        except (serial.SerialException, OSError) as error:
            self._lost(error)

    def _lost(self, error: Exception) -> NoReturn:
        self.close()
        raise DpLinkError(f"PROFIBUS line {self.url} lost: {error}") from error

    def close(self) -> None:
        port, self._port = self._port, None
        if port is not None:
            port.close()


class DpMaster:
    """The DP-V0 services of a class-1 master (SAP 62) on one line."""

    def __init__(
        self, link: ByteLink, address: int = DEFAULT_MASTER, timeout: float = RESPONSE_TIMEOUT, retries: int = RETRIES
    ) -> None:
        self.link = link
        self.address = address
        self.timeout = timeout
        self.retries = retries
        self.decoder = TelegramDecoder()
        self._frame_count: dict[int, int] = {}
        self._lock = threading.Lock()

    def close(self) -> None:
        self.link.close()

    # -- DP services ----------------------------------------------------------------------------------------

    def slave_diag(self, address: int, timeout: float | None = None, retries: int | None = None) -> dp.SlaveDiag:
        reply = self._data_reply(address, "Slave_Diag", b"", dp.SLAVE_DIAG_SAP, timeout, retries)
        try:
            return dp.SlaveDiag.decode(reply.data)
        except dp.DpServiceError as error:
            raise DpRefused(address, "Slave_Diag", str(error)) from error

    def set_prm(self, address: int, prm: dp.SetPrm) -> None:
        self._acknowledged(address, "Set_Prm", prm.encode(), dp.SET_PRM_SAP)

    def chk_cfg(self, address: int, config: bytes) -> None:
        self._acknowledged(address, "Chk_Cfg", config, dp.CHK_CFG_SAP)

    def data_exchange(self, address: int, outputs: bytes) -> bytes:
        """Outputs out, inputs back (Data_Exchange has no SAP)."""
        return self._data_reply(address, "Data_Exchange", outputs, None).data

    def global_control(self, command: int, group_select: int = 0) -> None:
        """Broadcast SDN: no station answers."""
        unit = dp.GlobalControl(command, group_select).encode()
        function = fc.request_code(fc.SDN_HIGH)
        telegram = Telegram(BROADCAST, self.address, function, unit, dp.GLOBAL_CONTROL_SAP, dp.MASTER_SAP)
        with self._lock:
            self.link.write(encode(telegram))

    def parameterise(self, address: int, ppo: Ppo, watchdog: float | None, ident_number: int) -> dp.SlaveDiag:
        """Set_Prm (locked to us, watchdog), Chk_Cfg with the PPO, then Slave_Diag until it is ready."""
        self.set_prm(address, prm_for(ident_number, watchdog))
        self.chk_cfg(address, ppo.identifiers)
        diag = self.slave_diag(address)
        if not diag.ready_for_data_exchange or diag.master_address != self.address:
            raise DpRefused(address, "parameterisation", describe_diag(diag))
        return diag

    def exchange(
        self,
        address: int,
        ppo: Ppo,
        outputs: Outputs,
        inputs: Inputs,
        on_link: LinkReport,
        period: float,
        watchdog: float | None,
    ) -> CyclicExchange:
        """The cyclic Data_Exchange with one slave (`interface.DpLine.exchange`)."""
        return CyclicExchange(self, address, ppo, outputs, inputs, on_link, period, watchdog)

    # -- one SRD transaction ----------------------------------------------------------------------------------

    def _data_reply(
        self,
        address: int,
        service: str,
        data: bytes,
        sap: int | None,
        timeout: float | None = None,
        retries: int | None = None,
    ) -> Telegram:
        response = self.transact(address, service, data, sap, timeout, retries)
        if not isinstance(response, Telegram) or fc.function_of(response.function) not in (fc.DATA_LOW, fc.DATA_HIGH):
            raise DpRefused(address, service, _response_text(response))
        return response

    def _acknowledged(self, address: int, service: str, data: bytes, sap: int) -> None:
        response = self.transact(address, service, data, sap)
        if isinstance(response, ShortAcknowledge):
            return
        if isinstance(response, Telegram) and fc.function_of(response.function) == fc.OK:
            return
        raise DpRefused(address, service, _response_text(response))

    def transact(
        self,
        address: int,
        service: str,
        data: bytes,
        sap: int | None,
        timeout: float | None = None,
        retries: int | None = None,
    ) -> Frame:
        """One SRD request with its retries (the master's own unless given); the station's response."""
        with self._lock:
            function = self._next_function(address)
            telegram = _request(address, self.address, function, data, sap)
            for _ in range((self.retries if retries is None else retries) + 1):
                response = self._send_and_wait(telegram, address, self.timeout if timeout is None else timeout)
                if response is not None:
                    self._frame_count[address] = fc.frame_count_bit(function)
                    return response
            self._frame_count.pop(address, None)
            raise DpNoResponse(address, service)

    def _next_function(self, address: int) -> int:
        previous = self._frame_count.get(address)
        if previous is None:
            return fc.request_code(fc.SRD_HIGH) | fc.FRAME_COUNT_BIT  # FCV clear, FCB 1
        return fc.request_code(fc.SRD_HIGH, previous ^ 1)

    def _send_and_wait(self, telegram: Telegram, address: int, timeout: float) -> Frame | None:
        self.link.discard_input()
        self.decoder = TelegramDecoder()
        self.link.write(encode(telegram))
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for frame in self.decoder.feed(self.link.read()):
                if self._answers(frame, address):
                    return frame
        return None

    def _answers(self, frame: Frame, address: int) -> bool:
        if isinstance(frame, ShortAcknowledge):
            return True
        return (
            isinstance(frame, Telegram)
            and not fc.is_request(frame.function)
            and frame.destination == self.address
            and frame.source == address
        )


def prm_for(ident_number: int, watchdog: float | None) -> dp.SetPrm:
    """Set_Prm that locks the slave to us; the watchdog as 10 ms × factor 1 × factor 2 (each 1..255)."""
    if watchdog is None:
        return dp.SetPrm(dp.STATUS_LOCK, 1, 1, 11, ident_number, 0)
    units = max(1, round(watchdog / dp.WATCHDOG_BASE))
    factor_2 = -(-units // 255)
    factor_1 = min(255, max(1, round(units / factor_2)))
    return dp.SetPrm(dp.STATUS_LOCK | dp.STATUS_WATCHDOG, factor_1, factor_2, 11, ident_number, 0)


def describe_diag(diag: dp.SlaveDiag) -> str:
    """The Slave_Diag status bits that keep a slave out of data exchange, in words."""
    texts = [
        text
        for bit, text in (
            (dp.DIAG_NOT_READY, "not ready for data exchange"),
            (dp.DIAG_CONFIG_FAULT, "configuration (PPO) refused"),
            (dp.DIAG_PRM_FAULT, "parameters (ident number) refused"),
            (dp.DIAG_MASTER_LOCK, f"locked to master {diag.master_address}"),
        )
        if diag.status_1 & bit
    ]
    return ", ".join(texts) or "ready"


def _request(destination: int, source: int, function: int, data: bytes, sap: int | None) -> Telegram:
    if sap is None:
        return Telegram(destination, source, function, data)
    return Telegram(destination, source, function, data, sap, dp.MASTER_SAP)


def _response_text(response: Frame) -> str:
    if isinstance(response, Telegram):
        code = fc.function_of(response.function)
        return _REFUSALS.get(code, f"response function 0x{code:X}")
    return f"unexpected {type(response).__name__}"
