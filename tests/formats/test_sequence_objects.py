"""Sequences as 0x3610/0x3611 object values, and the LOAD / MERGE semantics of the drive's sequence memory."""

from __future__ import annotations

import pytest

from servostudio.formats.sequence import (
    BitPattern,
    LoadMode,
    ObjectWrite,
    Sequence,
    SequenceTable,
    SequenceType,
    format_sequence_table,
    parse_sequence_text,
)

HOME = Sequence.of(
    SequenceType.HOME,
    HomeOfs=-500,
    Speed=2000,
    Speed2=100,
    Accel=20,
    Decel=30,
    Method=-2,
    Torque=400,
    Tempo=5,
    Trigger=32,
    Output=BitPattern(zeros=1, ones=2),
    StartCond=BitPattern(ones=4),
    EndCond=BitPattern(zeros=8),
    SeqNext=4,
    SeqCount=3,
    SeqLink=0,
)


def test_home_sequence_fills_every_sub_of_0x3611() -> None:
    assert HOME.to_object_values() == {
        1: 2,
        2: 4,
        3: 3,
        4: 0,
        5: 32,
        6: 1,
        7: 2,
        8: 0,
        9: 0,
        10: 4,
        11: 8,
        12: 0,
        13: -500,
        14: 0,
        15: 2000,
        16: 100,
        17: 0,
        18: 0,
        19: 20,
        20: 30,
        21: 0,
        22: -2,
        23: 5,
        24: 0,
        25: 400,
        26: 0,
    }


@pytest.mark.parametrize(
    ("sequence", "expected"),
    [
        (
            Sequence.of(SequenceType.POS, Pos=7, PosType=1, Speed=8, Speed2=9, Accel=10, Decel=11),
            {13: 7, 21: 1, 15: 8, 16: 9, 17: 10, 18: 11},
        ),
        (
            Sequence.of(SequenceType.SPEED, Speed=8, AccelTime=10, DecelTime=11, RunTime=65535),
            {15: 8, 19: 10, 20: 11, 24: 65535},
        ),
        (
            Sequence.of(SequenceType.TORQUE, Speed=-8, Accel=10, Decel=11, RunTime=12, Torque=13),
            {15: -8, 19: 10, 20: 11, 24: 12, 25: 13},
        ),
        (
            Sequence.of(SequenceType.GEAR, Config=3, Factor=-4, Speed=5, Accel=6, MasterDtn=7, SlaveDtn=8, SyncDtn=9),
            {21: 3, 26: -4, 15: 5, 19: 6, 13: 7, 14: 8, 16: 9},
        ),
    ],
)
def test_type_specific_keywords_land_in_their_subs(sequence: Sequence, expected: dict[int, int]) -> None:
    record = sequence.to_object_values()
    assert {sub: record[sub] for sub in expected} == expected
    assert record[1] == sequence.type.value
    untouched = set(range(3, 27)) - set(expected) - {4}
    assert all(record[sub] == 0 for sub in untouched)
    assert Sequence.from_object_values(record) == sequence


def test_empty_slot_reads_as_no_sequence() -> None:
    assert Sequence.from_object_values({1: 0, 13: 1234}) is None


def test_subs_a_type_does_not_use_are_ignored() -> None:
    record = {**Sequence.of(SequenceType.SPEED, Speed=5).to_object_values(), 13: 99, 17: 1000, 25: -3}
    assert Sequence.from_object_values(record) == Sequence.of(SequenceType.SPEED, Speed=5)


@pytest.mark.parametrize(
    ("changes", "reason"),
    [
        ({1: 6}, "CAM"),
        ({1: 9}, "sequence type 9"),
        ({8: 1}, "0x3611,8 (Output Bits Toggle)"),
        ({5: 16}, "Trigger: 16 has no constant"),
        ({5: 33}, "Trigger: 33 has no constant"),
        ({7: 0x100}, "Output (0x3611,6/7): pattern bits must be within bits 0..7"),
        ({9: 4, 10: 4}, "StartCond (0x3611,9/10): pattern bits 0x4 cannot be both 0 and 1"),
        ({23: 20000}, "Tempo: value 20000 is out of range: allowed 0..16000"),
        ({2: 200}, "SeqNext: value 200 is out of range: allowed -1..127"),
    ],
)
def test_values_a_file_cannot_express_are_refused(changes: dict[int, int], reason: str) -> None:
    record = {**Sequence.of(SequenceType.POS).to_object_values(), **changes}
    with pytest.raises(ValueError) as caught:
        Sequence.from_object_values(record)
    assert reason in str(caught.value)


def test_homing_return_option_has_no_keyword() -> None:
    record = {**HOME.to_object_values(), 21: 1}
    with pytest.raises(ValueError, match=r"0x3611,21 .* in a HOME sequence has no SEQUENCE\.TXT keyword"):
        Sequence.from_object_values(record)


def test_drive_defaults_outside_the_file_range_are_kept_and_left_out_of_the_file() -> None:
    """AccelTime 0 and Method 0 are the drive's defaults although a file may not write them."""
    table = SequenceTable({1: Sequence.of(SequenceType.SPEED, Speed=5), 2: Sequence.of(SequenceType.HOME)})
    assert (table[1]["AccelTime"], table[2]["Method"]) == (0, 0)
    text = format_sequence_table(table)
    assert "AccelTime" not in text and "Method" not in text and "Trigger" not in text
    assert parse_sequence_text(text) == table


@pytest.mark.parametrize(
    ("kind", "values", "reason"),
    [
        (SequenceType.POS, {"Method": 1}, "not parameters of a POS sequence: Method"),
        (SequenceType.SPEED, {"AccelTime": 70000}, "AccelTime: value 70000 is out of range: allowed 1..65535"),
        (SequenceType.POS, {"Output": 5}, "Output: needs a bit pattern"),
        (SequenceType.POS, {"Speed": BitPattern()}, "Speed: needs a number"),
        (SequenceType.POS, {"Trigger": 3}, "Trigger: 3 has no constant"),
    ],
)
def test_invalid_sequences_cannot_be_built(kind: SequenceType, values: dict, reason: str) -> None:
    with pytest.raises(ValueError) as caught:
        Sequence(kind, values)
    assert reason in str(caught.value)


def test_table_numbers_are_limited_to_0_127() -> None:
    with pytest.raises(ValueError, match=r"sequence number 128 out of range 0\.\.127"):
        SequenceTable({128: HOME})


def test_object_writes_select_the_number_then_write_all_subs() -> None:
    table = SequenceTable({3: HOME, 1: Sequence.of(SequenceType.SPEED, Speed=5)})
    writes = table.to_object_writes()
    assert len(writes) == 2 * 27
    assert writes[0] == ObjectWrite(0x3610, 0, 1)
    assert writes[1:27] == [ObjectWrite(0x3611, sub, value) for sub, value in table[1].to_object_values().items()]
    assert [write.sub for write in writes[1:27]] == list(range(1, 27))
    assert writes[27] == ObjectWrite(0x3610, 0, 3)
    assert writes[28] == ObjectWrite(0x3611, 1, 2)


def test_load_writes_clear_every_other_slot() -> None:
    table = SequenceTable({1: HOME})
    writes = table.to_object_writes(clear_below=3)
    assert writes[:2] == [ObjectWrite(0x3610, 0, 0), ObjectWrite(0x3611, 1, 0)]
    assert writes[2] == ObjectWrite(0x3610, 0, 1) and len(writes) == 2 + 27 + 2
    assert writes[-2:] == [ObjectWrite(0x3610, 0, 2), ObjectWrite(0x3611, 1, 0)]
    with pytest.raises(ValueError, match="sequence numbers >= 1"):
        table.to_object_writes(clear_below=1)


def test_table_from_object_records() -> None:
    records = {0: {1: 0}, 1: HOME.to_object_values(), 5: Sequence.of(SequenceType.GEAR, Factor=2).to_object_values()}
    table = SequenceTable.from_object_values(records)
    assert list(table) == [1, 5] and table[1] == HOME
    with pytest.raises(ValueError, match=r"^sequence 7: sequence type 6"):
        SequenceTable.from_object_values({7: {1: 6}})


MEMORY = SequenceTable(
    {
        0: Sequence.of(SequenceType.POS, Pos=1),
        1: Sequence.of(SequenceType.POS, Pos=2),
        2: Sequence.of(SequenceType.POS, Pos=3, Speed=50),
    }
)
FILE = parse_sequence_text("SeqNb=2\nSeqType=POS\nPos=30\nSeqNb=9\nSeqType=SPEED\nSpeed=9\n")


def test_load_replaces_the_whole_memory() -> None:
    assert FILE.apply_to(MEMORY, LoadMode.LOAD) == FILE


def test_merge_replaces_declared_sequences_whole_and_keeps_the_others() -> None:
    merged = FILE.apply_to(MEMORY, LoadMode.MERGE)
    assert list(merged) == [0, 1, 2, 9]
    assert (merged[0], merged[1], merged[9]) == (MEMORY[0], MEMORY[1], FILE[9])
    # Sequence 2 comes entirely from the file: its undeclared Speed is the default, not the 50 it held.
    assert (merged[2]["Pos"], merged[2]["Speed"]) == (30, 0)
