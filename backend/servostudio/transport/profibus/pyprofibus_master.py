"""pyprofibus's class-1 DP master over its serial PHY, the transport of a `profibus:PORT[@BAUD][?master=ADDR]` line
(an RS-485 adapter, the simulator's pseudo-terminal; docs/profibus.md §7). pyprofibus is GPL-2.0-or-later and an
optional extra (`pip install servostudio[profibus]`); `open.open_dp_line` imports this module only when a
serial line is opened.

Public interface (`interface.DpLine`, the same as the project's `master.DpMaster`; `TtaProClient`, the bus
connection and `scan.scan` use nothing else):

    PyprofibusMaster(port, baudrate=1_500_000, address=2, timeout=0.1, retries=1)
      .slave_diag(address, timeout=None, retries=None) -> SlaveDiag
      .global_control(command, group_select=0)
      .exchange(address, ppo, outputs, inputs, on_link, period, watchdog) -> DataExchange (start, stop, error, cycles)
      .close()
    errors: DpNoResponse (Timeout), DpRefused (Communication), DpLinkError (Unavailable) from `master.py`

How pyprofibus is used: the cyclic exchange of a slave is one `DPM1` with that slave (its own start-up FDL_Status
→ Slave_Diag → Set_Prm → Chk_Cfg → Slave_Diag → Data_Exchange, its FCB handling, watchdog factors and fault
debouncing that re-initialise a lost slave); a scan, Slave_Diag and Global_Control are pyprofibus's telegram
classes sent through its transceivers on the same PHY. pyprofibus is not thread-safe: one lock serialises whole
transactions (a request and its response), so a scan between two Data_Exchanges never takes a response meant for
the DPM1. DPM1 reads a PHY error as silence; the PHY here remembers it, so a failed port is `DpLinkError`, closed,
and opened again by the next attempt. pyprofibus prints its diagnostics; here they go to the log instead (the
CLI's standard output carries JSON).
"""

from __future__ import annotations

import contextlib
import logging
import select
import threading
import time
from collections.abc import Callable

import serial
from pyprofibus.dp import (
    DpCfgDataElement,
    DpTelegram,
    DpTelegram_GlobalControl,
    DpTelegram_SlaveDiag_Con,
    DpTelegram_SlaveDiag_Req,
    DpTransceiver,
)
from pyprofibus.dp_master import DPM1, DpSlaveDesc
from pyprofibus.fdl import FdlFCB, FdlTelegram, FdlTransceiver
from pyprofibus.phy import PhyError
from pyprofibus.phy_serial import CpPhySerial
from pyprofibus.util import ProfibusError

from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus.exchange import SlaveExchange
from servostudio.transport.profibus.interface import Inputs, LinkReport, Outputs
from servostudio.transport.profibus.master import (
    DEFAULT_BAUDRATE,
    DEFAULT_MASTER,
    RESPONSE_TIMEOUT,
    RETRIES,
    DpLinkError,
    DpNoResponse,
    DpRefused,
    describe_diag,
)
from servostudio.transport.profibus.ppo import Ppo

log = logging.getLogger(__name__)

POLL_SLICE = 0.002
"""Longest wait for a byte between two polls of the PHY (pyprofibus polls without blocking and a timed poll of its
PHY spins, so the adapter waits for the port to become readable: a response is taken as soon as it arrives)."""
CONNECT_TIMEOUT = 3.0
"""Seconds DPM1 has to bring a slave into data exchange when the exchange starts. Its own request timeouts are
10-50 ms (FDL_Status, Slave_Diag, Set_Prm, Chk_Cfg): on a loaded host it repeats them, and gets there later. A
refusal ends the start-up at once, a silent station its first Slave_Diag; only a slow line takes this long."""
RECONNECT_WINDOW = 0.02
"""Seconds a lost slave's DPM1 runs per window: enough for a few steps of its start-up, short enough that the
other exchanges of the line keep their slaves' watchdogs fed."""


class _SerialPhy(CpPhySerial):
    """pyprofibus's serial PHY, remembering a failure of the port (DPM1 takes PHY errors for silence) and logging
    its warnings (the baud rate note for anything but 9600/19200 baud)."""

    def __init__(self, port: str, baudrate: int) -> None:
        super().__init__(port=port)
        self.failure: PhyError | None = None
        self.setConfig(baudrate=baudrate)

    def pollData(self, timeout: float = 0.0) -> bytearray | None:  # pyprofibus's names, overridden
        try:
            return super().pollData(timeout)
        except PhyError as error:
            self._note(error)
            raise

    def sendData(self, telegramData: bytearray, srd: bool) -> None:
        try:
            super().sendData(telegramData, srd)
        except PhyError as error:
            self._note(error)
            raise

    def wait_readable(self, seconds: float) -> None:
        """Until a byte can be read or `seconds` pass; a port that failed returns at once (its next poll raises)."""
        port = self._CpPhySerial__serial  # pyprofibus 1.13 keeps its pyserial port private (pinned)
        with contextlib.suppress(OSError, ValueError, TypeError):
            select.select([port.fileno()], [], [], seconds)

    def _note(self, error: PhyError) -> None:
        """A port failure (pyserial's error behind the PhyError), not a garbled telegram (a PhyError alone)."""
        if isinstance(error.__context__, serial.SerialException):
            self.failure = error

    def _warningMsg(self, msg: str) -> None:
        log.info("pyprofibus: %s", msg)


class _LoggingDpm1(DPM1):
    """DPM1 whose messages go to the log (pyprofibus prints them); it keeps the last fault it reported (a refused
    Set_Prm or Chk_Cfg, a slave locked to another master), so a start-up that cannot succeed ends at once."""

    def __init__(self, phy: _SerialPhy, address: int) -> None:
        super().__init__(phy, address)
        self.fault: str | None = None

    def _DpMaster__errorMsg(self, msg: str) -> None:  # DpMaster's private names, overridden
        self.fault = msg
        log.warning("pyprofibus DPM1: %s", msg)

    def _DpMaster__debugMsg(self, msg: str) -> None:
        log.debug("pyprofibus DPM1: %s", msg)


class _FairLock:
    """A lock handed to its waiters in the order they came. `threading.Lock` lets the thread that releases it take
    it straight back, so a scan going from address to address, or a slave's start-up window after window, could
    keep the other slaves of the line from their Data_Exchange past their watchdog."""

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._next_ticket = 0
        self._serving = 0

    def __enter__(self) -> None:
        with self._condition:
            ticket = self._next_ticket
            self._next_ticket += 1
            self._condition.wait_for(lambda: self._serving == ticket)

    def __exit__(self, *_: object) -> None:
        with self._condition:
            self._serving += 1
            self._condition.notify_all()


class PyprofibusMaster:
    """A class-1 DP master (pyprofibus DPM1) on one serial line."""

    def __init__(
        self,
        port: str,
        baudrate: int = DEFAULT_BAUDRATE,
        address: int = DEFAULT_MASTER,
        timeout: float = RESPONSE_TIMEOUT,
        retries: int = RETRIES,
    ) -> None:
        self.port = port
        self.baudrate = baudrate
        self.address = address
        self.timeout = timeout
        self.retries = retries
        self.lock = _FairLock()
        """Held for a whole transaction: one Slave_Diag try, one Data_Exchange cycle, one start-up window."""
        self.generation = 0
        """Counts the openings of the port: an exchange whose DPM1 runs on an older PHY builds a new one."""
        self._phy: _SerialPhy | None = None
        self._transceiver: DpTransceiver | None = None
        self._closed = False
        self.opened()

    # -- the port -----------------------------------------------------------------------------------------------

    def opened(self) -> _SerialPhy:
        """The PHY, opened again after a failure (a re-plugged adapter is used again without a new master)."""
        if self._closed:
            raise DpLinkError(f"PROFIBUS line {self.port} is closed")
        if self._phy is None:
            try:
                self._phy = _SerialPhy(self.port, self.baudrate)
            except PhyError as error:
                raise DpLinkError(f"cannot open PROFIBUS line {self.port}: {error}") from error
            self._transceiver = _transceiver(self._phy, self.address)
            self.generation += 1
        return self._phy

    def check(self) -> None:
        """`DpLinkError` if the port failed since it was opened; the port is closed, the next use reopens it."""
        if self._phy is not None and self._phy.failure is not None:
            failure = self._phy.failure
            self._drop_port()
            raise DpLinkError(f"PROFIBUS line {self.port} lost: {failure}")

    def close(self) -> None:
        self._closed = True
        self._drop_port()

    def _drop_port(self) -> None:
        phy, self._phy, self._transceiver = self._phy, None, None
        if phy is not None:
            phy.close()

    # -- DP services ----------------------------------------------------------------------------------------

    def slave_diag(self, address: int, timeout: float | None = None, retries: int | None = None) -> dp.SlaveDiag:
        request = DpTelegram_SlaveDiag_Req(da=address, sa=self.address)
        for _ in range((self.retries if retries is None else retries) + 1):
            with self.lock:
                reply = self._request(request, address, self.timeout if timeout is None else timeout)
            if reply is not None:
                return _diag(address, reply)
        raise DpNoResponse(address, "Slave_Diag")

    def global_control(self, command: int, group_select: int = 0) -> None:
        """Broadcast SDN: no station answers."""
        telegram = DpTelegram_GlobalControl(da=FdlTelegram.ADDRESS_MCAST, sa=self.address)
        telegram.controlCommand = command
        telegram.groupSelect = group_select
        with self.lock:
            self._send(telegram)
            self.check()

    def exchange(
        self,
        address: int,
        ppo: Ppo,
        outputs: Outputs,
        inputs: Inputs,
        on_link: LinkReport,
        period: float,
        watchdog: float | None,
    ) -> PyprofibusExchange:
        """The cyclic Data_Exchange with one slave through a DPM1 of its own (`interface.DpLine.exchange`)."""
        return PyprofibusExchange(self, address, ppo, outputs, inputs, on_link, period, watchdog)

    def dpm_for(
        self, address: int, ppo: Ppo, watchdog: float | None, ident_number: int
    ) -> tuple[_LoggingDpm1, DpSlaveDesc]:
        """A DPM1 on the current PHY with one slave: locked to us, the PPO's Chk_Cfg, the watchdog (None: off)."""
        dpm = _LoggingDpm1(self.opened(), self.address)
        desc = _slave_desc(address, ppo, watchdog, ident_number)
        dpm.addSlave(desc)
        dpm.initialize()
        return dpm, desc

    # -- one request and its response, the caller holding the lock --------------------------------------------

    def _request(
        self, request: DpTelegram_SlaveDiag_Req, address: int, timeout: float
    ) -> DpTelegram_SlaveDiag_Con | None:
        self._send(request)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            reply = self._poll()
            if reply is not None and DpTelegram_SlaveDiag_Con.checkType(reply) and reply.sa == address:
                return reply
            self.opened().wait_readable(POLL_SLICE)
        self.check()
        return None

    def _send(self, telegram: DpTelegram) -> None:
        self.opened().releaseBus()  # no DPM1 transaction is running: the line is ours at once
        assert self._transceiver is not None
        try:
            self._transceiver.send(fcb=FdlFCB(enable=False), telegram=telegram)
        except ProfibusError as error:
            self.check()
            raise DpLinkError(f"PROFIBUS line {self.port}: cannot send: {error}") from error

    def _poll(self) -> DpTelegram | None:
        """One telegram for us, or None; corrupted or foreign telegrams are dropped (pyprofibus raises them)."""
        assert self._transceiver is not None
        try:
            ok, telegram = self._transceiver.poll(0.0)
        except ProfibusError:
            self.check()
            return None
        return telegram if ok else None


class PyprofibusExchange(SlaveExchange):
    """The cyclic Data_Exchange of one slave by a DPM1 (`interface.DataExchange`): every `period` one output image
    out and one input image back under the line's lock; a cycle without an answer reports the slave lost
    (`DpNoResponse`, or `DpLinkError` for a failed port) and the DPM1 reconnects it by itself."""

    def __init__(
        self,
        master: PyprofibusMaster,
        address: int,
        ppo: Ppo,
        outputs: Outputs,
        inputs: Inputs,
        on_link: LinkReport,
        period: float,
        watchdog: float | None,
    ) -> None:
        super().__init__(address, ppo, outputs, inputs, on_link, period, watchdog)
        self.master = master
        self._ident = 0
        self._last_answer = 0.0
        self._generation = 0
        self._dpm: _LoggingDpm1 | None = None
        self._desc: DpSlaveDesc | None = None

    def start(self) -> PyprofibusExchange:
        """Slave_Diag for its ident, DPM1's start-up into data exchange now (errors go to the caller), then the
        exchange in the background."""
        self._ident = self.master.slave_diag(self.address).ident_number
        if not self._start_up():
            fault = self._dpm_now().fault
            self._dpm = self._desc = None  # the next start begins afresh
            raise DpRefused(self.address, "parameterisation", self._refusal(fault))
        self._last_answer = time.monotonic()
        self._run_in_background(f"pyprofibus-dx-{self.address}")
        return self

    def _start_up(self) -> bool:
        """DPM1's start-up in short windows (the line's other slaves are served in between) until the slave is in
        data exchange (True), DPM1 reports a fault or the time is over (False)."""
        deadline = time.monotonic() + CONNECT_TIMEOUT
        while time.monotonic() < deadline:
            with self.master.lock:
                if self._run_until(self._started, RECONNECT_WINDOW):
                    return bool(self._slave().isConnected())
        return False

    def _started(self) -> bool:
        return bool(self._slave().isConnected()) or self._dpm_now().fault is not None

    def _refusal(self, fault: str | None) -> str:
        """Why the slave stays out of data exchange: its Slave_Diag in words, else what DPM1 reported."""
        reason = describe_diag(self.master.slave_diag(self.address))
        return fault if reason == "ready" and fault else reason

    def _step(self) -> None:
        """One cycle: the line is held for at most one response timeout (a reconnection window while lost), so
        the other slaves of the line keep being served; silence longer than the retries' time loses the slave."""
        with self.master.lock:
            data = self._exchange_once(self._outputs(), self.master.timeout if self.error is None else RECONNECT_WINDOW)
        if data is not None:
            self._answered(data)
        elif time.monotonic() - self._last_answer > self.master.timeout * (self.master.retries + 1):
            raise DpNoResponse(self.address, "Data_Exchange")

    def _answered(self, data: bytes) -> None:
        self._last_answer = time.monotonic()
        if self.error is not None:
            self._recovered()
        self._inputs(data)
        self.cycles += 1

    def _exchange_once(self, image: bytes, seconds: float) -> bytes | None:
        """Run the DPM1 for up to `seconds` until the slave's input image comes. DPM1 sends an output image once:
        it is given again until the answer comes, so a lost response is repeated after DPM1's 0.1 s."""
        received: list[bytes] = []
        self._slave().setMasterOutData(image)

        def arrived() -> bool:
            slave = self._slave()
            data = slave.getMasterInData()  # set by the run() that received it, cleared by the next
            if data is None:
                slave.setMasterOutData(image)
                return False
            received.append(bytes(data))
            return True

        self._run_until(arrived, seconds)
        return received[0] if received else None

    def _run_until(self, done: Callable[[], bool], seconds: float) -> bool:
        deadline = time.monotonic() + seconds
        while True:
            self._run_dpm()
            if done():
                return True
            self.master.check()
            if time.monotonic() >= deadline:
                return False
            self.master.opened().wait_readable(POLL_SLICE)

    def _run_dpm(self) -> None:
        """One step of the DPM1. It raises on a refused Data_Exchange (RS); a fresh DPM1 then starts over."""
        try:
            self._dpm_now().run()
        except ProfibusError as error:
            self._dpm = self._desc = None
            raise DpRefused(self.address, "Data_Exchange", str(error)) from error

    def _dpm_now(self) -> _LoggingDpm1:
        """This slave's DPM1, built again when the port was opened again."""
        self.master.opened()
        if self._dpm is None or self._generation != self.master.generation:
            self._dpm, self._desc = self.master.dpm_for(self.address, self.ppo, self.watchdog, self._ident)
            self._generation = self.master.generation
        return self._dpm

    def _slave(self) -> DpSlaveDesc:
        self._dpm_now()
        assert self._desc is not None
        return self._desc


def _transceiver(phy: _SerialPhy, address: int) -> DpTransceiver:
    """pyprofibus's FDL and DP transceivers for the requests outside a DPM1 (scan, Slave_Diag, Global_Control)."""
    fdl = FdlTransceiver(phy)
    fdl.setRXFilter([address])
    return DpTransceiver(fdl, thisIsMaster=True)


def _slave_desc(address: int, ppo: Ppo, watchdog: float | None, ident_number: int) -> DpSlaveDesc:
    desc = DpSlaveDesc()
    desc.slaveAddr = address
    desc.identNumber = ident_number
    desc.inputSize = desc.outputSize = ppo.length
    desc.setPrmTelegram.da = address
    desc.setPrmTelegram.identNumber = ident_number
    desc.chkCfgTelegram.da = address
    desc.setCfgDataElements([DpCfgDataElement(identifier) for identifier in ppo.identifiers])
    desc.setWatchdog(0 if watchdog is None else round(watchdog * 1000))
    return desc


def _diag(address: int, reply: DpTelegram_SlaveDiag_Con) -> dp.SlaveDiag:
    try:
        return dp.SlaveDiag.decode(bytes(reply.getDU()))
    except dp.DpServiceError as error:
        raise DpRefused(address, "Slave_Diag", str(error)) from error
