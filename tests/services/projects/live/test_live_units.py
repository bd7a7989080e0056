"""Pieces of the live project code that need no drive: the drive-backed compare source and derived bus names."""

from __future__ import annotations

from concurrent.futures import Future
from types import SimpleNamespace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.drive.object_values import ObjectValue
from servostudio.drive.sdo import SdoAbortError, SdoTimeoutError
from servostudio.od import builtin_library
from servostudio.services.projects import Bus, Project
from servostudio.services.projects.live.scaninto import bus_name_for
from servostudio.services.projects.live.source import DriveValues
from servostudio.services.projects.names import is_valid_name

DICTIONARY = builtin_library().load("xtrapulspac")


class ScriptedDrive:
    """Answers a batch of reads from a script: a value, an abort code, undecodable bytes or a timeout."""

    node = 1

    def __init__(self, script: dict[tuple[int, int], object]) -> None:
        self.script = script
        self.requested: list[tuple[int, int]] = []

    def submit_read_all(self, variables):
        self.requested += [variable.key for variable in variables]
        batch = SimpleNamespace(future=Future())
        batch.future.set_result([self._outcome(variable) for variable in variables])
        return batch

    def _outcome(self, variable):
        answer = self.script[variable.key]
        if answer == "timeout":
            return SdoTimeoutError(1, *variable.key, "no SDO response")
        if answer == "undecodable":
            return ValueError(f"{variable.label}: drive answered 01 02: not a value of its type")
        if isinstance(answer, tuple):
            return SdoAbortError(1, *variable.key, answer[1])
        return ObjectValue(1, variable, answer)


def variables(*keys):
    return [DICTIONARY[key] for key in keys]


def test_values_refusals_and_undecodable_answers_are_kept_apart():
    drive = ScriptedDrive(
        {(0x6083, 0): 5, (0x2004, 0): "axis\0\0", (0x6060, 0): ("abort", 0x06020000), (0x6084, 0): "undecodable"}
    )
    source = DriveValues(drive, variables((0x6083, 0), (0x2004, 0), (0x6060, 0), (0x6084, 0)))
    assert drive.requested == [(0x6083, 0), (0x2004, 0), (0x6060, 0), (0x6084, 0)]
    assert [source.read(*key) for key in drive.requested] == [5, "axis", None, None]
    assert "0x06020000" in source.refused[0x6060, 0]
    assert "not a value" in source.refused[0x6084, 0]


def test_a_drive_that_stops_answering_fails_the_read():
    drive = ScriptedDrive({(0x6083, 0): 5, (0x6084, 0): "timeout"})
    with pytest.raises(SdoTimeoutError):
        DriveValues(drive, variables((0x6083, 0), (0x6084, 0)))


@settings(deadline=None)
@given(st.text(max_size=120), st.lists(st.sampled_from(["sim", "sim-2", "bus", "socketcan-can0"]), unique=True))
def test_a_bus_name_derived_from_any_spec_is_valid_and_unused(spec, existing):
    project = Project("p", buses=tuple(Bus(name, "sim") for name in existing))
    name = bus_name_for(spec, project)
    assert is_valid_name(name) and name not in existing
