"""Saving to flash always gets an SDO answer: texts the object file cannot carry are left out, and a flash that
cannot be written makes the drive abort the request instead of leaving the client waiting."""

from __future__ import annotations

import struct

from servostudio.formats.objectfile import parse_object_file
from servostudio.sim.flash import DRIVEPAR, SAVE, ProcedureStatus
from servostudio.sim.frame import Frame
from servostudio.sim.network import SimulatedNetwork

SAVE_REQUEST = bytes([0x23, 0x10, 0x10, 1]) + struct.pack("<I", SAVE)


class Recorder:
    def __init__(self) -> None:
        self.frames: list[Frame] = []

    def receive(self, frame: Frame, timestamp: float) -> None:
        self.frames.append(frame)

    def sdo_answers(self, node_id: int) -> list[bytes]:
        return [frame.data for frame in self.frames if frame.can_id == 0x580 + node_id]


def save(network: SimulatedNetwork) -> Recorder:
    recorder = Recorder()
    network.attach(recorder)
    network.inject(Frame(0x601, SAVE_REQUEST))
    network.advance(0.3)
    return recorder


def test_an_empty_axis_name_is_left_out_of_drivepar_and_the_save_is_confirmed(tmp_path):
    network = SimulatedNetwork("1", state_dir=tmp_path)
    node = network.node(1)
    assert node.store.get(0x2004, 0) == ""  # a new XtrapulsPac has no axis name
    recorder = save(network)
    assert [answer[0] for answer in recorder.sdo_answers(1)] == [0x60]
    entries = parse_object_file((tmp_path / "node1" / DRIVEPAR).read_text(encoding="latin-1"))
    assert len(entries) > 300 and (0x2004, 0) not in {(entry.index, entry.sub) for entry in entries}
    assert node.flash.load(DRIVEPAR)
    assert node.store.get(0x2004, 0) == ""


def test_a_flash_that_cannot_be_written_aborts_the_save_with_0x08000020(tmp_path):
    blocked = tmp_path / "not-a-directory"
    blocked.write_text("a file where the drive's flash directory should be")
    network = SimulatedNetwork("1", state_dir=blocked)
    node = network.node(1)
    recorder = save(network)
    [answer] = recorder.sdo_answers(1)
    assert answer[0] == 0x80 and struct.unpack_from("<I", answer, 4)[0] == 0x08000020
    assert not node.events.flash_busy
    assert node.store.read_from_bus(0x1010, 1) == ProcedureStatus.ERROR
    assert "flash operation failed" in node.flash.last_error
