"""The audit log on its own: append-only JSON lines that survive a restart and a cut line, who from the acting
context, filters and pages, CSV and JSON-lines exports, and the project store's object-by-object journal."""

from __future__ import annotations

import csv
import io
import json

import pytest

from servostudio.errors import InvalidInput
from servostudio.services.audit import Actor, AuditLog, AuditQuery, ProjectAudit, acting_as, parse_time


def test_entries_are_appended_with_who_and_a_sequence_that_survives_a_restart(tmp_path):
    path = tmp_path / "data" / "audit.jsonl"
    with acting_as(Actor("alice", "expert", "c1")):
        AuditLog(path).record([{"action": "arm", "axis": "sim:1"}])
    AuditLog(path).record([{"action": "release", "axis": "sim:1", "user": "bob"}])
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    assert [(line["seq"], line["user"], line["client"], line["action"]) for line in lines] == [
        (1, "alice", "c1", "arm"),
        (2, "bob", None, "release"),
    ]
    assert lines[0]["time"].endswith("Z") and lines[0]["time"] <= lines[1]["time"]


def test_a_line_cut_short_by_a_crash_is_skipped_and_numbering_goes_on(tmp_path):
    path = tmp_path / "audit.jsonl"
    AuditLog(path).record([{"action": "arm"}])
    with path.open("a") as file:
        file.write('{"seq": 2, "action": "ena')  # the server was killed mid-line
    log = AuditLog(path)
    log.record([{"action": "stop"}])
    entries = log.entries(AuditQuery()).entries
    assert [(entry["seq"], entry["action"]) for entry in entries] == [(2, "stop"), (1, "arm")]


def _filled(tmp_path) -> AuditLog:
    log = AuditLog(tmp_path / "audit.jsonl")
    for number in range(5):
        with acting_as(Actor("alice" if number % 2 else "bob")):
            log.record(
                [{"action": "drive_write", "axis": f"sim:{number % 2 + 1}", "object": "0x60FF,0", "new": number}]
            )
    return log


def test_filters_and_pages_newest_first(tmp_path):
    log = _filled(tmp_path)
    page = log.entries(AuditQuery(axis="sim:2", limit=1, offset=1))
    assert page.total == 2 and [entry["new"] for entry in page.entries] == [1]
    assert log.entries(AuditQuery(user="bob")).total == 3
    assert log.entries(AuditQuery(since=parse_time("1h"))).total == 5
    assert log.entries(AuditQuery(until=parse_time("1h"))).total == 0
    with pytest.raises(InvalidInput):
        log.entries(AuditQuery(limit=0))


def test_exports_as_json_lines_and_csv_oldest_first(tmp_path):
    log = _filled(tmp_path)
    jsonl = "".join(log.export(AuditQuery(axis="sim:1"), "jsonl")).splitlines()
    assert [json.loads(line)["new"] for line in jsonl] == [0, 2, 4]
    rows = list(csv.DictReader(io.StringIO("".join(log.export(AuditQuery(), "csv")))))
    assert [row["new"] for row in rows] == ["0", "1", "2", "3", "4"]
    assert rows[0]["user"] == "bob" and rows[0]["client"] == "" and rows[0]["object"] == "0x60FF,0"
    with pytest.raises(InvalidInput):
        log.export(AuditQuery(), "xml")


@pytest.mark.parametrize(
    ("text", "shown"),
    [
        ("2026-12-01", "2026-12-01T00:00:00.000Z"),
        ("2026-12-01T10:30", "2026-12-01T10:30:00.000Z"),
        ("2026-12-01T11:30+01:00", "2026-12-01T10:30:00.000Z"),
        ("2h", "1970-01-01T00:00:00.000Z"),
    ],
)
def test_times_are_iso_8601_or_an_age(text, shown):
    assert parse_time(text, now=7200.0) == shown


def test_a_bad_time_names_what_works():
    with pytest.raises(InvalidInput, match="ISO 8601"):
        parse_time("yesterday")


def test_project_file_changes_are_logged_object_by_object(tmp_path):
    log = AuditLog(None)
    journal = ProjectAudit(log)
    old = b"0x6060,0=1\n0x60F9,2=100\n0x607A,0=5\n"
    new = b"0x6060,0=3\n0x60F9,2=100\n0x6081,0=2000\n"
    journal.axis_file("demo", "x", "DRIVEPAR.TXT", old, new)
    journal.axis_file("demo", "x", "SEQUENCE.TXT", b"a", b"b")
    journal.axis_file("demo", "x", "TTAPAR.TXT", b"700,0=4\n720,0=10\n", b"700,0=4\n720,0=12\n")  # PNU,IND
    entries = log.entries(AuditQuery(project="demo")).entries[::-1]
    assert [(entry["object"], entry.get("old"), entry.get("new")) for entry in entries] == [
        ("0x6060,0", 1, 3),
        ("0x607A,0", 5, None),
        ("0x6081,0", None, 2000),
        ("SEQUENCE.TXT", None, None),
        ("0x02D0,0", 10, 12),  # PNU 720 at the address the TTA-PRO's parameter list gives it
    ]
    assert {entry["project_axis"] for entry in entries} == {"x"}
