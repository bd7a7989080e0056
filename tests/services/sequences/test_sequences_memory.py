"""Sequence memory through the service: a bad file refused with file, line, keyword and range and nothing written;
LOAD and MERGE; the round trip project → drive → flash → reset → drive → project, byte for byte."""

from __future__ import annotations

import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.support.sequence_programs import CONDITIONAL_JUMP, COUNTER_LOOP

from servostudio.errors import ServoStudioError
from servostudio.formats.sequence import LoadMode, SequenceFileError, format_sequence_table, parse_sequence_text
from servostudio.services import sequences

MANUAL_BAD = """SeqNb=1
SeqType=pos
Pos=0x001000
Speed=100000
SeqNext=3
SeqNb=3
SeqType=speed
AccelTime=200000
Speed=500000
"""


def test_a_bad_file_is_refused_with_file_line_keyword_and_range_and_nothing_written(drive):
    sequences.download(drive, COUNTER_LOOP, LoadMode.LOAD)
    before = sequences.upload(drive)
    with pytest.raises(SequenceFileError) as refused:
        sequences.download(drive, MANUAL_BAD, LoadMode.LOAD, store=True)
    (issue,) = refused.value.issues
    assert (refused.value.file, issue.line, issue.keyword) == ("SEQUENCE.TXT", 8, "AccelTime")
    assert "allowed 1..65535" in issue.reason
    assert "SEQUENCE.TXT:8: AccelTime:" in str(refused.value)
    assert sequences.upload(drive) == before


def test_a_type_the_drive_does_not_list_is_refused_at_its_line(drive):
    found = sequences.limits(drive)
    text = "SeqNb=0\nSeqType=POS\n"
    if found.types_mask & 1:  # the default drive lists every type: ask the reader as a drive without POS would
        with pytest.raises(SequenceFileError) as refused:
            parse_sequence_text(text, "SEQUENCE.TXT", types=[t for t in found.types if t.name != "POS"])
        assert refused.value.issues[0].line == 2 and "not supported" in refused.value.issues[0].reason


def test_merge_keeps_the_other_sequences_and_load_clears_them(drive):
    sequences.download(drive, COUNTER_LOOP, LoadMode.LOAD)
    extra = "SeqNb=7\nSeqType=SPEED\nSpeed=100\nAccelTime=10\nRunTime=5\n"
    merged = sequences.download(drive, extra, LoadMode.MERGE)
    assert merged.verified and list(sequences.upload(drive)) == [1, 2, 3, 7]
    loaded = sequences.download(drive, extra, LoadMode.LOAD)
    assert loaded.verified and list(sequences.upload(drive)) == [7]


def test_round_trip_project_drive_flash_reset_drive_project_is_lossless(connection, drive, tmp_path):
    project_file = tmp_path / "SEQUENCE.TXT"
    project_file.write_text(format_sequence_table(parse_sequence_text(CONDITIONAL_JUMP)), encoding="latin-1")
    original = project_file.read_bytes()
    result = sequences.download(drive, original.decode("latin-1"), LoadMode.LOAD, store=True)
    assert result.verified and result.stored
    sequences.download(drive, COUNTER_LOOP, LoadMode.LOAD)  # RAM changed, flash not
    drive.write("nmt_reset_configuration", 2)  # the next reset node is a warm reset: SEQUENCE.TXT reloaded
    connection.nmt("reset-node", drive.node)
    deadline = time.monotonic() + 10
    while True:
        try:
            if list(sequences.upload(drive)) == [1, 2, 3, 4]:
                break
        except ServoStudioError:  # the node is booting
            pass
        assert time.monotonic() < deadline, "the drive did not come back with its flash copy"
        time.sleep(0.1)
    (tmp_path / "back.TXT").write_text(format_sequence_table(sequences.upload(drive)), encoding="latin-1")
    assert (tmp_path / "back.TXT").read_bytes() == original


@settings(max_examples=60, deadline=None)
@given(st.text(alphabet='SeqNbTypePOSHM=0123456789-."\n ;xAcl', max_size=120))
def test_check_agrees_with_the_file_reader(text):
    """One validation: the service's check says ok exactly when the reader accepts the text."""
    verdict = sequences.check(text)
    try:
        parse_sequence_text(text, "SEQUENCE.TXT")
    except SequenceFileError as error:
        assert not verdict["ok"] and len(verdict["issues"]) == len(error.issues)  # type: ignore[arg-type]
    else:
        assert verdict["ok"]
