"""XtrapulsPac-specific stack features: sequence memory (0x3610/0x3611), SEQUENCE.TXT (sseq / lseq / mseq) and the
TPDO_Count transmission mode (0x23A0/0x23A1)."""

from __future__ import annotations

import struct

import pytest
from tests.support.sim_test_drive import counting_factory, frames_with_id, write

from servostudio.formats.sequence_model import Sequence, SequenceTable
from servostudio.formats.sequence_reader import read_sequence_file
from servostudio.formats.sequence_spec import SequenceType
from servostudio.formats.sequence_writer import format_sequence_table
from servostudio.od import builtin_library
from servostudio.sim import sdo_abort
from servostudio.sim.flash import LOAD_SEQUENCES, MERGE_SEQUENCES, SAVE_SEQUENCES
from servostudio.sim.network import SimulatedNetwork


@pytest.fixture
def client(raw_client, tmp_path):
    network = SimulatedNetwork(
        "1",
        dictionaries={"xtrapulspac": builtin_library().load("xtrapulspac")},
        behaviour_factory=counting_factory,
        state_dir=tmp_path,
    )
    client = raw_client(network)
    client.collect(0.001)
    return client


def write_sequence(client, number, record):
    write(client, 1, 0x3610, 0, number, size=2)
    od = client.network.node(1).store.od
    for sub, value in record.items():
        write(client, 1, 0x3611, sub, value, size=od[(0x3611, sub)].data_type.size)


def test_selection_addresses_one_record_and_is_range_checked(client):
    write_sequence(client, 5, {1: 3})
    write(client, 1, 0x3610, 0, 6, size=2)
    assert struct.unpack_from("<h", client.sdo(1, bytes([0x40, 0x11, 0x36, 1])), 4)[0] == 0
    write(client, 1, 0x3610, 0, 5, size=2)
    assert struct.unpack_from("<h", client.sdo(1, bytes([0x40, 0x11, 0x36, 1])), 4)[0] == 3
    response = client.sdo(1, bytes([0x2B, 0x10, 0x36, 0, 128, 0]))
    assert struct.unpack_from("<I", response, 4)[0] == sdo_abort.VALUE_TOO_HIGH


def test_sseq_writes_the_memory_as_sequence_txt(client, tmp_path):
    position = Sequence.of(SequenceType.POS).to_object_values()
    write_sequence(client, 2, position)
    write_sequence(client, 4, Sequence.of(SequenceType.SPEED).to_object_values())
    write(client, 1, 0x1010, 1, SAVE_SEQUENCES)
    client.collect(0.3)
    table = read_sequence_file(tmp_path / "node1" / "SEQUENCE.TXT")
    assert list(table) == [2, 4]
    assert table[2] == Sequence.of(SequenceType.POS) and table[4].type is SequenceType.SPEED


def test_lseq_replaces_and_mseq_merges(client, tmp_path):
    folder = tmp_path / "node1"
    folder.mkdir()
    write_sequence(client, 5, Sequence.of(SequenceType.SPEED).to_object_values())
    (folder / "SEQUENCE.TXT").write_text(format_sequence_table(SequenceTable({1: Sequence.of(SequenceType.POS)})))
    write(client, 1, 0x1011, 1, LOAD_SEQUENCES)
    assert sorted(client.network.node(1).sequences.records) == [1]
    client.collect(0.3)
    (folder / "SEQUENCE.TXT").write_text(format_sequence_table(SequenceTable({7: Sequence.of(SequenceType.HOME)})))
    write(client, 1, 0x1011, 1, MERGE_SEQUENCES)
    memory = client.network.node(1).sequences
    assert sorted(memory.records) == [1, 7] and memory.record(7)[1] == int(SequenceType.HOME)


def test_bad_sequence_file_is_refused_with_error_44(client, tmp_path):
    folder = tmp_path / "node1"
    folder.mkdir()
    write_sequence(client, 3, Sequence.of(SequenceType.POS).to_object_values())
    (folder / "SEQUENCE.TXT").write_text("SeqNb=1\nSeqType=SPEED\nAccelTime=200000\n")  # above U16
    write(client, 1, 0x1011, 1, LOAD_SEQUENCES)
    assert client.network.node(1).behaviour.errors == [44]
    assert sorted(client.network.node(1).sequences.records) == [3]
    [emcy] = frames_with_id(client.collect(0.01), 0x81)
    assert emcy.data[3] == 44


def test_sequence_txt_is_loaded_at_power_on(tmp_path):
    folder = tmp_path / "node2"
    folder.mkdir()
    (folder / "SEQUENCE.TXT").write_text(format_sequence_table(SequenceTable({9: Sequence.of(SequenceType.SPEED)})))
    network = SimulatedNetwork(
        "2",
        dictionaries={"xtrapulspac": builtin_library().load("xtrapulspac")},
        behaviour_factory=counting_factory,
        state_dir=tmp_path,
    )
    assert network.node(2).sequences.record(9)[1] == int(SequenceType.SPEED)


def test_tpdo_count_mode_sends_type_254_pdos_when_the_host_counter_matches(client):
    write(client, 1, 0x1802, 2, 254, size=1)  # TPDO3 (position) in TPDO_Count mode
    write(client, 1, 0x23A1, 3, 2, size=1)
    client.send(0x000, bytes([0x01, 1]))
    sent = []
    for counter in (0, 1, 2, 3, 2):
        write(client, 1, 0x23A0, 0, counter, size=1)
        client.send(0x080)
        sent.append(len(frames_with_id(client.collect(0.005), 0x381)))
    assert sent == [0, 0, 1, 0, 1]
