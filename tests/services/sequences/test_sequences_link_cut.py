"""A link cut during a download (docs/sequences.md, Sequence memory): the error says which sequences reached RAM,
and the flash copy is what was stored before — the drive LOADs it again once the link is back."""

from __future__ import annotations

import pytest
from tests.support.sequence_programs import CONDITIONAL_JUMP, COUNTER_LOOP

from servostudio.formats.sequence import LoadMode
from servostudio.services import sequences
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan

NODE = 2
CUT_AFTER = 200  # writes queued before the cut: a few sequences' worth of the 128 × 27 of a LOAD


def open_drive(endpoint):
    manager = ConnectionManager()
    connection = manager.open(endpoint.spec, wait=5.0)
    scan(connection, nodes=[NODE])
    return manager, connection.drive(NODE)


def test_a_cut_link_leaves_the_flash_copy_and_names_what_reached_ram(socketcand, monkeypatch):
    manager, drive = open_drive(socketcand)
    try:
        assert sequences.download(drive, COUNTER_LOOP, LoadMode.LOAD, store=True).stored
        submitted = {"count": 0}
        submit = drive.submit_write

        def cutting(*args, **kwargs):
            submitted["count"] += 1
            if submitted["count"] == CUT_AFTER:
                socketcand.cut()
            return submit(*args, **kwargs)

        monkeypatch.setattr(drive, "submit_write", cutting)
        with pytest.raises(sequences.SequenceTransferError) as cut:
            sequences.download(drive, CONDITIONAL_JUMP, LoadMode.LOAD, store=True)
        assert "Sequences written to RAM:" in str(cut.value) and "flash copy (SEQUENCE.TXT) is unchanged" in str(
            cut.value
        )
    finally:
        manager.close_all()
        if socketcand.server is None:
            socketcand.restore()
    manager, drive = open_drive(socketcand)
    try:
        sequences.reload(drive, LoadMode.LOAD)
        assert sequences.upload(drive) == sequences.parse(COUNTER_LOOP)
    finally:
        manager.close_all()
