"""The sequencer of the simulated XtrapulsPac: sequence mode (0x6060 = −3) over the sequence memory 0x3610/0x3611,
its inputs (conditions, the simulator's physical inputs) and outputs (docs/sequences.md)."""

from __future__ import annotations

from servostudio.sim.drive.sequencer.mode import SequenceMode

__all__ = ["SequenceMode"]
