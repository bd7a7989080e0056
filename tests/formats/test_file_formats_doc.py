"""docs/file-formats.md's keyword table says exactly what the reader accepts."""

from __future__ import annotations

import re
from pathlib import Path

from servostudio.formats.sequence_model import default_value
from servostudio.formats.sequence_spec import COMMON, SEQ_TYPE, SPECIFIC, Keyword, SequenceType

DOC = Path(__file__).resolve().parents[2] / "docs" / "file-formats.md"
KINDS = {"all", *SequenceType.__members__}


def documented_rows() -> dict[tuple[str, str], tuple[str, str, str, str]]:
    rows = {}
    for line in DOC.read_text(encoding="utf-8").splitlines():
        cells = [cell.strip() for cell in line.split("|")[1:-1]]
        if len(cells) == 6 and cells[0] in KINDS and re.fullmatch(r"`\w+`", cells[1]):
            kind, name, aliases, subs, allowed, default = cells
            rows[(kind, name.strip("`"))] = (aliases, subs, allowed, default)
    return rows


def expected_row(keyword: Keyword) -> tuple[str, str, str, str]:
    aliases = ", ".join(f"`{alias}`" for alias in keyword.aliases)
    subs = "/".join(str(sub) for sub in keyword.subs)
    if keyword.is_pattern:
        return aliases, subs, "pattern", f"`{default_value(keyword)}`"
    if keyword.constants is not None:
        allowed = ", ".join(f"{name} ({value})" for name, value in keyword.constants.items())
        return aliases, subs, allowed, str(default_value(keyword))
    return aliases, subs, str(keyword.value_range), str(default_value(keyword))


def test_keyword_table_matches_the_reader() -> None:
    rows = documented_rows()
    expected = {("all", keyword.name): expected_row(keyword) for keyword in COMMON}
    for kind in SequenceType:
        expected.update({(kind.name, keyword.name): expected_row(keyword) for keyword in SPECIFIC[kind]})
    documented = {key: row for key, row in rows.items() if key not in {("all", "SeqNb"), ("all", SEQ_TYPE.name)}}
    assert documented.keys() == expected.keys()
    for key, (aliases, subs, allowed, default) in expected.items():
        doc_aliases, doc_subs, doc_allowed, doc_default = documented[key]
        assert (doc_aliases, doc_subs) == (aliases, subs), key
        assert doc_allowed == allowed, key
        assert doc_default.split(" ")[0] == default, key
