"""The TTA-PRO's sequence table through its buffer (PNU 780 / 782-794 / 781, then 781 = 128 for the checksum) as
TTASEQ.TXT, judged on the simulated slave's EEPROM image — what the drive would run after its next power-up —
through the project's own DP master over the simulated line's TCP stream, the round trip through pyprofibus too
(docs/profibus.md §13)."""

from __future__ import annotations

import contextlib
import random
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from tests.support.dp_masters import OWN_MASTER, TRANSPORTS, dp_drive, simulated_line

from servostudio.drive.access import Drive
from servostudio.drive.control import fault_report
from servostudio.services.backup import FileKind, RestoreValidationError, backup_file, restore_text
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.parameters import OTHER_ERROR, PkwRefusal
from servostudio.sim.profibus.sequence_table import SequenceTable

ADDRESS = 5
FIELDS = range(782, 795)
E2PSEQ = 19
"""The fault report's code of PNU 773's "sequences EEPROM checksum error"."""


@pytest.fixture
def line() -> Iterator[ProfibusLine]:
    with simulated_line(ADDRESS) as line:
        yield line


@pytest.fixture
def transport() -> str:
    """The project's own master unless a test asks for each (``indirect`` parametrisation)."""
    return OWN_MASTER


@pytest.fixture
def drive(transport: str, line: ProfibusLine) -> Iterator[Drive]:
    with dp_drive(transport, line, ADDRESS) as drive:
        yield drive


def random_sequence(rng: random.Random, number: int) -> dict[int, int]:
    """A valid positioning sequence with every buffer field in its range (783 a position, 788 the link …)."""
    values = {pnu: 0 for pnu in FIELDS}
    values.update({782: 0x0001 | rng.choice((0, 0x4)), 783: rng.randint(-(10**6), 10**6), 784: rng.randint(1, 3000)})
    values.update({785: rng.randint(1, 16000), 786: rng.randint(0, 16000), 787: rng.randint(0, 16000)})
    values.update({788: rng.choice((-1, (number + 1) % 128)), 791: rng.randint(0, 0xFFFF), 792: 0xFF00})
    return values


def eeprom_table(sequences: SequenceTable) -> dict[int, dict[int, int]]:
    """The sequences in use in the slave's EEPROM image, by number, the buffer fields 782-794 only."""
    return {n: {pnu: record[pnu] for pnu in FIELDS} for n, record in enumerate(sequences.eeprom) if record[782]}


def load_eeprom(sequences: SequenceTable, table: dict[int, dict[int, int]]) -> None:
    """Give the slave ``table`` as if written with its checksum long ago."""
    for number, values in table.items():
        sequences.eeprom[number] = {**sequences.eeprom[number], **values}
    sequences.stored_checksum = sequences.checksum()


def test_the_backup_lists_the_sequences_the_eeprom_holds(drive: Drive, line: ProfibusLine, tmp_path: Path) -> None:
    rng = random.Random(7)
    table = {number: random_sequence(rng, number) for number in (0, 3, 64, 127)}
    load_eeprom(line.slaves[ADDRESS].sequences, table)
    result = backup_file(drive, tmp_path / "TTASEQ.TXT")
    assert result.objects == 4 and result.kind == "TTASEQ.TXT"
    lines = [text for text in (tmp_path / "TTASEQ.TXT").read_text().splitlines() if not text.startswith(";")]
    assert lines == [f"{pnu},{number}={table[number][pnu]}" for number in sorted(table) for pnu in FIELDS]


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_a_restored_table_is_the_eeprom_s_and_survives_a_power_cycle(
    drive: Drive, line: ProfibusLine, tmp_path: Path
) -> None:
    slave = line.slaves[ADDRESS]
    rng = random.Random(11)
    table = {number: random_sequence(rng, number) for number in (1, 2, 90)}
    load_eeprom(slave.sequences, table)
    backup_file(drive, tmp_path / "TTASEQ.TXT")
    text = (tmp_path / "TTASEQ.TXT").read_text()
    load_eeprom(slave.sequences, {1: {783: 5}, 40: random_sequence(rng, 40)})  # changed, and one more in use
    result = restore_text(drive, text, FileKind.TTASEQ)
    assert result.ok and result.stored.startswith("sequence checksum"), result.as_dict()
    assert [outcome.label for outcome in result.outcomes] == ["sequence 1", "sequence 2", "sequence 40", "sequence 90"]
    assert eeprom_table(slave.sequences) == table  # 40 cleared: the file is the whole table
    slave.power_cycle()
    assert slave.sequences.checksum_valid and E2PSEQ not in [fault.code for fault in fault_report(drive).faults]
    backup_file(drive, tmp_path / "again" / "TTASEQ.TXT")
    assert _body(tmp_path / "again" / "TTASEQ.TXT") == _body(tmp_path / "TTASEQ.TXT")


def test_a_refused_write_leaves_the_checksum_and_the_drive_reports_it_at_power_up(
    drive: Drive, line: ProfibusLine
) -> None:
    slave = line.slaves[ADDRESS]
    rng = random.Random(5)
    table = {number: random_sequence(rng, number) for number in (0, 1, 2)}

    def refuse_sequence_2(index: int, value: int) -> None:
        if slave.memory.get(783) == table[2][783]:  # the buffer holds sequence 2's position: its speed is refused
            raise PkwRefusal(OTHER_ERROR, "simulated EEPROM write failure")

    slave.memory.on_write(784, refuse_sequence_2)
    text = "".join(f"{pnu},{number}={values[pnu]}\n" for number, values in table.items() for pnu in FIELDS)
    result = restore_text(drive, text, FileKind.TTASEQ)
    assert not result.ok and not result.stored
    assert "PNU 784" in result.error and "checksum was not updated" in result.error
    slave.power_cycle()
    faults = fault_report(drive).faults
    assert E2PSEQ in [fault.code for fault in faults], faults
    assert any(fault.name.startswith("E2PSEQ") and "sequence table" in fault.remedy for fault in faults)


@pytest.mark.parametrize(
    ("line_text", "reason"),
    [
        ("700,0=4", "PNU 700 is no sequence field (PNU 782-794)"),
        ("782,128=1", "IND 128: the sequences are numbered 0-127"),
        ("785,1=0", "sequence 1: "),  # the acceleration is 1..16000 ms
        ("788,1=x", ""),
        ("783,0=1", "duplicate assignment of PNU 783,0 (first at line 2)"),
    ],
)
def test_a_bad_file_is_refused_whole_before_anything_is_written(
    drive: Drive, line: ProfibusLine, line_text: str, reason: str
) -> None:
    slave = line.slaves[ADDRESS]
    written: list[int] = []
    for pnu in (*FIELDS, 780, 781):
        slave.memory.on_write(pnu, lambda index, value, pnu=pnu: written.append(pnu))
    good = "".join(f"{pnu},0={value}\n" for pnu, value in random_sequence(random.Random(1), 0).items())
    with pytest.raises(RestoreValidationError) as refused:
        restore_text(drive, good + line_text + "\n", FileKind.TTASEQ)
    assert str(refused.value).startswith("TTASEQ.TXT:14: ") and reason in str(refused.value)
    assert "nothing was written to node 5" in str(refused.value)
    assert written == []


def test_a_sequence_without_every_field_is_refused(drive: Drive) -> None:
    text = "; sequence 3, its deceleration forgotten\n" + "".join(
        f"{pnu},3={value}\n" for pnu, value in random_sequence(random.Random(2), 3).items() if pnu != 786
    )
    with pytest.raises(RestoreValidationError, match=r"TTASEQ.TXT:2: sequence 3 lacks sequence_deceleration"):
        restore_text(drive, text, FileKind.TTASEQ)


def _body(path: Path) -> list[str]:
    return [text for text in path.read_text().splitlines() if not text.startswith(";")]


def test_a_station_that_keeps_leaving_data_exchange_costs_time_not_the_table(
    drive: Drive, line: ProfibusLine, tmp_path: Path
) -> None:
    """A loaded host that stalls the master past the DP watchdog: each expiry drops the station out of data exchange
    in the middle of a buffer procedure (780 / 781), which is run again once the station is parameterised again."""
    slave = line.slaves[ADDRESS]
    rng = random.Random(3)
    table = {number: random_sequence(rng, number) for number in (4, 5)}
    load_eeprom(slave.sequences, table)
    with _watchdog_expiring_every(line, 0.4) as drops:
        backup_file(drive, tmp_path / "TTASEQ.TXT")
        load_eeprom(slave.sequences, {5: {783: 5}})
        result = restore_text(drive, (tmp_path / "TTASEQ.TXT").read_text(), FileKind.TTASEQ)
    assert result.ok and len(drops) >= 3, (result.as_dict(), drops)
    assert eeprom_table(slave.sequences) == table and slave.sequences.checksum_valid


@contextlib.contextmanager
def _watchdog_expiring_every(line: ProfibusLine, seconds: float) -> Iterator[list[float]]:
    """Drop every station of the line out of data exchange every ``seconds``; the instants it did."""
    stop, drops = threading.Event(), []

    def expire() -> None:
        while not stop.wait(seconds):
            with line.lock:
                for slave in line.slaves.values():
                    slave.station._leave_data_exchange()
            drops.append(time.monotonic())

    thread = threading.Thread(target=expire, daemon=True)
    thread.start()
    try:
        yield drops
    finally:
        stop.set()
        thread.join()
