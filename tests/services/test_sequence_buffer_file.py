"""TTASEQ.TXT, the TTA-PRO's sequence table file (docs/profibus.md §13), read and written without a drive: random
tables within each field's range round-trip through the canonical text; any text is either a table or refused
with its line; the fields' ranges are the parameter list's."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.drive.profiles import profile_for
from servostudio.od.pnu import builtin_parameter_list
from servostudio.services.sequence_buffer import SequenceTableInvalid, format_table, parse_table

PROFILE = profile_for("ttapro")
DICTIONARY = builtin_parameter_list()
BUFFER = PROFILE.sequence_buffer
assert BUFFER is not None
VARIABLES = {name: DICTIONARY[PROFILE.address(name)] for name in BUFFER.fields}


def field_value(name: str) -> st.SearchStrategy[int]:
    variable = VARIABLES[name]
    low, high = variable.minimum, variable.maximum
    if name == BUFFER.control:
        low = max(int(low), 1)  # in use
    return st.integers(int(low), int(high))


def sequences() -> st.SearchStrategy[dict[str, int]]:
    return st.fixed_dictionaries({name: field_value(name) for name in BUFFER.fields})


tables = st.dictionaries(st.integers(0, BUFFER.count - 1), sequences(), max_size=6)


@settings(max_examples=60, deadline=None)
@given(table=tables, header=st.text(st.characters(codec="latin-1", exclude_characters="\r\n"), max_size=40))
def test_a_table_round_trips_through_its_canonical_text(table, header):
    text = format_table(PROFILE, table, header)
    assert parse_table(PROFILE, DICTIONARY, text, "TTASEQ.TXT") == dict(sorted(table.items()))
    assert format_table(PROFILE, parse_table(PROFILE, DICTIONARY, text, "TTASEQ.TXT"), header) == text


@settings(max_examples=200, deadline=None)
@given(text=st.text(st.sampled_from("0123456789,=;-+x \n78"), max_size=120))
def test_any_text_is_a_table_or_refused_with_its_line(text):
    try:
        table = parse_table(PROFILE, DICTIONARY, text, "TTASEQ.TXT")
    except SequenceTableInvalid as refused:
        assert 1 <= refused.line <= text.count("\n") + 1 and refused.file == "TTASEQ.TXT" and refused.reason
    else:
        assert all(set(fields) == set(BUFFER.fields) for fields in table.values())


@pytest.mark.parametrize(("pnu", "value"), [(785, 0), (785, 16001), (784, 10001), (788, 128), (788, -2)])
def test_a_value_outside_the_parameter_list_s_range_is_refused(pnu, value):
    fields = {PROFILE.address(name)[0]: 1 for name in BUFFER.fields} | {788: -1, pnu: value}
    text = "".join(f"{field},9={number}\n" for field, number in fields.items())
    with pytest.raises(SequenceTableInvalid) as refused:
        parse_table(PROFILE, DICTIONARY, text, "TTASEQ.TXT")
    assert refused.value.line == list(fields).index(pnu) + 1 and refused.value.reason.startswith("sequence 9: ")


def test_an_unused_sequence_is_as_if_not_listed():
    fields = {PROFILE.address(name)[0]: 1 for name in BUFFER.fields} | {782: 0}
    text = "".join(f"{field},4={value}\n" for field, value in fields.items())
    assert parse_table(PROFILE, DICTIONARY, text, "TTASEQ.TXT") == {}
