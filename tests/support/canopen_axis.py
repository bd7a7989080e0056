"""The acceptance peer's axis: a simulated XtrapulsPac as the independent `canopen` library sees it
(`BaseNode402` with the built-in EDS, as an integrator's script would), its control and status word bits, and
bounded waits that fail with the last status word seen, so a stuck drive gives a readable failure instead of a
hanging suite."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from canopen.profiles.p402 import BaseNode402, State402
from tests.support.waits import wait_for

from servostudio.od.library import BUILTIN_EDS_DIR

XTRAPULSPAC_EDS = str(Path(BUILTIN_EDS_DIR) / "xtrapulspac.eds")
NODE_ID = 1
REV = 4096  # user units per motor revolution (0x6093 at its default 1:1)
WAIT = 10.0  # s of wall clock for any single wait (the host may be loaded; virtual time then slips)

CW_ENABLE_OPERATION = 0x0F
CW_NEW_SET_POINT = 1 << 4
CW_CHANGE_IMMEDIATELY = 1 << 5
CW_RELATIVE = 1 << 6
STATUS_TARGET_REACHED = 1 << 10
STATUS_SET_POINT_ACK = 1 << 12  # PP: set-point acknowledge; HM: homing attained; PV: speed = 0
SYNC_PERIOD = 0.01  # s, SYNC produced by the peer


def state_of(status_word: int) -> str:
    """The CiA 402 state a status word shows (canopen's own masks, so the peer and the test agree)."""
    for state, (mask, bits) in State402.SW_MASK.items():
        if status_word & mask == bits:
            return state
    return "UNKNOWN"


@dataclass(frozen=True)
class Sample:
    """One event-driven TPDO 4: the status word and the position actual the drive sampled with it."""

    status: int
    position: int

    @property
    def state(self) -> str:
        return state_of(self.status)


class Axis:
    """A `BaseNode402` on the bus plus the trace of every status word change (TPDO 4, with 0x6064)."""

    def __init__(self, node: BaseNode402) -> None:
        self.node = node
        self.trace: list[Sample] = []
        self._trace_lock = threading.Lock()
        node.tpdo[4].add_callback(self._record)

    def _record(self, pdo_map) -> None:
        with self._trace_lock:
            self.trace.append(Sample(int(pdo_map[0].raw), int(pdo_map[1].raw)))

    def samples_since(self, mark: int) -> list[Sample]:
        """The samples received after `mark` (an earlier `len(trace)`)."""
        with self._trace_lock:
            return self.trace[mark:]

    def states_since(self, mark: int) -> list[str]:
        """The states of the status words received after `mark`, repeats collapsed."""
        states: list[str] = []
        for sample in self.samples_since(mark):
            if not states or states[-1] != sample.state:
                states.append(sample.state)
        return states

    def first_sample(self, mark: int, condition: Callable[[Sample], bool], what: str) -> Sample:
        for sample in self.samples_since(mark):
            if condition(sample):
                return sample
        raise AssertionError(f"node {self.node.id}: no status word with {what} in the trace")

    @property
    def status(self) -> int:
        return int(self.node.statusword)

    def write(self, index: int, value: int, sub: int | None = None) -> None:
        """SDO download of one object (`sub` None for a simple variable)."""
        (self.node.sdo[index] if sub is None else self.node.sdo[index][sub]).raw = value

    def read(self, index: int, sub: int | None = None) -> int:
        return int((self.node.sdo[index] if sub is None else self.node.sdo[index][sub]).raw)

    def wait_status(self, condition: Callable[[int], bool], what: str, timeout: float = WAIT) -> int:
        """Wait until the last received status word satisfies `condition`; fail naming `what` otherwise."""
        return wait_for(
            lambda: self.status,
            condition,
            f"node {self.node.id}: {what}",
            timeout,
            describe=lambda status: f"last status word 0x{status:04X} ({state_of(status)})",
        )

    def wait_value(self, index: int, condition: Callable[[int], bool], what: str, timeout: float = WAIT) -> int:
        """Poll an object by SDO until `condition` holds; fail naming `what` and the last value otherwise."""
        return wait_for(
            lambda: self.read(index),
            condition,
            f"node {self.node.id}: {what}",
            timeout,
            0.01,
            lambda value: f"0x{index:04X} = {value}",
        )

    def wait_state(self, state: str, timeout: float = WAIT) -> int:
        return self.wait_status(lambda status: state_of(status) == state, f"state {state}", timeout)

    def command(self, control_word: int, state: str, timeout: float = WAIT) -> int:
        """Send a control word (RPDO 1, as BaseNode402 does) and wait for the state it must lead to."""
        self.node.controlword = control_word
        return self.wait_state(state, timeout)

    def settle(self) -> None:
        """Let the drive sample the last control word before the next one: it reads the control word once per
        control period, so two RPDOs in the same period would hide a pulse.

        An SDO read first is the barrier: its answer comes after the drive took the RPDO off the bus (one stream,
        in order), so the two SYNC status words after it answer SYNCs the drive ran its control periods up to
        with that control word. Status words alone are not enough on a loaded host: both may answer SYNCs that
        were queued before the RPDO, and the next RPDO then lands in the same period (CI lost a set-point so)."""
        self.read(0x6041)
        self.node.check_statusword()
        self.node.check_statusword()

    def move(self, target: int, relative: bool = False, until: str = "target reached (SW10)") -> None:
        """One PP set-point: 0x607A, CW4 rising (with CW5 change immediately), SW12 acknowledges without SW10,
        CW4 falls, SW12 clears, SW10 reports the end."""
        self.write(0x607A, target)
        bits = CW_CHANGE_IMMEDIATELY | (CW_RELATIVE if relative else 0)
        self.node.controlword = CW_ENABLE_OPERATION | bits  # CW4 low first, so the next write is a rising edge
        self.settle()
        self.node.controlword = CW_ENABLE_OPERATION | bits | CW_NEW_SET_POINT
        status = self.wait_status(lambda s: s & STATUS_SET_POINT_ACK, "set-point acknowledge (SW12)")
        assert not status & STATUS_TARGET_REACHED, f"target reached already with the acknowledge: 0x{status:04X}"
        self.node.controlword = CW_ENABLE_OPERATION | bits
        self.wait_status(lambda s: not s & STATUS_SET_POINT_ACK, "acknowledge cleared after CW4 = 0")
        self.wait_status(lambda s: s & STATUS_TARGET_REACHED, until)

    def wait_standstill(self, timeout: float = WAIT) -> int:
        """Wait until 0x6064 stops changing (two SDO reads 50 ms apart within 2 user units); the position."""
        deadline = time.monotonic() + timeout
        position = self.read(0x6064)
        while True:
            time.sleep(0.05)
            latest = self.read(0x6064)
            if abs(latest - position) <= 2:
                return latest
            if time.monotonic() > deadline:
                raise AssertionError(f"node {self.node.id}: still moving after {timeout} s (0x6064 = {latest})")
            position = latest

    def go(self, state: str) -> None:
        """Walk with canopen's own state machine helper and check the status word afterwards."""
        self.node.state = state
        assert state_of(self.status) == state, f"BaseNode402 reports {self.node.state}, status 0x{self.status:04X}"

    def set_mode(self, mode: str) -> None:
        self.node.op_mode = mode  # canopen logs (does not raise) a refused switch: check what the drive shows
        assert self.node.op_mode == mode, f"0x6061 shows {self.node.op_mode}, expected {mode}"


def configure_pdos(node: BaseNode402) -> None:
    """The TPDO set-up an integrator makes for BaseNode402, by SDO in PRE-OPERATIONAL (docs/simulator.md).

    TPDO 1 = status word + mode display, sent at every SYNC: BaseNode402 waits for a fresh status word after each
    command, which an event-driven TPDO cannot guarantee once canopen has measured a period for it. TPDO 4 =
    status word + position actual, event-driven: every change, including states that last less than a SYNC
    period, with the position the drive had at that instant.
    """
    node.tpdo.read()
    states = node.tpdo[1]
    states.clear()
    states.add_variable(0x6041)
    states.add_variable(0x6061)
    states.trans_type = 1
    states.enabled = True
    changes = node.tpdo[4]
    changes.clear()
    changes.add_variable(0x6041)
    changes.add_variable(0x6064)
    changes.trans_type = 255
    changes.enabled = True
    node.tpdo.save()
