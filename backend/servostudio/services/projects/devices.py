"""Device facts a project needs before any drive is connected: addressing rules and the drive files of an axis.

The files come from the drive profiles (``servostudio.drive.profiles``); the addressing rules are kept here, keyed
by device key, until the profiles carry them. Imported EDS devices get the CANopen range and the generic profile.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from servostudio.drive.profiles import profile_for
from servostudio.od import SaveType
from servostudio.services.projects import layout

CANOPEN_NODE_IDS = range(1, 128)


@dataclass(frozen=True)
class Addressing:
    node_ids: range
    reason: str
    redirect_offset: int | None = None   # the device also serves SDO as node n + offset: no other node may use it


ADDRESSING: dict[str, Addressing] = {
    "xtrapulspac": Addressing(
        range(1, 64),
        "XtrapulsPac node IDs are 1-63 (front-panel switches); n+64 is its redirected SDO channel (manual L2565-2589)",
        redirect_offset=64,
    ),
    "cd1k": Addressing(CANOPEN_NODE_IDS, "CD1-k node IDs are 1-127 (switches)"),
    "encotrive": Addressing(CANOPEN_NODE_IDS, "encoTRive node IDs are 1-127"),
}


def addressing(device: str) -> Addressing:
    return ADDRESSING.get(device, Addressing(CANOPEN_NODE_IDS, "CANopen node IDs are 1-127"))


def parameter_files(device: str) -> Mapping[str, SaveType]:
    """The device's parameter files and the save type of the objects each holds, in the order the drive applies
    them (a later file overrides an earlier one: XtrapulsPac loads DRIVEPAR.TXT, then USER_PAR.TXT with 'lusr')."""
    return profile_for(device).parameter_files


def axis_files(device: str) -> tuple[str, ...]:
    """Every file an axis directory of this device holds: the parameter files, plus SEQUENCE.TXT if it has one."""
    profile = profile_for(device)
    return (*profile.parameter_files, *((layout.SEQUENCE,) if profile.has_sequences else ()))
