"""A DP-V0 slave station: what it answers on the line (EN 50170 vol. 2 part 3; TTA-PRO Profibus Communication
Profile, Chapter 1, L63-179 and L397-413).

States: Wait_Prm (after power-up or a watchdog expiry) → Set_Prm with the right ident number locks the slave to
that master → Wait_Cfg → Chk_Cfg with a configuration the application accepts → Data_Exch. Slave_Diag is answered
in every state. Data_Exchange from anyone but the locking master, or before Data_Exch, is answered "no service"
(RS). A request repeated with FCV set and an unchanged FCB gets the previous response again without being executed.
Global_Control SYNC latches the outputs until the next SYNC (UNSYNC ends it), FREEZE samples the inputs that the
following Data_Exchanges return until the next FREEZE (UNFREEZE ends it), CLEAR_DATA sets the outputs to 0. With
the watchdog on, a master silent for longer than the watchdog time drops the slave back to Wait_Prm.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Protocol

from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus import function_codes as fc
from servostudio.transport.profibus.telegram import BROADCAST, Frame, ShortAcknowledge, Telegram

DIAG_SAPS = (dp.MASTER_SAP, dp.SLAVE_DIAG_SAP)
"""Slave_Diag response: to the master's SAP 62, from SAP 60."""


class DpApplication(Protocol):
    """What the station needs from the device behind it."""

    @property
    def config(self) -> bytes: ...
    @property
    def output_length(self) -> int: ...
    def check_config(self, config: bytes) -> bool: ...
    def apply_outputs(self, data: bytes) -> None: ...
    def read_inputs(self) -> bytes: ...
    def link_lost(self) -> None: ...


class StationState(enum.Enum):
    WAIT_PRM = "Wait_Prm"
    WAIT_CFG = "Wait_Cfg"
    DATA_EXCHANGE = "Data_Exch"


@dataclass(frozen=True)
class _Answered:
    """The last SRD request's response, kept for a repetition (same master, FCV set, same FCB)."""

    master: int
    frame_count_bit: int
    response: Frame | None


class DpStation:
    def __init__(self, address: int, ident_number: int, application: DpApplication) -> None:
        self.address = address
        self.ident_number = ident_number
        self.application = application
        self.state = StationState.WAIT_PRM
        self.master: int | None = None
        self.group_ident = 0
        self.watchdog: float | None = None
        self.prm_fault = False
        self.config_fault = False
        self.sync = False
        self.freeze = False
        self._latched: bytes | None = None
        self._frozen = b""
        self._last_seen = 0.0
        self._answered: _Answered | None = None

    # -- line ---------------------------------------------------------------------------------------------------

    def handle(self, frame: Frame, now: float) -> Frame | None:
        """The response to one telegram on the line, or None (not for us, no reply due)."""
        if not isinstance(frame, Telegram) or not fc.is_request(frame.function):
            return None
        if frame.destination == BROADCAST:
            self._broadcast(frame)
            return None
        if frame.destination != self.address:
            return None
        if fc.function_of(frame.function) == fc.FDL_STATUS:
            return Telegram(frame.source, self.address, fc.OK)
        if fc.function_of(frame.function) not in (fc.SRD_LOW, fc.SRD_HIGH):
            self._unacknowledged(frame)
            return None
        return self._request_with_reply(frame, now)

    def check_watchdog(self, now: float) -> None:
        """Called every positioner cycle: a silent master loses the slave."""
        if self.state is StationState.DATA_EXCHANGE and self.watchdog and now - self._last_seen > self.watchdog:
            self._leave_data_exchange()

    def _request_with_reply(self, frame: Telegram, now: float) -> Frame | None:
        answered = self._answered
        if answered is not None and _repeats(frame, answered):
            return answered.response
        if frame.source == self.master:
            self._last_seen = now
        response = self._service(frame)
        self._answered = _Answered(frame.source, fc.frame_count_bit(frame.function), response)
        return response

    def _unacknowledged(self, frame: Telegram) -> None:
        """SDN addressed to us: only Global_Control is meaningful."""
        if frame.destination_sap == dp.GLOBAL_CONTROL_SAP:
            self._global_control(frame)

    def _service(self, frame: Telegram) -> Frame:
        if frame.destination_sap is None:
            return self._data_exchange(frame)
        if frame.source_sap != dp.MASTER_SAP:
            return self._no_service(frame)
        handler = {
            dp.SLAVE_DIAG_SAP: self._slave_diag,
            dp.SET_PRM_SAP: self._set_prm,
            dp.CHK_CFG_SAP: self._chk_cfg,
            dp.GET_CONFIG_SAP: self._get_config,
        }.get(frame.destination_sap)
        return handler(frame) if handler is not None else self._no_service(frame)

    def _no_service(self, frame: Telegram) -> Telegram:
        return Telegram(frame.source, self.address, fc.NO_SERVICE)

    # -- services -----------------------------------------------------------------------------------------------

    def _data_exchange(self, frame: Telegram) -> Telegram:
        if self.state is not StationState.DATA_EXCHANGE or frame.source != self.master:
            return self._no_service(frame)
        if len(frame.data) != self.application.output_length:
            return self._no_service(frame)
        if self.sync:
            self._latched = frame.data
        else:
            self.application.apply_outputs(frame.data)
        inputs = self._frozen if self.freeze else self.application.read_inputs()
        return Telegram(frame.source, self.address, fc.DATA_LOW, inputs)

    def _slave_diag(self, frame: Telegram) -> Telegram:
        diag = self.diagnosis(locked_out=self.master is not None and frame.source != self.master)
        return Telegram(frame.source, self.address, fc.DATA_LOW, diag.encode(), *DIAG_SAPS)

    def diagnosis(self, locked_out: bool = False) -> dp.SlaveDiag:
        status_1 = _flags(
            (self.state is not StationState.DATA_EXCHANGE, dp.DIAG_NOT_READY),
            (self.config_fault, dp.DIAG_CONFIG_FAULT),
            (self.prm_fault, dp.DIAG_PRM_FAULT),
            (locked_out, dp.DIAG_MASTER_LOCK),
        )
        status_2 = dp.DIAG_ALWAYS_ONE | _flags(
            (self.state is StationState.WAIT_PRM, dp.DIAG_PRM_REQUEST),
            (self.watchdog is not None, dp.DIAG_WATCHDOG_ON),
            (self.freeze, dp.DIAG_FREEZE_MODE),
            (self.sync, dp.DIAG_SYNC_MODE),
        )
        master = dp.NO_MASTER if self.master is None else self.master
        return dp.SlaveDiag(status_1, status_2, 0, master, self.ident_number)

    def _set_prm(self, frame: Telegram) -> Frame:
        try:
            prm = dp.SetPrm.decode(frame.data)
        except dp.DpServiceError:
            self.prm_fault = True
            return ShortAcknowledge()
        if self.master is not None and frame.source != self.master and self.state is not StationState.WAIT_PRM:
            return ShortAcknowledge()  # locked to another master: Slave_Diag tells it (Master_Lock)
        if prm.station_status & dp.STATUS_UNLOCK and not prm.station_status & dp.STATUS_LOCK:
            self._leave_data_exchange()
            return ShortAcknowledge()
        self._parameterise(frame.source, prm)
        return ShortAcknowledge()

    def _parameterise(self, master: int, prm: dp.SetPrm) -> None:
        self.prm_fault = prm.ident_number != self.ident_number
        self.config_fault = False
        if self.prm_fault:
            self.state = StationState.WAIT_PRM
            return
        self.master = master
        self.watchdog = prm.watchdog
        self.group_ident = prm.group_ident
        self.sync = self.freeze = False
        self.state = StationState.WAIT_CFG

    def _chk_cfg(self, frame: Telegram) -> Frame:
        if self.state is StationState.WAIT_PRM or frame.source != self.master:
            return ShortAcknowledge()
        accepted = self.application.check_config(frame.data)
        self.config_fault = not accepted
        self.state = StationState.DATA_EXCHANGE if accepted else StationState.WAIT_PRM
        return ShortAcknowledge()

    def _get_config(self, frame: Telegram) -> Telegram:
        return Telegram(
            frame.source, self.address, fc.DATA_LOW, self.application.config, dp.MASTER_SAP, dp.GET_CONFIG_SAP
        )

    # -- global control -----------------------------------------------------------------------------------------

    def _broadcast(self, frame: Telegram) -> None:
        if frame.destination_sap == dp.GLOBAL_CONTROL_SAP and frame.source_sap == dp.MASTER_SAP:
            self._global_control(frame)

    def _global_control(self, frame: Telegram) -> None:
        if self.state is not StationState.DATA_EXCHANGE or frame.source != self.master:
            return
        try:
            control = dp.GlobalControl.decode(frame.data)
        except dp.DpServiceError:
            return
        if control.addresses(self.group_ident):
            self._apply_global_control(control.command)

    def _apply_global_control(self, command: int) -> None:
        if command & dp.CLEAR_DATA:
            self.application.apply_outputs(bytes(self.application.output_length))
        if command & dp.UNSYNC:
            self.sync = False
            self._release_latched()
        elif command & dp.SYNC:
            self._release_latched()
            self.sync = True
        if command & dp.UNFREEZE:
            self.freeze = False
        elif command & dp.FREEZE:
            self._frozen = self.application.read_inputs()
            self.freeze = True

    def _release_latched(self) -> None:
        if self._latched is not None:
            self.application.apply_outputs(self._latched)
            self._latched = None

    def _leave_data_exchange(self) -> None:
        was_exchanging = self.state is StationState.DATA_EXCHANGE
        self.state = StationState.WAIT_PRM
        self.master = None
        self.sync = self.freeze = False
        self._latched = None
        if was_exchanging:
            self.application.link_lost()


def _repeats(frame: Telegram, answered: _Answered) -> bool:
    """FCV set and the FCB unchanged from the same master: the master did not get our response."""
    bit = fc.frame_count_bit(frame.function)
    return fc.frame_count_valid(frame.function) and answered.master == frame.source and answered.frame_count_bit == bit


def _flags(*pairs: tuple[bool, int]) -> int:
    return sum(bit for active, bit in pairs if active)
