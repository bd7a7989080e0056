"""SEQUENCE.TXT backup and restore through 0x3610/0x3611 on a simulated XtrapulsPac (over socketcand)."""

from __future__ import annotations

import pytest

from servostudio.formats.sequence import Sequence, SequenceTable, SequenceType, read_sequence_file
from servostudio.services.backup import BackupError, FileKind, RestoreValidationError, backup_file, restore_file
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan

TABLE = SequenceTable(
    {
        2: Sequence.of(SequenceType.POS, Pos=40960, Speed=1000, Accel=500, Decel=500, Tempo=100, SeqNext=5),
        5: Sequence.of(SequenceType.SPEED, Speed=-300, AccelTime=50, DecelTime=60, RunTime=2000),
    }
)


@pytest.fixture(scope="module")
def drive(socketcand):
    manager = ConnectionManager()
    bus = manager.open(socketcand.spec)
    scan(bus, nodes=[1])
    yield bus.drive(1)
    manager.close_all()


def _load(drive, table: SequenceTable) -> None:
    """Put a table into sequence memory the way the tool restores it (LOAD semantics)."""
    count = int(drive.read("max_sequences").raw)
    for write in table.to_object_writes(clear_below=count):
        drive.submit_write((write.index, write.sub), write.value)
    drive.read("max_sequences")  # the node's FIFO: every write above is done


def test_sequence_backup_then_restore(drive, tmp_path):
    _load(drive, TABLE)
    path = tmp_path / "SEQUENCE.TXT"
    result = backup_file(drive, path)
    assert result.kind == "SEQUENCE.TXT" and result.objects == 2
    assert read_sequence_file(path) == TABLE

    _load(drive, SequenceTable({1: Sequence.of(SequenceType.SPEED, Speed=10)}))
    restored = restore_file(drive, path)
    assert restored.ok, restored.as_dict()
    assert restored.stored == "save_sequences"
    again = tmp_path / "again_SEQUENCE.TXT"
    backup_file(drive, again, FileKind.SEQUENCE)
    assert read_sequence_file(again) == TABLE


def test_invalid_sequence_file_is_refused_with_its_line(drive, tmp_path):
    path = tmp_path / "SEQUENCE.TXT"
    path.write_text("SeqNb=1\nSeqType=SPEED\nSpeed=100\nAccelTime=200000\n", encoding="latin-1")
    with pytest.raises(RestoreValidationError) as error:
        restore_file(drive, path)
    assert "SEQUENCE.TXT" in str(error.value) and ":4" in str(error.value)
    assert "nothing was written" in str(error.value)
    assert isinstance(error.value, BackupError)
