"""The PKW engine: the SDO engine's transfer interface for the TTA-PRO drives of a PROFIBUS-DP line
(docs/profibus.md §9).

A `Drive` reads and writes through ``engine.upload`` / ``download`` (and the ``_all`` batches) with (index, sub) and
little-endian bytes; on a PROFIBUS bus the index is the PNU and the sub the IND, and this engine turns each transfer
into a PKW request of the node's `TtaProClient` (one cyclic Data_Exchange per station, started on first use). So
every service that works on a `Drive` — read, write, backup, restore, compare, the terminal — works on a TTA-PRO
unchanged.

- Width and sign come from the node's parameter list (every PNU is a word or a double word, so there is no
  segmented or block transfer); a write of a procedure PNU (729 save, …) waits until the drive reports it done.
- Each node has one worker thread and two lanes, as the SDO engine: single requests someone waits for first, the
  batches of a backup or restore behind them. The lanes, the futures and the batches (``on_each``, ``cancel()``,
  the bounded wait) are the SDO engine's own, from ``drive/transfers.py``; only the carrying out is this engine's.
- Outcomes are the SDO engine's error classes, so the services that tell a refusal from a lost link keep doing so:
  a negative PKW reply is `PkwRefusal` (an `SdoAbortError`, 409 / exit 3) with the manual's text naming the PNU;
  no reply in time `PkwNoReply` (`SdoTimeoutError`), a station or line lost `PkwLinkLost` (`SdoLinkError`).
- The PZD1 control and status words (dictionary addresses `CONTROL_WORD`, `STATUS_WORD`, beyond every PNU) are
  not PKW requests: a read gives the latest status word (or the control word going out), a write sets the control
  word and returns once a Data_Exchange carried it. They are carried out at once on the caller's thread, never
  queued behind a parameter request: a quick stop must not wait for a backup's PNUs (docs/profibus.md §12).
- It subclasses `SdoEngine` only to be one type for `Drive` and `BusConnection`; each public method is overridden,
  and the CANopen-only one (block upload) is refused (`NoCanFrames`).
"""

from __future__ import annotations

import functools
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import CancelledError, Future
from dataclasses import dataclass
from typing import Any, TypeVar

from servostudio.drive.link import BusLink
from servostudio.drive.profibus.client import PKW_TIMEOUT, PROCEDURE_TIMEOUT, ProfibusLinkDown, TtaProClient
from servostudio.drive.profibus.link import ProfibusLink, refusal
from servostudio.drive.profibus.pkw import read_request, write_request
from servostudio.drive.profibus.pkw_errors import PkwError, PkwRefused
from servostudio.drive.profibus.pkw_handshake import reply_value
from servostudio.drive.profibus.pzd import join_double, split_double
from servostudio.drive.sdo import SdoAbortError, SdoEngine, SdoError, SdoLinkError, SdoTimeoutError
from servostudio.drive.transfers import Completion, FutureCompletion, NodeLanes, TransferBatch
from servostudio.errors import InvalidInput, ServoStudioError, Timeout
from servostudio.od.datatypes import DataType
from servostudio.od.pnu_model import CONTROL_WORD, POSITION_SET_POINT, STATUS_WORD, Parameter, ParameterDictionary

R = Any
T = TypeVar("T")
STATIONS = range(1, 126)
RECOVERY_POLL = 0.02
"""Seconds between two attempts of a request while its station is being parameterised again."""


def _pnu_error(error: SdoError, node: int, pnu: int, index: int, reason: str) -> None:
    """Fill an SDO error's fields and give it a message that names the PNU, not a hexadecimal index."""
    Exception.__init__(error, f"node {node}, {reason}")
    error.node, error.index, error.sub, error.reason = node, pnu, index, reason


class PkwRefusal(SdoAbortError):
    """The drive answered a PKW request negatively (AK 7 / 8, or a procedure that failed); ``code`` is the PKW
    error number (or 0)."""

    def __init__(self, node: int, error: PkwError) -> None:
        _pnu_error(self, node, error.pnu, error.index, str(error))
        self.code = error.error_number if isinstance(error, PkwRefused) else 0


class PkwNoReply(SdoTimeoutError):
    """No PKW reply in time, or the station did not answer the DP master."""

    def __init__(self, node: int, pnu: int, index: int, reason: str) -> None:
        _pnu_error(self, node, pnu, index, reason)


class PkwLinkLost(SdoLinkError):
    """The station left data exchange, refused its parameterisation, or the line failed."""

    def __init__(self, node: int, pnu: int, index: int, reason: str) -> None:
        _pnu_error(self, node, pnu, index, reason)


class StationOutOfRange(InvalidInput):
    """A node number no DP slave can have (126 is an unset slave's, 127 the broadcast)."""


@dataclass(frozen=True)
class _Transfer:
    node: int
    pnu: int
    index: int
    data: bytes | None  # None: a read
    timeout: float
    completion: Completion
    slot: int = 0


ParameterLists = Callable[[int], ParameterDictionary | None]
StatusListener = Callable[[int, int], None]
"""(node, status word)."""


class PkwEngine(SdoEngine):
    """Every PKW transfer of one PROFIBUS-DP line; ``parameter_list(node)`` describes the node's PNUs."""

    def __init__(self, link: ProfibusLink, parameter_list: ParameterLists, timeout: float = PKW_TIMEOUT) -> None:
        super().__init__(link, timeout)
        self.profibus = link
        self.parameter_list = parameter_list
        self._clients: dict[int, TtaProClient] = {}
        self._workers: dict[int, _NodeWorker] = {}
        self._guard = threading.Lock()
        self._status_listener: StatusListener | None = None
        link.on_state(self._closed_with_link)

    def on_status_word(self, listener: StatusListener) -> None:
        """Call ``listener(node, status_word)`` whenever a station in data exchange sends a new PZD1 status word
        (the bus's drive_state events: a PROFIBUS line has no CAN frames for a bus monitor to watch)."""
        with self._guard:
            self._status_listener = listener
            clients = list(self._clients.items())
        for node, client in clients:
            client.on_status_word(functools.partial(listener, node))

    # -- the SDO engine's interface ------------------------------------------------------------------------------
    def upload(
        self,
        node: int,
        index: int,
        sub: int,
        timeout: float | None = None,
        probe: bool = False,
        convert: Callable[[bytes], object] | None = None,
        bulk: bool = False,
    ) -> Future:
        completion = FutureCompletion(convert)
        self._submit_pkw([_Transfer(node, index, sub, None, timeout or self.timeout, completion)], bulk)
        return completion.future

    def upload_all(
        self,
        node: int,
        objects: Sequence[tuple[int, int]],
        timeout: float | None = None,
        convert: Callable[[int, bytes], R] | None = None,
        on_each: Callable[[int, R | Exception], None] | None = None,
    ) -> TransferBatch[R]:
        seconds = timeout or self.timeout
        batch: TransferBatch[R] = TransferBatch(len(objects), convert, on_each, each=seconds)
        transfers = [_Transfer(node, pnu, ind, None, seconds, batch, slot) for slot, (pnu, ind) in enumerate(objects)]
        self._submit_pkw(transfers, bulk=True)
        return batch

    def download(
        self,
        node: int,
        index: int,
        sub: int,
        data: bytes,
        timeout: float | None = None,
        convert: Callable[[None], object] | None = None,
        bulk: bool = False,
    ) -> Future:
        completion = FutureCompletion(convert)
        self._submit_pkw([_Transfer(node, index, sub, bytes(data), timeout or self.timeout, completion)], bulk)
        return completion.future

    def download_all(
        self,
        node: int,
        writes: Sequence[tuple[int, int, bytes]],
        timeout: float | None = None,
        convert: Callable[[int, None], R] | None = None,
        on_each: Callable[[int, R | Exception], None] | None = None,
    ) -> TransferBatch[R]:
        seconds = timeout or self.timeout
        batch: TransferBatch[R] = TransferBatch(len(writes), convert, on_each, each=max(seconds, PROCEDURE_TIMEOUT))
        transfers = [
            _Transfer(node, pnu, ind, bytes(data), seconds, batch, slot) for slot, (pnu, ind, data) in enumerate(writes)
        ]
        self._submit_pkw(transfers, bulk=True)
        return batch

    def upload_block(self, node: int, index: int, sub: int, *args: Any, **kwargs: Any) -> Future:
        raise refusal(self.profibus.name, "a block upload (the recorder's buffer)")

    # -- queues and workers ----------------------------------------------------------------------------------------
    def _submit_pkw(self, transfers: list[_Transfer], bulk: bool) -> None:
        if not transfers:
            return
        node = transfers[0].node
        if node not in STATIONS:
            raise StationOutOfRange(f"DP station address {node} outside 1..125: nothing was sent")
        if all(transfer.pnu in PROCESS_DATA for transfer in transfers):
            for transfer in transfers:  # their own channel: never behind a parameter request
                self._run(transfer)
            return
        with self._guard:
            worker = self._workers.get(node)
            if worker is None:
                worker = self._workers[node] = _NodeWorker(node, self._run)
        worker.add(transfers, bulk, self.profibus)

    def _run(self, transfer: _Transfer) -> None:
        """Carry out one transfer on the worker thread and report its outcome."""
        if not transfer.completion.start(transfer.slot):
            transfer.completion.done(transfer.slot, CancelledError())
            return
        try:
            outcome: object = self._carry_out(transfer)
        except PkwError as error:
            outcome = PkwRefusal(transfer.node, error)
        except Timeout as error:
            transfer.completion.drive_silent()
            outcome = PkwNoReply(transfer.node, transfer.pnu, transfer.index, _named(transfer, error))
        except ServoStudioError as error:
            transfer.completion.drive_silent()
            outcome = PkwLinkLost(transfer.node, transfer.pnu, transfer.index, _named(transfer, error))
        except ValueError as error:  # raw bytes wider than the PNU (a typed write is checked by `Drive` before)
            outcome = PkwRefusal(transfer.node, PkwError(transfer.pnu, transfer.index, str(error)))
        except Exception as error:  # noqa: BLE001 -- a bug: its caller gets it (internal), the worker goes on
            outcome = error
        transfer.completion.done(transfer.slot, outcome)

    def _carry_out(self, transfer: _Transfer) -> bytes | None:
        client = self._client(transfer.node)
        if transfer.pnu in PROCESS_DATA:  # idempotent too: a read, or the same control word set again
            return _through_recovery(lambda: _process_data(client, transfer), transfer.timeout)
        width = _Width.of(self._parameter(transfer), transfer.data)
        if transfer.data is None:
            request = read_request(transfer.pnu, transfer.index)
            reply = _through_recovery(lambda: client.transaction(request, timeout=transfer.timeout), transfer.timeout)
            value = reply_value(request, reply, double=width.double, signed=width.signed)
            return value.to_bytes(width.size, "little", signed=width.signed)
        value = int.from_bytes(transfer.data, "little", signed=width.signed)
        if width.procedure:
            _run_procedure(client, transfer.pnu, value, max(transfer.timeout, PROCEDURE_TIMEOUT), width.repeatable)
            return None
        request = write_request(transfer.pnu, value, width.double, transfer.index)
        reply = _through_recovery(lambda: client.transaction(request, timeout=transfer.timeout), transfer.timeout)
        reply_value(request, reply, double=width.double, signed=False)
        return None

    def _parameter(self, transfer: _Transfer) -> Parameter | None:
        parameters = self.parameter_list(transfer.node)
        return parameters.parameters.get(transfer.pnu) if parameters is not None else None

    def _client(self, node: int) -> TtaProClient:
        """The node's client, parameterised and exchanging from its first transfer on (an error leaves none)."""
        with self._guard:
            client = self._clients.get(node)
        if client is None:
            client = TtaProClient(self.profibus.master, node)
            listener = self._status_listener
            if listener is not None:
                client.on_status_word(functools.partial(listener, node))
            client.start()
            with self._guard:
                self._clients[node] = client
        return client

    def clients(self) -> dict[int, TtaProClient]:
        """The stations in data exchange with this engine (for the PZD words of a later stage and the tests)."""
        with self._guard:
            return dict(self._clients)

    def _closed_with_link(self, connected: bool, reason: str) -> None:
        if connected or not self.profibus.closed:
            return
        with self._guard:
            workers, self._workers = list(self._workers.values()), {}
            clients, self._clients = list(self._clients.values()), {}
        for worker in workers:
            worker.stop()
        for client in clients:
            client.close()


PROCESS_DATA = (CONTROL_WORD, STATUS_WORD, POSITION_SET_POINT)
SET_POINT_WORDS = (4, 5)
"""PZD5 (most significant word) and PZD6 of the PPO write: the position set point (``POSITION_SET_POINT``)."""


def _process_data(client: TtaProClient, transfer: _Transfer) -> bytes | None:
    """PZD1: the status word in, the control word out (read back as it goes out); PZD5-6: the position set point."""
    if transfer.pnu == POSITION_SET_POINT:
        return _set_point(client, transfer)
    if transfer.pnu == STATUS_WORD:
        if transfer.data is not None:
            raise ValueError("the status word is the drive's: it cannot be written")
        return client.current_input(0, transfer.timeout).to_bytes(2, "little")
    if transfer.data is None:
        return client.output(0).to_bytes(2, "little")
    client.send_output(0, int.from_bytes(transfer.data, "little"), transfer.timeout)
    return None


def _set_point(client: TtaProClient, transfer: _Transfer) -> bytes | None:
    """Both words go out in the images after the call; it returns once a Data_Exchange carried the second (a move
    is triggered only after that, so the drive never starts on half a set point)."""
    high, low = SET_POINT_WORDS
    if transfer.data is None:
        return join_double(client.output(high), client.output(low)).to_bytes(4, "little", signed=True)
    upper, lower = split_double(int.from_bytes(transfer.data, "little", signed=True))
    client.set_output(high, upper)
    client.send_output(low, lower, transfer.timeout)
    return None


def _named(transfer: _Transfer, error: Exception) -> str:
    """The error's text with the PNU it concerns in front (the client's own errors name it, or their PZD word)."""
    text = str(error)
    return text if text.startswith(("PNU ", "PZD")) else f"PNU {transfer.pnu}: {text}"


def _run_procedure(client: TtaProClient, pnu: int, value: int, timeout: float, repeatable: bool) -> None:
    """A procedure the parameter list calls repeatable (a copy, a save) is run again after a lost exchange like a
    value write; any other (auto-phasing, auto-tuning: they move the motor) runs once per request, whatever happens."""
    run = functools.partial(client.run_procedure, pnu, value, timeout)
    if repeatable:
        _through_recovery(run, timeout)
    else:
        run()


def _through_recovery(transaction: Callable[[], T], patience: float) -> T:
    """A read or a value write whose station left data exchange meanwhile is sent again once the cyclic exchange
    has parameterised it again (within ``patience`` seconds of the loss): the request is idempotent (a read, or the
    same value written again), and one dropped exchange should not fail an 80-parameter backup."""
    deadline = time.monotonic() + patience
    while True:
        try:
            return transaction()
        except ProfibusLinkDown:
            if time.monotonic() >= deadline:
                raise
            time.sleep(RECOVERY_POLL)


@dataclass(frozen=True)
class _Width:
    """How a PNU travels: word or double word, signed or not, and whether a write starts a procedure."""

    double: bool
    signed: bool
    procedure: bool = False
    repeatable: bool = False

    @property
    def size(self) -> int:
        return 4 if self.double else 2

    @classmethod
    def of(cls, parameter: Parameter | None, data: bytes | None) -> _Width:
        """From the parameter list; a PNU it does not list travels as the bytes given (a read: an unsigned word)."""
        if parameter is None:
            return cls(double=data is not None and len(data) > 2, signed=False)
        signed = parameter.data_type in (DataType.INTEGER16, DataType.INTEGER32)
        return cls(parameter.is_double, signed, parameter.procedure, parameter.repeatable)


class _NodeWorker:
    """One thread per station: interactive transfers first, the bulk lane behind them, one at a time."""

    def __init__(self, node: int, run: Callable[[_Transfer], None]) -> None:
        self._run = run
        self._lanes: NodeLanes[_Transfer] = NodeLanes()
        self._condition = threading.Condition()
        self._stopped = False
        self._thread = threading.Thread(target=self._loop, name=f"pkw-node-{node}", daemon=True)
        self._thread.start()

    def add(self, transfers: list[_Transfer], bulk: bool, link: BusLink) -> None:
        with self._condition:
            stopped = self._stopped or link.closed
            if not stopped:
                self._lanes.add(transfers, bulk)
                self._condition.notify()
        if stopped:
            _closed(transfers)

    def stop(self) -> None:
        """End the thread; the transfers still queued end with `PkwLinkLost` (the bus was closed)."""
        with self._condition:
            self._stopped = True
            left = self._lanes.drain()
            self._condition.notify()
        _closed(left)
        if self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)

    def _loop(self) -> None:
        while (transfer := self._next()) is not None:
            self._run(transfer)

    def _next(self) -> _Transfer | None:
        with self._condition:
            self._condition.wait_for(lambda: self._stopped or bool(self._lanes))
            return None if self._stopped else self._lanes.next()


def _closed(transfers: list[_Transfer]) -> None:
    """Transfers the closed bus will never carry out: each ends at once, as on the SDO engine's closed link."""
    for transfer in transfers:
        started = transfer.completion.start(transfer.slot)
        closed = PkwLinkLost(transfer.node, transfer.pnu, transfer.index, "the bus was closed")
        transfer.completion.done(transfer.slot, closed if started else CancelledError())
