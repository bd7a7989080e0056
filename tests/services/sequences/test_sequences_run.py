"""The manual's two chaining examples (L10258–10339) run on the simulated drive through the sequence service and
observed by its live monitor (TPDO 4 with 0x3605 first): the executed sequences in exactly the documented order."""

from __future__ import annotations

import time

import pytest
from tests.support.motion import controlling
from tests.support.sequence_programs import CONDITIONAL_JUMP, COUNTER_LOOP

from servostudio.drive.cia402 import State
from servostudio.drive.control import read_state
from servostudio.errors import InvalidInput, RefusedForSafety
from servostudio.formats.sequence import LoadMode
from servostudio.services import sequences
from servostudio.services.sequences import SequenceMonitor

WAIT = 15.0


def run(manager, connection, drive, text: str, first: int = 1, bits: str | None = None) -> list[dict]:
    """Download the program, start ``first`` as the armed controller, and return the monitor's executed list."""
    sequences.download(drive, text, LoadMode.LOAD)
    table = sequences.upload(drive)
    monitor = SequenceMonitor(connection, drive, table).start()
    try:
        with controlling(manager, connection.id, drive.node):
            if bits is not None:
                sequences.set_conditional_input(drive, bits)
            sequences.start(manager.motion, connection.id, drive, first)
            wait_end(monitor)
            sequences.stop(drive)
        return monitor.snapshot()["executed"]  # type: ignore[return-value]
    finally:
        monitor.stop()


def wait_end(monitor: SequenceMonitor) -> None:
    deadline = time.monotonic() + WAIT
    while not monitor.runs() or monitor.running:
        assert time.monotonic() < deadline, f"the program did not end: {monitor.snapshot()}"
        time.sleep(0.02)


def test_counter_loop_runs_1_2_1_2_3(manager, connection, drive):
    executed = run(manager, connection, drive, COUNTER_LOOP)
    assert [entry["sequence"] for entry in executed] == [1, 2, 1, 2, 3]
    assert all(entry["phase"] == "END" for entry in executed)
    times = [entry["t"] for entry in executed]
    assert times == sorted(times)


@pytest.mark.parametrize(("bits", "order"), [("1.......", [1, 2, 3]), ("0.......", [1, 4])])
def test_conditional_jump_follows_input_8(manager, connection, drive, bits, order):
    executed = run(manager, connection, drive, CONDITIONAL_JUMP, bits=bits)
    assert [entry["sequence"] for entry in executed] == order
    assert int(drive.read("sequence_conditional_input").raw) & 0x80 == (0x80 if bits[0] == "1" else 0)


def test_the_counter_is_counted_from_the_executed_sequences(manager, connection, drive):
    sequences.download(drive, COUNTER_LOOP, LoadMode.LOAD)
    monitor = SequenceMonitor(connection, drive, sequences.upload(drive)).start()
    seen: list[object] = []
    try:
        with controlling(manager, connection.id, drive.node):
            sequences.start(manager.motion, connection.id, drive, 1)
            deadline = time.monotonic() + WAIT
            while not monitor.runs() or monitor.running:
                assert time.monotonic() < deadline
                counter = monitor.snapshot()["counter"]
                if counter not in seen:
                    seen.append(counter)
                time.sleep(0.002)
    finally:
        monitor.stop()
    assert {"sequence": 2, "remaining": 1} in seen  # after the first end of sequence 2, before the second


def test_start_needs_the_armed_controller(manager, connection, drive):
    sequences.download(drive, COUNTER_LOOP, LoadMode.LOAD)
    with pytest.raises(RefusedForSafety):
        sequences.start(manager.motion, connection.id, drive, 1)
    assert read_state(drive)[0] is not State.OPERATION_ENABLED


def test_a_sequence_number_past_0x3612_is_refused_before_the_bus(manager, connection, drive):
    with controlling(manager, connection.id, drive.node), pytest.raises(InvalidInput):
        sequences.start(manager.motion, connection.id, drive, 128)
