"""One simulated TTA-PRO on the PROFIBUS line: the DP station in front, the PPO split into PKW and PZD, the PKW
server, the procedures, the sequence table and the drive behind it, run in virtual time.

`power_cycle()` keeps only what the drive's EEPROM holds (E parameters, sequences and their checksum) and starts
everything else afresh, including the DP link; a sequence table written without its checksum then shows
error 2 (EEPROM sequences checksum), as the manual says (PNU 781, L1906-1921).
"""

from __future__ import annotations

import struct

from servostudio.od.pnu_model import ParameterDictionary
from servostudio.sim.plant import Plant
from servostudio.sim.profibus.faults import FaultRegister
from servostudio.sim.profibus.parameters import ParameterMemory
from servostudio.sim.profibus.pkw_server import NO_REQUEST, VALUE, PkwServer
from servostudio.sim.profibus.positioner import CYCLE, CYCLE_PERIODS, TtaProDrive
from servostudio.sim.profibus.procedures import Procedure, ProcedureRunner
from servostudio.sim.profibus.sequence_table import SequenceTable
from servostudio.sim.profibus.station import DpStation
from servostudio.transport.profibus.ppo import PKW_WORDS, WORD_BYTES, Ppo, ppo_for_config

PKW_BYTES = PKW_WORDS * WORD_BYTES
SEQUENCE_CHECKSUM_ERROR = 2
SAVE_SECONDS = 0.1
SEQUENCE_READ_SECONDS = 0.005
SEQUENCE_WRITE_SECONDS = 0.02
FEEDBACK_PROGRAMMING_SECONDS = 0.2
"""The simulator's duration of PNU 894 (motor feedback programming); the real drive takes about 5 s (L3105)."""
FEEDBACK_SELECTION = (890, 891, 892, 893, 898)
"""What PNU 894 applies: encoder input selection and resolution, interpolation, motor feedback, SinCos tracks."""


class TtaProSlave:
    def __init__(
        self, address: int, parameters: ParameterDictionary, plant: Plant, double_reply_ak: int = VALUE
    ) -> None:
        self.address = address
        self.parameters = parameters
        self.plant = plant
        self.double_reply_ak = double_reply_ak
        self.feedback_programmings: list[dict[int, int]] = []
        """Every PNU 894 carried out since the drive was built (power cycles too): the selection it applied."""
        self._build(ParameterMemory(parameters), commission=True)

    def _build(self, memory: ParameterMemory, commission: bool) -> None:
        self.memory = memory
        self.faults = FaultRegister()
        self.sequences = SequenceTable(memory)
        self.drive = TtaProDrive(memory, self.plant, self.faults, commission)
        self.procedures = ProcedureRunner(memory, enabled=lambda: self.drive.powered)
        self._define_procedures()
        self.pkw = PkwServer(memory, self.procedures, self.double_reply_ak)
        self.station = DpStation(self.address, self.parameters.ident_number, self)
        self.ppo: Ppo | None = None
        self._periods = 0

    def _define_procedures(self) -> None:
        memory, sequences = self.memory, self.sequences
        self.procedures.define(729, Procedure(SAVE_SECONDS, lambda _: _done(memory.save_eeprom)))
        self.procedures.define(780, Procedure(SEQUENCE_READ_SECONDS, lambda n: _done(sequences.read_into_buffer, n)))
        self.procedures.define(781, Procedure(SEQUENCE_WRITE_SECONDS, lambda n: _done(sequences.write, n)))
        self.procedures.define(894, Procedure(FEEDBACK_PROGRAMMING_SECONDS, lambda _: _done(self._program_feedback)))

    def _program_feedback(self) -> None:
        """PNU 894: the feedback selection written to 890-893/898 becomes the one the drive uses (L3105). The
        simulated plant keeps its own sensor: what was applied is recorded, not modelled."""
        self.feedback_programmings.append({pnu: self.memory.get(pnu) for pnu in FEEDBACK_SELECTION})

    def power_cycle(self) -> None:
        memory = ParameterMemory(self.parameters)
        memory.eeprom = dict(self.memory.eeprom)
        memory.load_eeprom()
        eeprom, checksum = self.sequences.eeprom, self.sequences.stored_checksum
        self._build(memory, commission=False)
        self.sequences.eeprom, self.sequences.stored_checksum = eeprom, checksum
        if not self.sequences.power_up():
            self.faults.raise_fault(SEQUENCE_CHECKSUM_ERROR)

    # -- DP application -----------------------------------------------------------------------------------------

    @property
    def config(self) -> bytes:
        return self.ppo.identifiers if self.ppo is not None else b""

    @property
    def output_length(self) -> int:
        return self.ppo.length if self.ppo is not None else 0

    def check_config(self, config: bytes) -> bool:
        """Chk_Cfg: PPO1 to PPO4 are accepted (L181-267)."""
        ppo = ppo_for_config(config)
        if ppo is not None:
            self.ppo = ppo
        return ppo is not None

    def apply_outputs(self, data: bytes) -> None:
        ppo = self.ppo
        if ppo is None:
            return
        if ppo.has_pkw:
            self.pkw.receive(data[:PKW_BYTES])
        pzd = data[ppo.pzd_offset :]
        self.drive.receive(struct.unpack(f">{len(pzd) // 2}H", pzd))

    def read_inputs(self) -> bytes:
        ppo = self.ppo
        if ppo is None:
            return b""
        words = self.drive.feedback(ppo.pzd_words)
        pzd = struct.pack(f">{len(words)}H", *(word & 0xFFFF for word in words))
        return (self.pkw.reply if ppo.has_pkw else b"") + pzd

    def link_lost(self) -> None:
        self.drive.link_lost()
        self.pkw.receive(NO_REQUEST)

    # -- time ---------------------------------------------------------------------------------------------------

    def step(self, now: float) -> None:
        """One control period; every fourth is a positioner cycle."""
        self.drive.step()
        self._periods += 1
        if self._periods % CYCLE_PERIODS:
            return
        self.drive.cycle()
        self.procedures.step(CYCLE)
        self.pkw.cycle()
        self.station.check_watchdog(now)


def _done(action, *arguments: int) -> bool:
    """Run a procedure's action; the simulated ones cannot fail once started."""
    action(*arguments)
    return True
