"""Old → new in the audit log of a restore (docs/security.md, Audit log): by default a batch of more than 16 objects
is not read first (its entries say ``old: null``); with ``every-write`` (``--audit-old-values``) every entry of
the restore has the value the drive held before, read back from the simulated drive."""

from __future__ import annotations

import pytest
from tests.support.embedded_sim import open_sim

from servostudio.services.audit import AuditLog, AuditQuery
from servostudio.services.backup import backup_file, restore_file
from servostudio.services.bus import ConnectionManager
from servostudio.services.motion import MotionGuard
from servostudio.services.settings import Settings, UnknownAuditChoice

KPV = (0x60F9, 2)


@pytest.mark.parametrize("choice", ["small-writes", "every-write"])
def test_a_restores_entries_have_the_old_values_when_asked_for(tmp_path, choice):
    audit = AuditLog(None)
    manager = ConnectionManager(motion=MotionGuard(audit=audit, old_values_up_to=Settings(audit_old_values=choice)
                                                   .old_values_up_to))  # fmt: skip
    try:
        open_sim(manager, "sim:1")
        drive = manager.get("sim").drive(1)
        saved = tmp_path / "DRIVEPAR.TXT"
        assert backup_file(drive, saved).objects > 16
        kpv = drive.variable(KPV)
        before = drive.read(kpv).raw
        changed = kpv.minimum if before != kpv.minimum else kpv.maximum
        drive.write(kpv, changed)
        assert restore_file(drive, saved).ok
        assert drive.read(kpv).raw == before
    finally:
        manager.close_all()
    writes = [entry for entry in audit.entries(AuditQuery(axis="sim:1", limit=1000)).entries
              if entry["object"] == "0x60F9,2"]  # fmt: skip
    restored, edited = writes[0], writes[1]  # newest first
    assert (edited["old"], edited["new"]) == (before, changed)  # a single write is always read first
    assert restored["new"] == before
    assert restored["old"] == (changed if choice == "every-write" else None)


def test_an_unknown_choice_is_refused_with_the_choices():
    with pytest.raises(UnknownAuditChoice, match="small-writes, every-write"):
        Settings(audit_old_values="sometimes")
