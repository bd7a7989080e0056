"""Pieces of the live project code that need no drive: the drive-backed compare source and derived bus names."""

from __future__ import annotations

from concurrent.futures import Future

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.drive.sdo import SdoAbortError, SdoTimeoutError
from servostudio.drive.values import ObjectValue
from servostudio.od import builtin_library
from servostudio.services.projects import Bus, Project
from servostudio.services.projects.live.scaninto import bus_name_for
from servostudio.services.projects.live.source import DriveValues
from servostudio.services.projects.names import is_valid_name

DICTIONARY = builtin_library().load("xtrapulspac")


class ScriptedDrive:
    """Answers reads from a script: a value, an abort code, or a timeout; records the order of the requests."""

    node = 1

    def __init__(self, script: dict[tuple[int, int], object]) -> None:
        self.script = script
        self.requested: list[tuple[int, int]] = []
        self.futures: list[Future] = []

    def submit_read(self, variable):
        self.requested.append(variable.key)
        future: Future = Future()
        answer = self.script[variable.key]
        if answer == "timeout":
            future.set_exception(SdoTimeoutError(1, *variable.key, "no SDO response"))
        elif isinstance(answer, tuple):
            future.set_exception(SdoAbortError(1, *variable.key, answer[1]))
        elif answer != "pending":
            future.set_result(ObjectValue(1, variable, answer))
        self.futures.append(future)
        return future


def variables(*keys):
    return [DICTIONARY[key] for key in keys]


def test_all_reads_are_queued_before_the_first_answer_is_awaited():
    drive = ScriptedDrive({(0x6083, 0): 5, (0x2004, 0): "axis\0\0", (0x6060, 0): ("abort", 0x06020000)})
    source = DriveValues(drive, variables((0x6083, 0), (0x2004, 0), (0x6060, 0)))
    assert drive.requested == [(0x6083, 0), (0x2004, 0), (0x6060, 0)]
    assert (source.read(0x6083, 0), source.read(0x2004, 0), source.read(0x6060, 0)) == (5, "axis", None)
    assert "0x06020000" in source.refused[0x6060, 0]


def test_a_drive_that_stops_answering_fails_the_read_and_cancels_the_rest():
    drive = ScriptedDrive({(0x6083, 0): "timeout", (0x6084, 0): "pending"})
    with pytest.raises(SdoTimeoutError):
        DriveValues(drive, variables((0x6083, 0), (0x6084, 0)))
    assert drive.futures[1].cancelled()


@settings(deadline=None)
@given(st.text(max_size=120), st.lists(st.sampled_from(["sim", "sim-2", "bus", "socketcan-can0"]), unique=True))
def test_a_bus_name_derived_from_any_spec_is_valid_and_unused(spec, existing):
    project = Project("p", buses=tuple(Bus(name, "sim") for name in existing))
    name = bus_name_for(spec, project)
    assert is_valid_name(name) and name not in existing
