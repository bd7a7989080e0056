"""The manual's sequence examples, read through the SEQUENCE.TXT reader (fixtures: see fixtures/README.md)."""

from __future__ import annotations

from pathlib import Path

import pytest

from servostudio.formats.sequence import (
    BitPattern,
    SequenceFileError,
    SequenceType,
    parse_sequence_text,
    read_sequence_file,
)

FIXTURES = Path(__file__).parent / "fixtures"


def test_manual_file_example_is_rejected_for_its_out_of_range_times() -> None:
    """docs/decisions.md §3: AccelTime=200000 exceeds the U16 ms range of sub 19; so does DecelTime (sub 20)."""
    path = FIXTURES / "manual_sequence_example.txt"
    with pytest.raises(SequenceFileError) as caught:
        read_sequence_file(path)
    error = caught.value
    assert error.file == str(path)
    assert [(issue.line, issue.keyword) for issue in error.issues] == [(32, "AccelTime"), (34, "DecelTime")]
    assert "allowed 1..65535" in error.issues[0].reason and "0x3611,19" in error.issues[0].reason
    assert "allowed 0..65535" in error.issues[1].reason and "0x3611,20" in error.issues[1].reason
    assert f"{path}:32: AccelTime: value 200000 is out of range: allowed 1..65535" in str(error)


def test_manual_file_example_with_times_in_range_reads_as_the_manual_describes() -> None:
    text = (FIXTURES / "manual_sequence_example.txt").read_text().replace("=200000", "=2000")
    table = parse_sequence_text(text)
    assert list(table) == [1, 3]
    positioning, speed = table[1], table[3]
    assert positioning.type is SequenceType.POS
    assert positioning["Pos"] == 0x1000
    assert positioning["PosType"] == 0  # ABS
    assert positioning["Speed"] == 100000
    assert positioning["Output"] == BitPattern(zeros=0b0011_0111, ones=0b0000_1000)
    assert positioning["Trigger"] == 1  # BEGIN = bit 0 of sub 5
    assert (positioning["Tempo"], positioning["SeqNext"]) == (1000, 3)
    assert (positioning["Accel"], positioning["Decel"]) == (100000, 100000)  # from the Default block
    assert speed.type is SequenceType.SPEED
    assert (speed["AccelTime"], speed["DecelTime"], speed["Speed"], speed["RunTime"]) == (2000, 2000, 500000, 10000)
    subs = positioning.to_object_values()
    assert (subs[1], subs[13], subs[17], subs[18], subs[5], subs[6], subs[7]) == (1, 4096, 100000, 100000, 1, 0x37, 8)


def test_manual_two_positioning_sequences_without_stopping() -> None:
    table = read_sequence_file(FIXTURES / "manual_pos_chain.txt")
    first, second = table[1], table[2]
    assert (first["Speed"], first["Accel"], first["Decel"], first["SeqNext"]) == (150000, 400, 0, 2)
    assert (second["Speed"], second["Accel"], second["Decel"], second["SeqNext"]) == (250000, 300, 400, -1)
    # POS keeps acceleration in acceleration units: AccelTime/DecelTime land in subs 17/18, not 19/20.
    subs = first.to_object_values()
    assert (subs[17], subs[18], subs[19], subs[20], subs[2]) == (400, 0, 0, 0, 2)


def test_manual_combined_speed_sequences() -> None:
    table = read_sequence_file(FIXTURES / "manual_speed_chain.txt")
    assert {
        number: (seq["Speed"], seq["AccelTime"], seq["RunTime"], seq["DecelTime"], seq["SeqNext"])
        for number, seq in table.sequences.items()
    } == {1: (150000, 400, 0, 0, 2), 2: (250000, 400, 0, 0, 3), 3: (140000, 400, 0, 150, -1)}
    subs = table[3].to_object_values()
    assert (subs[1], subs[15], subs[19], subs[20], subs[24]) == (3, 140000, 400, 150, 0)


def test_manual_counter_loop() -> None:
    table = read_sequence_file(FIXTURES / "manual_counter_loop.txt")
    assert {number: (seq["SeqCount"], seq["SeqNext"], seq["SeqLink"]) for number, seq in table.sequences.items()} == {
        1: (0, 2, -1),
        2: (2, 3, 1),
        3: (0, -1, -1),
    }
    assert all(seq.type is SequenceType.POS for seq in table.sequences.values())


def test_manual_conditional_jump_pattern_is_msb_first() -> None:
    table = read_sequence_file(FIXTURES / "manual_conditional_jump.txt")
    assert table[2]["StartCond"] == BitPattern(zeros=0, ones=0x80)  # "1......." = logic input 8 = bit 7
    assert (table[2]["SeqNext"], table[2]["SeqLink"]) == (3, 4)
    subs = table[2].to_object_values()
    assert (subs[9], subs[10]) == (0, 0x80)
    assert table[1]["StartCond"] == BitPattern()
