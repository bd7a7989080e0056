"""The trigger of a triggered recorder capture of several axes, carried from drive to drive (docs/scope.md §7).

The trigger drive's recorder triggers on its own channel; its recorder status (0x5829, PDO-mappable) goes out in one
of its TPDOs, event-driven (transmission type 255: sent in the control period the status changes, no inhibit time,
no event timer), and every other drive receives that frame in an RPDO applied on reception, mapped onto its
recorder's *trigger relay* object (the profile's ``trigger_relay``: the XtrapulsPac's 0x23A0, which acts on nothing
while no TPDO uses transmission type 254 at a SYNC). Their recorders trigger on the relay rising through the status
code of "recording": the control period after the trigger drive's, so their pre-trigger is one sample longer and
every recording covers the same control periods.

Everything borrowed — the TPDO (with its inhibit time and event timer), each RPDO, each relay object's value — is
read first and written back afterwards, whatever happened; nodes started for the PDOs (they act only in OPERATIONAL)
are put back to PRE-OPERATIONAL.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.drive.rpdo import APPLY_ON_RECEPTION, RpdoConfig, last_rpdo, mapped, read_rpdo, write_rpdo
from servostudio.drive.tpdo import (
    COB_ID_INVALID,
    TpdoConfig,
    TpdoSlot,
    mapping_entry,
    read_tpdo,
    tpdo_slots,
    write_tpdo,
)
from servostudio.errors import ServoStudioError
from servostudio.services.scope.plan import CaptureRefused, recorder_of

#: CiA 301 event-driven transmission: the TPDO is sent when its data changes
ON_CHANGE = 255
#: the TPDO's inhibit time (sub 3) and event timer (sub 5): zero while it relays, so no status change waits
TIMING_SUBS = (3, 5)
#: the relayed status frame carries one byte; the records the followers' trigger lags the trigger drive's
RELAY_DELAY = 1


def relay_slot(drive: Drive) -> TpdoSlot:
    """The trigger drive's TPDO that carries its recorder status (the highest-numbered one), or the refusal."""
    slots = tpdo_slots(drive.dictionary) if drive.dictionary is not None else []
    status = drive.variable(recorder_of(drive).address("status"))
    if not slots or not status.pdo_mappable:
        raise CaptureRefused(f"node {drive.node}: its recorder status cannot be sent in a TPDO, so the other axes' "
                             "recorders cannot follow its trigger")  # fmt: skip
    return slots[-1]


def relay_object(drive: Drive) -> tuple[int, int]:
    """A follower's relay object, or the refusal naming why the drive cannot follow another drive's trigger."""
    recorder = recorder_of(drive)
    if "trigger_relay" not in recorder.objects:
        raise CaptureRefused(f"node {drive.node}: its recorder has no object an RPDO can set for it to trigger on, "
                             "so it cannot follow another axis's trigger")  # fmt: skip
    try:
        last_rpdo(drive)
    except ServoStudioError as error:
        raise CaptureRefused(f"{error}: it cannot receive the trigger drive's status") from None
    return recorder.address("trigger_relay")


@dataclass
class _Borrowed:
    """A follower's RPDO and relay value as they were."""

    drive: Drive
    rpdo: RpdoConfig
    relay: tuple[int, int]
    value: int


class TriggerRelay:
    """The trigger drive's TPDO and the followers' RPDOs that carry its trigger, and putting them back."""

    def __init__(self, trigger: Drive, followers: list[Drive], link: BusLink,
                 operational: Callable[[int], bool]) -> None:  # fmt: skip
        self.trigger, self.followers, self.link, self.operational = trigger, followers, link, operational
        self.tpdo: TpdoConfig | None = None
        self.timing: dict[int, int] = {}
        self.borrowed: list[_Borrowed] = []
        self.started: list[int] = []

    def open(self) -> None:
        """Map the status TPDO and the followers' RPDOs (their relay objects 0 first), start the nodes that are not
        OPERATIONAL. ``restore`` follows in any case."""
        identifier = self._map_trigger()
        for drive in self.followers:
            self._map_follower(drive, identifier)
        nodes = [self.trigger, *self.followers]
        self.started = [drive.node for drive in nodes if not self.operational(drive.node)]
        for node in self.started:
            send_nmt(self.link, NmtCommand.START, node)

    def _map_trigger(self) -> int:
        drive = self.trigger
        slot = relay_slot(drive)
        self.tpdo = saved = read_tpdo(drive, slot)
        self.timing = {sub: _integer(drive, (slot.communication, sub)) for sub in self._timing_subs(slot)}
        _set_timing(drive, saved, dict.fromkeys(self.timing, 0))
        status = drive.variable(recorder_of(drive).address("status"))
        write_tpdo(drive, TpdoConfig(slot, saved.identifier, ON_CHANGE, (mapping_entry(status),), 1))
        return saved.identifier

    def _timing_subs(self, slot: TpdoSlot) -> list[int]:
        dictionary = self.trigger.dictionary
        return [sub for sub in TIMING_SUBS if dictionary is not None and dictionary.get(slot.communication, sub)]

    def _map_follower(self, drive: Drive, identifier: int) -> None:
        relay = relay_object(drive)
        saved = read_rpdo(drive, last_rpdo(drive))
        self.borrowed.append(_Borrowed(drive, saved, relay, _integer(drive, relay)))
        drive.write(relay, 0)
        write_rpdo(drive, mapped(saved.number, identifier, [drive.variable(relay)], APPLY_ON_RECEPTION))

    def restore(self) -> str:
        """Every borrowed PDO and relay value back, the started nodes back to PRE-OPERATIONAL (each tried); what
        could not be done, as the end of the capture's note ("" when all was)."""
        # the followers stop listening first: the TPDO's own content, once back, is no relay value
        failures = [*(failure for each in self.borrowed for failure in _restore(each)), *self._restore_trigger()]
        for node in self.started:
            try:
                send_nmt(self.link, NmtCommand.PRE_OPERATIONAL, node)
            except ServoStudioError as error:
                failures.append(f"node {node} left OPERATIONAL: {error}")
        return "".join(f"; {failure}" for failure in failures)

    def _restore_trigger(self) -> list[str]:
        if self.tpdo is None:
            return []
        drive, slot = self.trigger, self.tpdo.slot
        try:
            _set_timing(drive, self.tpdo, self.timing)
            write_tpdo(drive, self.tpdo)
        except ServoStudioError as error:
            return [f"node {drive.node} TPDO {slot.number + 1} left mapped with the recorder status: {error}"]
        return []


def _restore(borrowed: _Borrowed) -> list[str]:
    drive = borrowed.drive
    try:
        write_rpdo(drive, borrowed.rpdo)
        drive.write(borrowed.relay, borrowed.value)
    except ServoStudioError as error:
        return [f"node {drive.node} RPDO {borrowed.rpdo.number + 1} left mapped with the trigger relay: {error}"]
    return []


def _set_timing(drive: Drive, config: TpdoConfig, values: dict[int, int]) -> None:
    """The TPDO's inhibit time and event timer, written while it is invalid (CiA 301 refuses them on a valid one);
    ``write_tpdo`` makes it valid again."""
    if values:
        drive.write((config.slot.communication, 1), config.cob_id | COB_ID_INVALID)
    for sub, value in values.items():
        drive.write((config.slot.communication, sub), value)


def _integer(drive: Drive, key: tuple[int, int]) -> int:
    value = drive.read(key).raw
    assert isinstance(value, int)
    return value
