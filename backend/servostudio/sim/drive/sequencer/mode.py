"""Sequence mode (0x6060 = −3): the sequencer that runs programs of chained sequences from the sequence memory.

A rising edge of control word bit 4 in Operation Enabled starts the sequence whose number is in 0x3601,1 (ignored
while a program runs); bit 5 stops the program: the running motion brakes (with its own deceleration where it has
one, else 0x6084) and the program ends without END. The sequencer takes one chaining step per control period:
entering a sequence (run it, skip to SeqLink, or wait for its start condition: `chaining`), then the sequence's
motion until it has arrived, its Tempo, END, and the next sequence.

0x3601,2 shows the sequence being executed (also one waiting for its start condition; a skipped one never shows),
−1 when no program runs; 0x3605 the phases it has reached so far (0 while waiting; the last sequence's stay after
the program). An end condition that holds while a sequence runs ends its running phase early; the sequence then
finishes and chains as usual. The program ends on a failed motion (a homing error), a limit switch in the direction
of travel, a number without a runnable sequence (an empty slot, a type 0x360F does not list), and when the drive
leaves Operation Enabled or sequence mode.

Status word in sequence mode: bit 10 no program runs and the axis stands at its reference, bit 12 the dedicated
output POS, bit 13 SEQ (docs/sequences.md).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from typing import TYPE_CHECKING

from servostudio.formats.sequence_spec import SequenceType
from servostudio.od.model import Value
from servostudio.sim.drive.device_map import MODE_SQ
from servostudio.sim.drive.modes import BIT_12, BIT_13, BIT_TARGET_REACHED, ModeHandler
from servostudio.sim.drive.sequencer.chaining import END_OF_PROGRAM, Entry, LoopCounter, entry
from servostudio.sim.drive.sequencer.gearbox import GearMotion, VirtualMaster
from servostudio.sim.drive.sequencer.home_motion import HomeMotion
from servostudio.sim.drive.sequencer.inputs import LogicInputs
from servostudio.sim.drive.sequencer.motions import (
    Carry,
    Motion,
    SpeedMotion,
    StopMotion,
    TorqueMotion,
    carry_of,
    position_motion,
    profile_deceleration,
)
from servostudio.sim.drive.sequencer.outputs import POS, SEQ, SequenceOutputs
from servostudio.sim.drive.sequencer.phases import BEGIN, END, NONE, in_order
from servostudio.sim.drive.sequencer.record import SequenceRecord
from servostudio.sim.sequences import SequenceMemory

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour

NUMBER_INPUT, EXECUTED_NUMBER, CONDITIONAL_INPUT = ((0x3601, sub) for sub in (1, 2, 3))
PHASE = (0x3605, 0)
SUPPORTED_TYPES = (0x360F, 0)
MODE_OF_OPERATION = (0x6060, 0)
CW_START = 1 << 4
CW_STOP = 1 << 5

MotionFactory = Callable[["DriveBehaviour", SequenceRecord, Carry], Motion]
MOTIONS: dict[int, MotionFactory] = {
    SequenceType.POS: position_motion,
    SequenceType.HOME: HomeMotion,
    SequenceType.SPEED: SpeedMotion,
    SequenceType.TORQUE: TorqueMotion,
    SequenceType.GEAR: GearMotion,
}


class Program(enum.Enum):
    IDLE = "idle"
    ENTERING = "entering"
    WAITING = "waiting"
    RUNNING = "running"
    STOPPING = "stopping"


class SequenceMode(ModeHandler):
    def __init__(self, drive: DriveBehaviour, memory: SequenceMemory) -> None:
        super().__init__(drive)
        self.memory = memory
        self.counter = LoopCounter()
        self.outputs = SequenceOutputs(drive)
        self.inputs = LogicInputs(drive)
        self.virtual_master = VirtualMaster(drive)
        self.program = Program.IDLE
        self.number = END_OF_PROGRAM
        self.record: SequenceRecord | None = None
        self.motion: Motion = StopMotion.holding(drive)
        self._entering = END_OF_PROGRAM
        self._phases = NONE
        self._ending = False
        self._tempo_until: float | None = None
        store = drive.store
        self._read_number = store.integer_reader(*NUMBER_INPUT)
        self._read_conditions = store.integer_reader(*CONDITIONAL_INPUT)
        store.set_factory(*EXECUTED_NUMBER, END_OF_PROGRAM)
        store.on_write(*MODE_OF_OPERATION, self._mode_written)

    @classmethod
    def for_drive(cls, drive: DriveBehaviour) -> SequenceMode | None:
        """The sequencer of a drive that has sequence mode and a sequence memory (the XtrapulsPac), else None."""
        memory = getattr(drive.events, "sequences", None)
        if not isinstance(memory, SequenceMemory) or MODE_SQ not in drive.profile.modes:
            return None
        return cls(drive, memory)

    # -- the drive's calls ---------------------------------------------------------------------------------------

    def enter(self) -> None:
        self._abort()

    def on_nmt_reset(self) -> None:
        """Warm reset: the objects are back at their power-on values; no program, outputs off, inputs re-read."""
        self._abort()
        self.outputs.reset()
        self.inputs.apply()
        self.virtual_master.reset()

    def control_word(self, control_word: int, previous: int) -> None:
        if not self.drive.device_control.follows_set_points:
            self._abort()
        elif control_word & CW_STOP:
            self.stop()
        elif control_word & CW_START and not previous & CW_START and self.program is Program.IDLE:
            self.start(self._read_number())

    def step(self) -> None:
        program = self.program
        if program is Program.ENTERING:
            self._enter(self._entering)
        elif program is Program.WAITING:
            self._retry_start()
        phases = self.motion.step()
        if self.program is Program.RUNNING:
            self._run(phases)
        elif self.program is Program.STOPPING:
            self._brake(phases)
        self.outputs.tick()

    def status_bits(self) -> int:
        self._notice_interruption()
        dedicated = self.outputs.dedicated
        bits = BIT_TARGET_REACHED if self.program is Program.IDLE and self.motion.arrived else 0
        return bits | (BIT_12 if dedicated & POS else 0) | (BIT_13 if dedicated & SEQ else 0)

    def not_following(self) -> int:
        self._notice_interruption()
        return 0

    def limit_switch_stop(self) -> None:
        """A limit switch in the direction of travel ends the program; the drive holds the actual position."""
        self._abort()

    @property
    def uses_limit_switches(self) -> bool:
        return self.program is Program.RUNNING and self.motion.uses_limit_switches

    def current_limit(self) -> float:
        return self.motion.current_limit()

    # -- program ----------------------------------------------------------------------------------------------

    def start(self, number: int) -> None:
        self.counter.clear()
        self.outputs.program_started()
        self.program = Program.ENTERING
        self._entering = number

    def stop(self) -> None:
        """Control word bit 5: brake the running motion, then end the program (no END, no chaining)."""
        if self.program is Program.RUNNING:
            self.motion = self.motion.end_early()
            self.program = Program.STOPPING
        elif self.program in (Program.ENTERING, Program.WAITING):
            self._finish()

    def _enter(self, number: int) -> None:
        record = self._runnable(number)
        if record is None:
            self._finish()
            return
        decision = entry(record, self._conditions())
        if decision is Entry.RUN:
            self._begin(number, record)
        elif decision is Entry.SKIP:
            self._entering = record.link
        else:
            self.program = Program.WAITING
            self.record = record
            self._entering = number
            self._show(number, NONE)

    def _retry_start(self) -> None:
        record = self.record
        if record is not None and record.start.holds(self._conditions()):
            self._begin(self._entering, record)

    def _begin(self, number: int, record: SequenceRecord) -> None:
        self.program = Program.RUNNING
        self.record = record
        self._ending = False
        self._tempo_until = None
        self.motion = MOTIONS[record.type](self.drive, record, carry_of(self.drive.loops))
        self._show(number, NONE)
        self._reach(BEGIN)

    def _run(self, phases: int) -> None:
        record = self.record
        if record is None or self.motion.failed:
            self._finish()
            return
        if phases:
            self._reach_all(phases)
        if record.end.defined and not self._ending and record.end.holds(self._conditions()):
            self._ending = True
            self.motion = self.motion.end_early()
        if self.motion.arrived:
            self._count_tempo(record)

    def _brake(self, phases: int) -> None:
        """A stopped program: its sequence's phases until it stands, then the end (no Tempo, no END)."""
        if phases:
            self._reach_all(phases)
        if self.motion.arrived:
            self._finish()

    def _count_tempo(self, record: SequenceRecord) -> None:
        """After the motion: Tempo ms, then END and the next sequence (entered in the next period)."""
        now = self.drive.time
        if self._tempo_until is None:
            self._tempo_until = now + record.tempo / 1000.0 - self.drive.dt / 2
        if now >= self._tempo_until:
            self._reach(END)
            self.program = Program.ENTERING
            self._entering = self.counter.next_after(self.number, record)

    def _reach_all(self, phases: int) -> None:
        for phase in in_order(phases):
            self._reach(phase)

    def _reach(self, phase: int) -> None:
        """0x3605 gains the phase's bit (BEGIN starts afresh); the outputs react."""
        self._show(self.number, phase | (self._phases if phase != BEGIN else NONE))
        if self.record is not None:
            self.outputs.phase_reached(phase, self.record)

    def _finish(self) -> None:
        """The program is over: a moving reference brakes at 0x6084 and stands."""
        self.motion = StopMotion(self.drive, carry_of(self.drive.loops), profile_deceleration(self.drive))
        self._idle()

    def _abort(self) -> None:
        """The program is cut off (the drive left Operation Enabled or the mode, a limit switch, a reset): the
        actual position is held."""
        self.motion = StopMotion.holding(self.drive)
        if self.program is not Program.IDLE:
            self._idle()

    def _idle(self) -> None:
        self.program = Program.IDLE
        self.record = None
        self._show(END_OF_PROGRAM, self._phases)
        self.outputs.program_ended()

    def _notice_interruption(self) -> None:
        """Checked with every status word: a program does not survive a fault, a stop or a disable."""
        if self.program is not Program.IDLE and not self.drive.device_control.follows_set_points:
            self._abort()
        self.outputs.tick()

    def _mode_written(self, index: int, sub: int, value: Value) -> None:
        if int(value) != MODE_SQ:
            self._abort()

    # -- objects ----------------------------------------------------------------------------------------------

    def _runnable(self, number: int) -> SequenceRecord | None:
        """The sequence `number` when it can run: in the memory, of a type the drive supports and simulates."""
        if not 0 <= number < self.memory.capacity:
            return None
        record = SequenceRecord.of(self.memory.record(number))
        supported = int(self.drive.store.get(*SUPPORTED_TYPES)) >> (record.type - 1) & 1 if record.type else 0
        return record if supported and record.type in MOTIONS else None

    def _conditions(self) -> int:
        return self._read_conditions() & 0xFFFF

    def _show(self, number: int, phases: int) -> None:
        """0x3601,2 and 0x3605."""
        self.number = number
        self._phases = phases
        store = self.drive.store
        store.set(*EXECUTED_NUMBER, number)
        store.set(*PHASE, phases)
