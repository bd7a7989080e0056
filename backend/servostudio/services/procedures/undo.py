"""Undo an auto-tuning: write the gains of a result's ``before`` back, every value checked before anything is sent.

Only the objects auto-tuning changes may be written this way (a result cannot be used to write anything else), and
only the whole set: one unknown name or one value out of range refuses all of it.
"""

from __future__ import annotations

from collections.abc import Mapping

from servostudio.drive.access import Drive
from servostudio.drive.profiles.procedures import ProcedureDescription
from servostudio.drive.sdo import settle
from servostudio.errors import InvalidInput
from servostudio.services.procedures.run import read_values


class BadUndo(InvalidInput):
    """Gains refused before anything was written."""


def undo_gains(drive: Drive, description: ProcedureDescription, gains: Mapping[str, object]) -> dict[str, object]:
    """Write ``gains`` (semantic name → raw) back; returns them as read back."""
    if not gains:
        raise BadUndo("no gains to write back: give the 'before' of an auto-tuning result")
    allowed = set(description.results)
    foreign = sorted(set(gains) - allowed)
    if foreign:
        raise BadUndo(
            f"node {drive.node}: {', '.join(foreign)} are not auto-tuning gains of the {drive.profile.device}"
        )
    prepared = []
    for name, value in gains.items():
        if isinstance(value, bool) or not isinstance(value, int):
            raise BadUndo(f"node {drive.node}: {name} = {value!r}: a raw gain is an integer")
        variable, raw, _ = drive.prepare_write(name, value)
        prepared.append((variable, raw))
    settle(drive.submit_write_all(prepared).future)
    return {"gains": read_values(drive, list(gains))}
