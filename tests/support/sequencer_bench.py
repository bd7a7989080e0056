"""The sequencer bench: the sequencer seen from outside, one real-time simulated XtrapulsPac and an independent
`canopen` peer on the in-process bus, plus a probe on the simulator's thread.

The peer does everything a tool would: it writes SEQUENCE.TXT into the drive's flash directory and loads it with
`lseq` (or writes 0x3610/0x3611 by SDO), selects sequence mode, enables, starts with control word bit 4, and
watches the executed sequence number 0x3601,2 with the phase 0x3605 on an event-driven TPDO 2 (sent in the
control period the number changes, with the virtual time stamp). The probe is the reference for timing: it reads
chosen objects after every control period, through the same hooks a bus read uses.
"""

from __future__ import annotations

import struct
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import canopen
from tests.support.waits import wait_for

from servostudio.od.library import BUILTIN_EDS_DIR
from servostudio.sim.drive import make_behaviour
from servostudio.sim.flash import LOAD_SEQUENCES
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.node import SimulatedNode
from servostudio.sim.plant import Plant

XTRAPULSPAC_EDS = str(Path(BUILTIN_EDS_DIR) / "xtrapulspac.eds")
NODE_ID = 1
REV = 4096  # user units per motor revolution (0x6093 at its default)
AFTER_END = 8
"""Control periods (2 ms) of rows `wait_program_end` waits for after a program's end."""
WAIT = 10.0  # s of wall clock for any wait (a loaded host slows virtual time down)
SEQUENCE_MODE = -3
CW_ENABLE_OPERATION = 0x0F
CW_START = 1 << 4
CW_STOP = 1 << 5
SIM_PHYSICAL_INPUTS = 0x5F00

Key = tuple[int, int]
EXECUTED, PHASE, OUTPUTS, DEDICATED = (0x3601, 2), (0x3605, 0), (0x3602, 1), (0x3602, 3)
POSITION, VELOCITY, CURRENT, STATUS_WORD, CAPTURED = (0x6064, 0), (0x606C, 0), (0x6078, 0), (0x6041, 0), (0x360B, 0)
BEGIN, CRUISE, DECEL, HOLD, INPOS, END = (1 << n for n in range(6))


@dataclass(frozen=True)
class Row:
    """The probe's values after one control period."""

    time: float
    values: dict[Key, int]

    def __getitem__(self, key: Key) -> int:
        return self.values[key]


class Probe:
    """Values of `keys` after every control period of one node (installed and read under the network lock)."""

    def __init__(self, node: SimulatedNode, keys: Sequence[Key]) -> None:
        self.rows: list[Row] = []
        variables = [node.store.od[key] for key in keys]
        read, clock, step = node.store.read_value, node.clock, node.step

        def probed_step(dt: float) -> None:
            step(dt)
            self.rows.append(Row(clock.now, {var.key: int(read(var)) for var in variables}))

        node.step = probed_step  # type: ignore[method-assign]


@dataclass(frozen=True)
class Change:
    """One TPDO 2: the executed sequence number and the phase, stamped with the drive's (virtual) time."""

    time: float
    number: int
    phase: int


class Bench:
    """The drive, its canopen peer and the probe."""

    def __init__(self, network: SimulatedNetwork, state_dir: Path, probe_keys: Sequence[Key]) -> None:
        self.network = network
        self.flash_dir = state_dir / f"node{NODE_ID}"
        self.client = canopen.Network(network.open_bus())
        self.client.NOTIFIER_CYCLE = 0.1
        self.client.connect()
        self.node = canopen.RemoteNode(NODE_ID, XTRAPULSPAC_EDS)
        self.node.sdo.RESPONSE_TIMEOUT = 5.0
        self.client.add_node(self.node)
        self.changes: list[Change] = []
        self._lock = threading.Lock()
        with network.lock:
            self.probe = Probe(network.node(NODE_ID), [EXECUTED, PHASE, OUTPUTS, DEDICATED, *probe_keys])
        self._watch_sequence_number()

    def _watch_sequence_number(self) -> None:
        """TPDO 2 = 0x3601,2 + 0x3605, event-driven (sent whenever the number changes), set up in PRE-OPERATIONAL."""
        pdos = self.node.tpdo
        pdos.read()
        watch = pdos[2]
        watch.clear()
        watch.add_variable(0x3601, 2)
        watch.add_variable(0x3605)
        watch.trans_type = 255
        watch.enabled = True
        pdos.save()
        watch.add_callback(self._changed)
        self.node.nmt.state = "OPERATIONAL"

    def _changed(self, pdo_map) -> None:
        with self._lock:
            self.changes.append(Change(pdo_map.timestamp, int(pdo_map[0].raw), int(pdo_map[1].raw)))

    def close(self) -> None:
        self.client.disconnect()

    # -- access ---------------------------------------------------------------------------------------------------

    def write(self, index: int, value: int, sub: int = 0) -> None:
        variable = self.node.sdo[index] if sub == 0 and not self._has_subs(index) else self.node.sdo[index][sub]
        variable.raw = value

    def read(self, index: int, sub: int = 0) -> int:
        variable = self.node.sdo[index] if sub == 0 and not self._has_subs(index) else self.node.sdo[index][sub]
        return int(variable.raw)

    def _has_subs(self, index: int) -> bool:
        return not isinstance(self.node.object_dictionary[index], canopen.objectdictionary.ODVariable)

    def set_physical_inputs(self, bits: int) -> None:
        """The simulator-only 0x5F00 (no EDS entry: a raw SDO download, as the tool's --sim-inputs does)."""
        self.node.sdo.download(SIM_PHYSICAL_INPUTS, 0, struct.pack("<H", bits))

    def write_record(self, number: int, record: dict[int, int]) -> None:
        """One sequence by direct access: 0x3610 selects it, 0x3611,1..26 hold it."""
        self.write(0x3610, number)
        for sub, value in sorted(record.items()):
            self.write(0x3611, value, sub)

    def read_record(self, number: int) -> dict[int, int]:
        self.write(0x3610, number)
        return {sub: self.read(0x3611, sub) for sub in range(1, 27)}

    def load_program(self, text: str) -> None:
        """SEQUENCE.TXT into the drive's flash, then LOAD (`lseq`) into the sequence memory."""
        self.flash_dir.mkdir(parents=True, exist_ok=True)
        (self.flash_dir / "SEQUENCE.TXT").write_text(text, encoding="latin-1")
        self.procedure(0x1011, LOAD_SEQUENCES)

    def procedure(self, index: int, code: int) -> int:
        """Write a signature to `index`,1 and wait for its status to leave "running" (decisions.md §4)."""
        self.write(index, code, 1)
        return wait_for(lambda: self.read(index, 1), lambda status: status != 2, f"0x{index:04X},1 finished")

    # -- motion ---------------------------------------------------------------------------------------------------

    def enable_sequence_mode(self) -> None:
        self.write(0x6060, SEQUENCE_MODE)
        for control_word in (0x06, 0x07, CW_ENABLE_OPERATION):
            self.write(0x6040, control_word)
        wait_for(lambda: self.read(0x6041), lambda status: status & 0x6F == 0x27, "Operation Enabled")

    def start(self, number: int) -> int:
        """0x3601,1 = number, then a rising edge of control word bit 4; the mark to read changes from."""
        self.write(0x3601, number, 1)
        self.write(0x6040, CW_ENABLE_OPERATION)
        mark = len(self.rows())
        self.write(0x6040, CW_ENABLE_OPERATION | CW_START)
        return mark

    def stop(self) -> None:
        self.write(0x6040, CW_ENABLE_OPERATION | CW_STOP)

    def wait_program_end(self, mark: int, timeout: float = WAIT) -> list[Row]:
        """The probe's rows from `mark` until no program runs any more (0x3601,2 back to −1 after a start), and
        `AFTER_END` control periods more: what the drive publishes after the end (its status word every 1 ms) is
        in the rows, however late this thread looked."""

        def ended() -> bool:
            numbers = [row[EXECUTED] for row in self.rows(mark)]
            started = next((n for n, number in enumerate(numbers) if number >= 0), None)
            if started is None or numbers[-1] != -1:
                return False
            end = next(n for n in range(started, len(numbers)) if numbers[n] == -1)
            return len(numbers) > end + AFTER_END

        wait_for(lambda: int(ended()), bool, "the end of the program", timeout)
        return self.rows(mark)

    def run_for(self, seconds: float) -> None:
        """Let the drive run `seconds` of virtual time (a loaded host makes that longer in wall-clock time)."""
        until = self.network.now + seconds
        wait_for(lambda: int(self.network.now >= until), bool, f"{seconds} s of virtual time")

    # -- observation ----------------------------------------------------------------------------------------------

    def settled_position(self) -> int:
        """0x6064 once the axis settled: with 0x6067 = 0 a POS ends with its reference on the target, while the
        axis is still a few counts away from it (more on a loaded host, whose SDO read comes sooner in virtual time)."""
        self.run_for(0.05)
        return self.read(0x6064)

    def rows(self, mark: int = 0) -> list[Row]:
        with self.network.lock:
            return self.probe.rows[mark:]

    def executed(self, since: float) -> list[int]:
        """The sequence numbers TPDO 2 reported after `since` (virtual time), repeats collapsed."""
        with self._lock:
            numbers = [change.number for change in self.changes if change.time > since]
        return [number for n, number in enumerate(numbers) if n == 0 or numbers[n - 1] != number]


def first(rows: Sequence[Row], condition: Callable[[Row], bool], what: str) -> Row:
    for row in rows:
        if condition(row):
            return row
    raise AssertionError(f"no control period with {what}")


def phase_rows(rows: Sequence[Row]) -> list[Row]:
    """The first row of every change of the sequence number or its phases."""

    def state(row: Row) -> tuple[int, int]:
        return row[EXECUTED], row[PHASE]

    return [row for n, row in enumerate(rows) if n == 0 or state(rows[n - 1]) != state(row)]


def commissioned(plant: Plant):
    """A behaviour factory: the commissioned drive on `plant` (a --plant file gives an uncommissioned one)."""

    def factory(device: str, node_id: int, store, events):
        return make_behaviour(device, store, plant, events, commissioned=True)

    return factory
