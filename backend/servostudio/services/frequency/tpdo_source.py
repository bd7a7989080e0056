"""The response of a drive without a recorder (CD1-k, encoTRive, any CiA 402 drive): synchronous TPDOs answered to
the SYNCs that carry the excitation (docs/frequency-response.md §8).

One SYNC producer (``stream.ExcitationStream``'s) does both: just before SYNC k it sends excitation value k by RPDO,
and the drive answers SYNC k with its TPDOs, so sample k of the response is the drive at SYNC k.  The response is
the actual position, the target velocity as the drive holds it (the excitation it applied) and the current actual
value; the TPDOs are borrowed as a scope capture borrows them (``scope.stream.TpdoStream``: saved first, written
back whatever happens).

**Latency.** CiA 301: a synchronous RPDO's data takes effect at the SYNC after its reception — here the SYNC it was
sent just before —, and a synchronous TPDO carries what the drive has at the SYNC.  So the target read back at SYNC
k is value k (the simulator applies a SYNC's RPDOs before it answers the TPDOs; a drive that samples first shows it
at k + 1, found from the data: ``latency``), held until SYNC k + 1, while the position of SYNC k is where the
earlier values brought the shaft: value k acts on the response from sample k + 1 on, one SYNC later.  The input's
line is therefore that of the staircase the drive holds, ``U·(1 − e^{−jθ})/(jθ)`` with θ = 2π·h/N — exact for a
value held from its SYNC to the next, with neither a sample's lead nor a hold's droop left in the response.

**Bus budget.** Per SYNC: the SYNC, the excitation's RPDO and the response's TPDOs, each with its worst-case bits
(``stream_plan.frame_bits``); above ``MAX_BUS_LOAD`` (70 %) of the bit rate the measurement is refused before
anything is written, as a roll is.
"""

from __future__ import annotations

import cmath
import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.tpdo import PDO_BYTES
from servostudio.errors import CommunicationError
from servostudio.od.model import Variable
from servostudio.services.frequency import estimate
from servostudio.services.frequency.timed import DriveClock
from servostudio.services.scope.definition import CaptureDefinition
from servostudio.services.scope.plan import CaptureRefused
from servostudio.services.scope.stream import TpdoStream, _Receiver
from servostudio.services.scope.stream_plan import MAX_BUS_LOAD, Bus, StreamPlan, frame_bits, plan_stream

#: the response's objects, in the order of its columns (the current only where the drive names it)
RESPONSE = ("position_actual", "target_velocity", "current_actual")
#: how many SYNCs after it was applied a value may show in the read-back target at most (a drive that samples its
#: TPDOs before it applies the SYNC's RPDO shows it one SYNC later)
MAX_LATENCY = 2
#: the last sample is the watch's reading while it is at most this old
FRESH_S = 0.1
#: the share of the read-back samples that must equal the values sent (a value lost on the bus costs coherence)
AGREEING = 0.9


class BusTooSlow(CaptureRefused):
    """The excitation and the response at the SYNC rate would take more of the bus than a measurement may."""


class NotApplied(CommunicationError):
    """The target read back is not the excitation at any fixed delay: the drive did not apply the values at their
    SYNCs (frames lost or late, or a drive whose cycle does not follow the SYNC), and no estimate is made."""


@dataclass(frozen=True)
class ResponsePlan:
    """The TPDOs the response borrows and what the measurement puts on the bus."""

    stream: StreamPlan
    names: tuple[str, ...]
    frames_per_s: float
    bus_load: float
    bitrate: int

    def describe(self) -> dict[str, object]:
        return {"frames_per_s": round(self.frames_per_s, 1), "bus_load": round(self.bus_load, 4),
                "bitrate": self.bitrate, "tpdos": [use.slot.number + 1 for use in self.stream.tpdos]}  # fmt: skip


def plan_response(drive: Drive, excited: Variable, bitrate: int | None, period_s: float, current: bool) -> ResponsePlan:
    """The TPDOs of the response (packed as a scope capture packs its channels) and the bus load of the SYNC, the
    RPDO and the TPDOs every ``period_s``; refused (nothing written) beyond ``MAX_BUS_LOAD``."""
    names = tuple(name for name in RESPONSE if name != "current_actual" or current)
    definition = CaptureDefinition(channels=names, period_us=1000.0, samples=2, source="tpdo")
    plan = plan_stream(drive, lambda node: drive, definition, Bus(bitrate), "tpdo")
    sizes = [sum(plan.channels[n].size for n in use.channels) for use in plan.tpdos]
    bits = frame_bits(0) + frame_bits(min(PDO_BYTES, excited.data_type.fixed_size)) + sum(map(frame_bits, sizes))
    rate = Bus(bitrate).rate
    load = bits / period_s / rate
    if load > MAX_BUS_LOAD:
        raise BusTooSlow(
            f"the excitation by RPDO and the response in {len(sizes)} TPDOs take {bits} bits per SYNC, every "
            f"{period_s * 1e6:g} µs {load:.0%} of {rate / 1e6:g} Mbit/s (at most {MAX_BUS_LOAD:.0%}): the drive's "
            "bus is too slow for the measurement"
        )
    return ResponsePlan(plan, names, (len(sizes) + 2) / period_s, load, rate)


@dataclass
class _Timed(_Receiver):
    """A TPDO's frames, when each arrived here, and when the drive sent it by its own clock: the frame's time stamp
    (the CAN adapter's; the simulator's virtual instant) less the frame's time on the wire at ``bitrate``."""

    instants: list[float] = field(default_factory=list)
    stamps: list[float] = field(default_factory=list)
    bitrate: int = 1_000_000
    clock: DriveClock = field(default_factory=DriveClock)

    def on_frame(self, cob_id: int, data: bytes, timestamp: float) -> None:
        if len(data) == self.layout.size:
            arrived = time.monotonic()
            stamp = timestamp - frame_bits(len(data)) / self.bitrate
            self.instants.append(arrived)
            self.stamps.append(stamp)
            self.clock.answered(stamp, arrived)
            self.frames.append(bytes(data))


class ResponseStream(TpdoStream):
    """The response's TPDOs: borrowed, mapped, answered at every SYNC of the excitation's producer; written back."""

    def __init__(self, plan: ResponsePlan, drive: Drive, link: BusLink) -> None:
        super().__init__(plan.stream, lambda node: drive, link)
        self.names = plan.names
        #: the drive's time, from its answers' stamps (the excitation of a drive whose cycle free-runs follows it)
        self.clock = DriveClock()
        self.timed = [_Timed(receiver.use, receiver.layout, bitrate=plan.bitrate, clock=self.clock)
                      for receiver in self.receivers]  # fmt: skip
        self.receivers = [*self.timed]

    def _announce_cycle(self) -> None:
        """Nothing: the excitation's stream announced the SYNC period in 0x1006 already (``frequency.stream``), and
        this plan's nominal period is not the SYNC's."""

    def open(self) -> None:
        """Save and map the TPDOs, subscribe, and drop any answer to the probe SYNC (sample 0 answers SYNC 0)."""
        self._configure()
        for receiver in self.timed:
            del receiver.instants[: len(receiver.instants) - len(receiver.frames)]
            del receiver.stamps[: len(receiver.stamps) - len(receiver.frames)]

    def stalled(self, first: int, last: int, longest_s: float) -> bool:
        """Did the answers to two of SYNCs ``first`` … ``last`` arrive more than ``longest_s`` apart (a drive or bus
        held up, or a simulator whose thread was; the SYNC instants alone do not show it)?"""
        for receiver in self.timed:
            instants = receiver.instants[max(first, 0) : last + 1]
            if any(later - earlier > longest_s for earlier, later in itertools.pairwise(instants)):
                return True
        return False

    def answered(self) -> int:
        return self._answered()

    def latest(self) -> dict[str, object] | None:
        """The last sample by object name: what the watch checks while the response runs, without SDO requests
        between the SYNCs (a frame in the way delays a SYNC); None before the first and once the answers stop
        (``FRESH_S``: the watch then reads by SDO)."""
        count = self.answered()
        if count == 0 or min(receiver.instants[count - 1] for receiver in self.timed) < time.monotonic() - FRESH_S:
            return None
        return {name: column[0] for name, column in zip(self.names, self._columns(count - 1, count), strict=True)}

    def columns(self, first: int, count: int) -> list[list[float]]:
        """Samples ``first`` … ``first + count − 1``, one column per response object."""
        return [list(map(float, column)) for column in self._columns(first, first + count)]

    def sync_instants(self, first: int, count: int) -> list[float]:
        """When the drive took SYNCs ``first`` … ``first + count − 1`` by its own clock: the earliest of its answers'
        start of transmission (the first TPDO leaves as the SYNC ends)."""
        return [min(receiver.stamps[k] for receiver in self.timed) for k in range(first, first + count)]

    def close(self) -> str | None:
        """The TPDOs written back and unsubscribed (each tried); what failed, or None."""
        return self._restore()


def latency(readback: list[float], sent: Callable[[int], int], first: int) -> int:
    """SYNCs from a value's application to its read-back (0: the drive answers with the value of the SYNC it
    applied it at), found from the data: the delay at which the read-back target is the value sent."""
    matches = [sum(value == sent(first + k - delay) for k, value in enumerate(readback)) for delay in
               range(MAX_LATENCY + 1)]  # fmt: skip
    delay = max(range(MAX_LATENCY + 1), key=matches.__getitem__)
    if matches[delay] < AGREEING * len(readback):
        raise NotApplied(
            f"the target velocity read back is not the excitation sent ({matches[delay]} of {len(readback)} "
            f"samples at the best delay, {delay} SYNCs): the drive did not apply the RPDO at its SYNC"
        )
    return delay


def held_input(lines: list[estimate.Lines], harmonics: list[int], block: int, delay: int) -> list[estimate.Lines]:
    """The line of the staircase a read-back value starts at its sample and holds for a SYNC, ``delay`` samples
    earlier than it shows: ``U·e^{jθ·delay}·(1 − e^{−jθ})/(jθ)`` (θ = 2π·h/block), exact for a periodic staircase."""
    factors = []
    for harmonic in harmonics:
        theta = 2.0 * math.pi * harmonic / block
        factors.append(cmath.exp(1j * theta * delay) * (1.0 - cmath.exp(-1j * theta)) / (1j * theta))
    return [[value * factor for value, factor in zip(row, factors, strict=True)] for row in lines]
