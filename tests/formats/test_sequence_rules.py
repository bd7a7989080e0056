"""One test per SEQUENCE.TXT syntax rule (manual L11128–11170, docs/decisions.md §3): accepted forms and rejections.

Each rejection names the line, the keyword as written, and the reason (with the allowed range or values).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from servostudio.formats.sequence import (
    BitPattern,
    Sequence,
    SequenceFileError,
    SequenceIssue,
    SequenceTable,
    SequenceType,
    parse_sequence_text,
    read_sequence_file,
)


def issues_of(text: str, **options: int) -> tuple[SequenceIssue, ...]:
    with pytest.raises(SequenceFileError) as caught:
        parse_sequence_text(text, "SEQUENCE.TXT", **options)
    assert caught.value.file == "SEQUENCE.TXT"
    return caught.value.issues


def single_issue(text: str, **options: int) -> SequenceIssue:
    issues = issues_of(text, **options)
    assert len(issues) == 1, issues
    return issues[0]


# Rule 1: text file; keywords and constants are not case-sensitive (spaces inside a keyword do not matter either).
def test_rule1_keywords_and_constants_ignore_case_and_inner_spaces() -> None:
    table = parse_sequence_text(
        'seqnb=1\nSEQTYPE=Pos\nposition=5\npostype=rel\nstart cond="1......."\nNEXTSEQ=2\ntrigger=Cruise\n'
    )
    assert table[1] == Sequence.of(
        SequenceType.POS, Pos=5, PosType=1, StartCond=BitPattern(ones=0x80), SeqNext=2, Trigger=2
    )


def test_rule1_text_with_crlf_line_ends_keeps_line_numbers() -> None:
    assert parse_sequence_text("SeqNb=1\r\nSeqType=POS\r\nPos=3\r\n")[1]["Pos"] == 3
    issue = single_issue("SeqNb=1\r\nSeqType=POS\r\nPos=x\r\n")
    assert (issue.line, issue.keyword) == (3, "Pos")


# Rule 2: `Key_word = value`, one keyword per line.
def test_rule2_spaces_around_equals_are_allowed() -> None:
    assert parse_sequence_text("SeqNb = 4\n  SeqType =  HOME  \n Method\t= 35\n")[4]["Method"] == 35


def test_rule2_line_without_equals_is_rejected() -> None:
    issue = single_issue("SeqNb=1\nSeqType=POS\nSpeed 100\n")
    assert (issue.line, issue.keyword) == (3, None)
    assert "expected 'Key_word = value'" in issue.reason and "'Speed 100'" in issue.reason


def test_rule2_two_keywords_on_one_line_are_rejected() -> None:
    issue = single_issue("SeqNb=1\nSeqType=POS\nSpeed=100 Accel=5\n")
    assert (issue.line, issue.keyword) == (3, "Speed")
    assert "is not a number" in issue.reason


def test_rule2_missing_keyword_is_rejected() -> None:
    issue = single_issue("SeqNb=1\nSeqType=POS\n=100\n")
    assert (issue.line, issue.keyword) == (3, None)


# Rule 3: a value is a decimal or 0x hex number, or a constant.
def test_rule3_decimal_and_hex_numbers() -> None:
    sequence = parse_sequence_text("SeqNb=0x0A\nSeqType=POS\nPos=0x001000\nSpeed=-0x10\nTempo=0016\n")[10]
    assert (sequence["Pos"], sequence["Speed"], sequence["Tempo"]) == (4096, -16, 16)


@pytest.mark.parametrize("value", ["1O0", "0x", "1.5", "ten", "1e3", "0b101", ""])
def test_rule3_malformed_number_is_rejected(value: str) -> None:
    issue = single_issue(f"SeqNb=1\nSeqType=POS\nSpeed={value}\n")
    assert (issue.line, issue.keyword) == (3, "Speed")
    assert "is not a number (decimal or 0x hex)" in issue.reason


@pytest.mark.parametrize(
    ("line", "keyword", "allowed"),
    [
        ("SeqType=JOG", "SeqType", "allowed: POS, HOME, SPEED, TORQUE, GEAR"),
        ("SeqType=1", "SeqType", "allowed: POS, HOME"),
        ("PosType=RELATIVE", "PosType", "allowed: ABS, REL"),
        ("Trigger=INPOS", "Trigger", "allowed: BEGIN, CRUISE, DECEL, HOLD, END"),
        ("Trigger=BEGIN|END", "Trigger", "allowed: BEGIN"),
    ],
)
def test_rule3_unknown_constant_is_rejected(line: str, keyword: str, allowed: str) -> None:
    issues = issues_of(f"SeqNb=1\n{line}\nSeqType=POS\n" if keyword != "SeqType" else f"SeqNb=1\n{line}\n")
    assert (issues[0].line, issues[0].keyword) == (2, keyword)
    assert "constant" in issues[0].reason and allowed in issues[0].reason


def test_rule3_each_trigger_constant_sets_its_bit() -> None:
    bits = {}
    for name in ("BEGIN", "CRUISE", "DECEL", "HOLD", "END"):
        bits[name] = parse_sequence_text(f"SeqNb=1\nSeqType=SPEED\nTrigger={name.lower()}\n")[1].to_object_values()[5]
    assert bits == {"BEGIN": 1, "CRUISE": 2, "DECEL": 4, "HOLD": 8, "END": 32}


# Rule 4: `;` starts a comment to the end of the line.
def test_rule4_comments() -> None:
    text = "; program\nSeqNb=2 ; second\n;SeqNb=3\nSeqType=SPEED;speed\nSpeed=7;Speed=8\n   ; indented comment\n"
    table = parse_sequence_text(text)
    assert list(table) == [2]
    assert table[2]["Speed"] == 7


# Rule 5: a sequence begins with SeqNb.
def test_rule5_parameter_before_any_seqnb_is_rejected() -> None:
    issues = issues_of("; comment\nSeqType=POS\nSeqNb=1\nSeqType=POS\n")
    assert [(issue.line, issue.keyword) for issue in issues] == [(2, "SeqType")]
    assert "a sequence begins with SeqNb" in issues[0].reason


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        ("x", "'x' is not a sequence number (decimal or 0x hex)"),
        ("128", "sequence number 128 is out of range: allowed 0..127"),
        ("-1", "sequence number -1 is out of range: allowed 0..127"),
    ],
)
def test_rule5_bad_sequence_number_is_rejected(value: str, reason: str) -> None:
    issue = single_issue(f"SeqNb={value}\nSeqType=POS\n")
    assert (issue.line, issue.keyword, issue.reason) == (1, "SeqNb", reason)


def test_rule5_sequence_number_limited_by_the_drive_maximum() -> None:
    assert list(parse_sequence_text("SeqNb=15\nSeqType=POS\n", max_sequences=16)) == [15]
    issue = single_issue("SeqNb=16\nSeqType=POS\n", max_sequences=16)
    assert "allowed 0..15" in issue.reason


def test_rule5_drive_maximum_must_be_positive() -> None:
    with pytest.raises(ValueError, match="max_sequences must be at least 1"):
        parse_sequence_text("", max_sequences=0)


# Rule 6: apart from SeqNb, the order of parameters does not matter.
def test_rule6_parameter_order_does_not_matter() -> None:
    forward = parse_sequence_text("SeqNb=1\nSeqType=HOME\nMethod=-2\nTorque=300\nAccel=50\n")
    backward = parse_sequence_text("SeqNb=1\nAccel=50\nTorque=300\nMethod=-2\nSeqType=HOME\n")
    assert forward == backward
    assert forward[1].to_object_values()[19] == 50  # HOME Accel is sub 19, resolved once the type is known


# Rule 7: no end marker; the next SeqNb ends the current sequence.
def test_rule7_next_seqnb_ends_the_sequence() -> None:
    table = parse_sequence_text("SeqNb=1\nSeqType=POS\nSpeed=5\nSeqNb=2\nSeqType=POS\nPos=9\n")
    assert (table[1]["Speed"], table[1]["Pos"], table[2]["Speed"], table[2]["Pos"]) == (5, 0, 0, 9)


def test_rule7_sequence_number_declared_twice_is_rejected() -> None:
    issue = single_issue("SeqNb=1\nSeqType=POS\nSeqNb=1\nSeqType=SPEED\n")
    assert (issue.line, issue.keyword, issue.reason) == (3, "SeqNb", "sequence 1 is already declared at line 1")


# Rule 8: incoherent parameters or out-of-limit values are errors.
@pytest.mark.parametrize(
    ("kind", "line", "allowed"),
    [
        ("POS", "Tempo=16001", "allowed 0..16000"),
        ("POS", "SeqNext=128", "allowed -1..127"),
        ("POS", "SeqLink=-2", "allowed -1..127"),
        ("POS", "SeqCount=65536", "allowed 0..65535"),
        ("POS", "Pos=2147483648", "allowed -2147483648..2147483647"),
        ("POS", "Speed=-2147483649", "allowed -2147483648..2147483647"),
        ("POS", "Accel=-1", "allowed 0..4294967295"),
        ("POS", "Decel=0x100000000", "allowed 0..4294967295"),
        ("SPEED", "AccelTime=0", "allowed 1..65535"),
        ("SPEED", "AccelTime=200000", "allowed 1..65535"),
        ("SPEED", "DecelTime=65536", "allowed 0..65535"),
        ("SPEED", "RunTime=-1", "allowed 0..65535"),
        ("HOME", "Method=15", "allowed -4..-1, 1..14, 17..30, 33..35"),
        ("HOME", "Method=0", "allowed -4..-1"),
        ("HOME", "Torque=32768", "allowed -32768..32767"),
        ("HOME", "Accel=65536", "allowed 1..65535"),
        ("TORQUE", "Current Limit=-32769", "allowed -32768..32767"),
        ("GEAR", "Config=65536", "allowed 0..65535"),
        ("GEAR", "Factor=40000", "allowed -32768..32767"),
        ("GEAR", "SyncDtn=0x80000000", "allowed -2147483648..2147483647"),
    ],
)
def test_rule8_out_of_limit_value_names_line_keyword_and_range(kind: str, line: str, allowed: str) -> None:
    keyword = line.split("=")[0]
    issue = single_issue(f"SeqNb=7\nSeqType={kind}\n{line}\n")
    assert (issue.line, issue.keyword) == (3, keyword)
    assert "out of range" in issue.reason and allowed in issue.reason and f"{kind} sequence 7" in issue.reason


@pytest.mark.parametrize(
    ("kind", "line"),
    [
        ("POS", "Tempo=16000"),
        ("POS", "SeqNext=-1"),
        ("POS", "SeqLink=127"),
        ("POS", "Accel=4294967295"),
        ("SPEED", "AccelTime=1"),
        ("SPEED", "AccelTime=65535"),
        ("SPEED", "RunTime=65535"),
        ("HOME", "Method=-4"),
        ("HOME", "Method=35"),
        ("HOME", "Method=17"),
        ("GEAR", "Factor=-32768"),
    ],
)
def test_rule8_limits_themselves_are_accepted(kind: str, line: str) -> None:
    keyword, value = line.split("=")
    assert parse_sequence_text(f"SeqNb=7\nSeqType={kind}\n{line}\n")[7][keyword] == int(value)


@pytest.mark.parametrize(
    ("kind", "line"),
    [
        ("POS", "Method=1"),
        ("POS", "RunTime=5"),
        ("SPEED", "Pos=1"),
        ("SPEED", "PosType=ABS"),
        ("HOME", "Pos=1"),
        ("TORQUE", "Speed2=1"),
        ("GEAR", "Decel=5"),
        ("GEAR", "DecelTime=5"),
    ],
)
def test_rule8_keyword_of_another_sequence_type_is_rejected(kind: str, line: str) -> None:
    issue = single_issue(f"SeqNb=1\nSeqType={kind}\n{line}\n")
    assert (issue.line, issue.keyword) == (3, line.split("=")[0])
    assert f"not a keyword of {kind} sequences" in issue.reason and "allowed: SeqType" in issue.reason


def test_rule8_unknown_keyword_is_rejected() -> None:
    issue = single_issue("SeqNb=1\nSeqType=POS\nVelocity=5\n")
    assert (issue.line, issue.keyword, issue.reason) == (3, "Velocity", "unknown keyword")


@pytest.mark.parametrize(
    ("first", "second", "name"),
    [
        ("Speed=1", "speed=2", "Speed"),
        ("Accel=1", "AccelTime=2", "Accel"),  # POS: the two spellings are one parameter
        ("NextSeq=1", "SeqNext=2", "SeqNext"),
        ("Pos=1", "Position=2", "Pos"),
    ],
)
def test_rule8_parameter_declared_twice_is_rejected(first: str, second: str, name: str) -> None:
    issue = single_issue(f"SeqNb=1\nSeqType=POS\n{first}\n{second}\n")
    assert (issue.line, issue.keyword) == (4, second.split("=")[0])
    assert issue.reason == f"{name} is declared twice in POS sequence 1 (first at line 3)"


def test_rule8_sequence_type_declared_twice_is_rejected() -> None:
    issue = single_issue("SeqNb=1\nSeqType=POS\nSeqType=SPEED\n")
    assert (issue.line, issue.keyword) == (3, "SeqType")
    assert "declared twice (first at line 2)" in issue.reason


def test_rule8_sequence_without_type_is_rejected() -> None:
    issue = single_issue("SeqNb=5\nSpeed=100\n")
    assert (issue.line, issue.keyword) == (1, "SeqNb")
    assert issue.reason == "sequence 5 has no SeqType (allowed: POS, HOME, SPEED, TORQUE, GEAR)"


# Rule 9: undeclared parameters take defaults; the Default keyword changes them.
def test_rule9_builtin_defaults() -> None:
    sequence = parse_sequence_text("SeqNb=0\nSeqType=SPEED\n")[0]
    assert dict(sequence.values) == {
        "Speed": 0,
        "AccelTime": 0,
        "DecelTime": 0,
        "RunTime": 0,
        "Tempo": 0,
        "Trigger": 0,
        "Output": BitPattern(),
        "StartCond": BitPattern(),
        "EndCond": BitPattern(),
        "SeqNext": -1,
        "SeqCount": 0,
        "SeqLink": -1,
    }


def test_rule9_default_block_applies_to_undeclared_parameters_of_later_sequences() -> None:
    text = (
        "Default\nSpeed=1000\nAccel=50\nTempo=20\n"
        "SeqNb=1\nSeqType=POS\nSpeed=5\n"  # Accel (sub 17) and Tempo from the defaults
        "SeqNb=2\nSeqType=SPEED\n"  # AccelTime takes the Accel default (one parameter)
        "Default\nSpeed=2000\n"  # changes the default for what follows only
        "SeqNb=3\nSeqType=TORQUE\n"
    )
    table = parse_sequence_text(text)
    assert (table[1]["Speed"], table[1]["Accel"], table[1]["Tempo"]) == (5, 50, 20)
    assert (table[2]["Speed"], table[2]["AccelTime"], table[2]["Tempo"]) == (1000, 50, 20)
    assert (table[3]["Speed"], table[3]["Accel"]) == (2000, 50)


def test_rule9_default_may_give_the_sequence_type() -> None:
    table = parse_sequence_text("Default\nSeqType=speed\nSeqNb=1\nSeqNb=2\nSeqType=POS\n")
    assert (table[1].type, table[2].type) == (SequenceType.SPEED, SequenceType.POS)


def test_rule9_default_out_of_range_for_a_sequence_is_reported_at_the_default_line() -> None:
    # Accel=100000 is fine for POS (sub 17) but not for the ms range of SPEED's AccelTime (sub 19).
    text = "Default\nAccel=100000\nSeqNb=1\nSeqType=POS\nSeqNb=2\nSeqType=SPEED\n"
    issue = single_issue(text)
    assert (issue.line, issue.keyword) == (2, "Accel")
    assert "allowed 1..65535" in issue.reason and "[Default, applied to SPEED sequence 2]" in issue.reason


def test_rule9_default_keywords_are_checked_where_they_stand() -> None:
    issues = issues_of("Default\nSpede=1\nSpeed=fast\nOutput=1\nSeqNb=1\nSeqType=POS\n")
    assert [(issue.line, issue.keyword) for issue in issues] == [(2, "Spede"), (3, "Speed"), (4, "Output")]
    assert issues[0].reason == "unknown keyword"


def test_rule9_default_parameters_that_do_not_fit_a_type_are_not_applied_to_it() -> None:
    table = parse_sequence_text("Default\nMethod=35\nPosType=REL\nSeqNb=1\nSeqType=SPEED\nSeqNb=2\nSeqType=POS\n")
    assert table[2]["PosType"] == 1 and "Method" not in table[1].values


# Patterns (docs/decisions.md §3): 8 characters of 1/0/., MSB first, in double quotes.
def test_pattern_strings_are_msb_first() -> None:
    sequence = parse_sequence_text('SeqNb=1\nSeqType=POS\nOutput="1......0"\nEndCond="0.1....."\n')[1]
    assert sequence["Output"] == BitPattern(zeros=0x01, ones=0x80)
    assert sequence["EndCond"] == BitPattern(zeros=0x80, ones=0x20)
    assert str(sequence["EndCond"]) == '"0.1....."'


@pytest.mark.parametrize("value", ['"..00100"', '"..0010000"', '"..0x1000"', "..001000", "'..001000'", '"..001000'])
def test_malformed_pattern_is_rejected(value: str) -> None:
    issue = single_issue(f"SeqNb=1\nSeqType=POS\nStartCond={value}\n")
    assert (issue.line, issue.keyword) == (3, "StartCond")
    assert "a pattern is 8 characters of 1, 0 or . in double quotes, MSB first" in issue.reason


# Whole-file behaviour: every error is reported, and no table comes back from a file with any error.
def test_all_errors_are_collected_in_line_order() -> None:
    text = (
        "SeqNb=1\nSeqType=POS\nTempo=99999\nMethod=3\n"
        "SeqNb=2\nSeqType=SPEED\nAccelTime=0\n"
        "SeqNb=3\nSeqType=GEAR\nFactor=1\n"  # a valid sequence among broken ones
        "nonsense\n"
    )
    issues = issues_of(text)
    assert [(issue.line, issue.keyword) for issue in issues] == [
        (3, "Tempo"),
        (4, "Method"),
        (7, "AccelTime"),
        (11, None),
    ]


def test_a_file_with_any_error_yields_no_table(tmp_path: Path) -> None:
    good = "".join(f"SeqNb={n}\nSeqType=POS\nPos={n * 100}\n" for n in range(10))
    assert len(parse_sequence_text(good)) == 10
    path = tmp_path / "SEQUENCE.TXT"
    path.write_text(good + "SeqNb=10\nSeqType=POS\nTempo=16001\n")
    with pytest.raises(SequenceFileError) as caught:
        read_sequence_file(path)
    assert [(issue.line, issue.keyword) for issue in caught.value.issues] == [(33, "Tempo")]
    assert str(caught.value).splitlines()[1].startswith(f"{path}:33: Tempo: value 16001 is out of range")


def test_empty_file_is_an_empty_table() -> None:
    assert parse_sequence_text("; nothing here\n\n") == SequenceTable({})
