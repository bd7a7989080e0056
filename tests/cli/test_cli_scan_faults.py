"""A scan that finds nothing fails (exit 4, NotFound) and says why a bus may look empty; ``fault`` works on every
supported drive (the CD1-k has no 0x603F)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from tests.support.commands import run_json

from servostudio.errors import OUTCOMES, ErrorKind
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import empty_scan_hint, scan
from servostudio.transport.spec import parse_bus_spec


def test_a_scan_of_an_empty_virtual_channel_fails_and_says_why(capsys):
    code, nodes, error = run_json(capsys, "scan", "--bus", "virtual:empty-channel-of-this-test")
    assert code == OUTCOMES[ErrorKind.NOT_FOUND].exit_code == 4
    assert nodes == []
    assert "no node answered on virtual:empty-channel-of-this-test" in error
    assert "another process" in error and "socketcand" in error


@pytest.mark.parametrize(
    ("spec", "words"),
    [
        ("socketcan:vcan9", ("bit rate", "termination", "powered")),
        ("socketcand:127.0.0.1:1", ("channel", "bit rate")),
        ("serial:socket://127.0.0.1:1", ("baud rate", "cable")),
    ],
)
def test_the_hint_names_the_reasons_of_each_kind_of_bus(spec: str, words: tuple[str, ...]):
    hint = empty_scan_hint(SimpleNamespace(spec=parse_bus_spec(spec)))  # type: ignore[arg-type]
    assert all(word in hint for word in words), hint


def test_the_empty_scan_event_carries_the_hint():
    manager = ConnectionManager()
    events: list[dict] = []
    manager.events.add_listener(events.append)
    try:
        connection = manager.open("virtual:empty-channel-of-the-event-test", wait=2.0)
        assert scan(connection) == []
    finally:
        manager.close_all()
    scanned = next(event for event in events if event["type"] == "scan")
    assert scanned["nodes"] == [] and "virtual channel" in scanned["hint"]


def test_fault_works_on_a_cd1k_and_an_encotrive(capsys):
    for node in (7, 9):
        code, report, error = run_json(capsys, "fault", "--bus", "sim:7:cd1k,9:encotrive", "--node", str(node))
        assert code == 0, error
        assert report["node"] == node and report["faults"] == [] and report["causes"] == []
