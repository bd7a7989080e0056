"""The TOML-subset parser and writer behind project and motor files."""

from __future__ import annotations

import tomllib

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.services.projects import Axis, Bus, Project, tomlsubset
from servostudio.services.projects.errors import FileFormatError
from servostudio.services.projects.model import from_text, to_text

KEYS = st.text(min_size=1, max_size=12)
VALUES = st.one_of(
    st.text(max_size=20),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.floats(allow_nan=False, allow_infinity=False),
    st.booleans(),
)
TABLES = st.dictionaries(KEYS, VALUES, max_size=5)
# Fewer examples than hypothesis's default: each one writes and parses a whole document; 60 still cover the
# value kinds, escapes and key shapes many times over.
DOCUMENTS = st.dictionaries(st.tuples(st.sampled_from(["project", "bus", "axis"]), KEYS), TABLES, max_size=6)


def _document(tables: dict[tuple[str, str], dict]) -> dict:
    return {path: tomlsubset.Table(values=values) for path, values in tables.items()}


@settings(max_examples=60, deadline=None)
@given(DOCUMENTS)
def test_write_then_parse_gives_the_same_document(tables):
    text = tomlsubset.dump(_document(tables))
    parsed = tomlsubset.parse(text, "doc.toml")
    assert {path: table.values for path, table in parsed.items()} == tables
    assert tomlsubset.dump(parsed) == text


@settings(max_examples=60, deadline=None)
@given(DOCUMENTS)
def test_written_files_are_valid_toml_with_the_same_content(tables):
    text = tomlsubset.dump(_document(tables))
    expected: dict = {}
    for (group, name), values in tables.items():
        expected.setdefault(group, {})[name] = values
    assert tomllib.loads(text) == expected


@settings(deadline=None)  # no per-example time limit: the machine is shared
@given(st.text(max_size=200))
def test_any_text_parses_or_fails_with_file_and_line(text):
    try:
        tomlsubset.parse(text, "fuzz.toml")
    except FileFormatError as error:
        assert str(error).startswith("fuzz.toml:")
        assert 1 <= error.line <= text.count("\n") + 1


@settings(max_examples=60, deadline=None)
@given(DOCUMENTS, st.data())
def test_what_the_parser_accepts_tomllib_reads_identically(tables, data):
    text = tomlsubset.dump(_document(tables))
    lines = text.split("\n")
    position = data.draw(st.integers(0, len(lines) - 1))
    lines[position] = data.draw(st.text(max_size=30).filter(lambda line: "\n" not in line and "\r" not in line))
    mutated = "\n".join(lines)
    try:
        parsed = tomlsubset.parse(mutated, "m.toml")
    except FileFormatError:
        return
    loaded = tomllib.loads(mutated)
    for path, table in parsed.items():
        node = loaded
        for part in path:
            node = node[part]
        assert {key: node[key] for key in table.values} == table.values


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ('[project]\nname = "x\n', 2, "not closed"),
        ("[project]\nname = 'x'\n", 2, "not a quoted string"),
        ('[project]\nname = "a"\nname = "b"\n', 3, "set twice"),
        ("[project]\n[project]\n", 2, "defined twice"),
        ('name = "x"\n', 1, "outside any [table]"),
        ("[project]\nnode = 007\n", 2, "not a quoted string, a decimal integer"),
        ("[project\n", 1, "expected ']'"),
        ("[a]\nb = 1\n[a.b]\n", 3, "clashes with key"),
    ],
)
def test_errors_name_the_line_and_the_reason(text, line, reason):
    with pytest.raises(FileFormatError) as caught:
        tomlsubset.parse(text, "bad.toml")
    assert caught.value.line == line
    assert reason in caught.value.reason
    assert str(caught.value).startswith(f"bad.toml:{line}: ")


NAMES = st.from_regex(r"[A-Za-z0-9][A-Za-z0-9 _.+-]{0,20}[A-Za-z0-9_+-]", fullmatch=True)
BUSES = st.builds(Bus, NAMES, st.text(min_size=1, max_size=20), st.none() | st.integers(1, 10**7))
AXES = st.builds(
    Axis,
    NAMES,
    st.sampled_from(["xtrapulspac", "cd1k"]),
    st.integers(1, 127),
    NAMES,
    st.text(max_size=30),
    st.text(max_size=10),
    st.text(max_size=10),
)
PROJECTS = st.builds(
    Project,
    NAMES,
    st.text(max_size=40),
    st.lists(BUSES, max_size=3, unique_by=lambda b: b.name).map(tuple),
    st.lists(AXES, max_size=4, unique_by=lambda a: a.name).map(tuple),
)


@settings(max_examples=60, deadline=None)
@given(PROJECTS)
def test_project_file_round_trip_is_exact_and_stable(project):
    text = to_text(project)
    assert from_text(text, "project.toml", project.name) == project
    assert to_text(from_text(text, "project.toml", project.name)) == text
    assert tomllib.loads(text)["project"]["name"] == project.name
