"""Device control as the server offers it: the CiA 402 state and the faults of one drive.

Every status word read here is reported to the bus monitor, so ``drive_state`` events follow changes made through
the API as well; enabling goes through the motion guard (``services.motion``).
"""

from __future__ import annotations

from servostudio.drive import control
from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.services.bus import BusConnection
from servostudio.services.motion import MotionGuard


def drive_state(connection: BusConnection, drive: Drive) -> dict[str, object]:
    """CiA 402 state, status word and the NMT state the node last announced."""
    state, statusword = control.read_state(drive)
    connection.report_statusword(drive.node, statusword)
    return {
        "node": drive.node,
        "state": state.value if state else None,
        "statusword": statusword,
        "nmt_state": connection.nmt_state(drive.node),
    }


def change_state(
    connection: BusConnection, motion: MotionGuard, client: str | None, drive: Drive, target: str
) -> dict[str, object]:
    """Walk the drive to the state named ``target``; enabling needs the caller's live motion client."""
    motion.change_state(client, (connection.id, drive.node), drive, State.parse(target))
    return drive_state(connection, drive)


def reset_faults(connection: BusConnection, drive: Drive) -> control.FaultReport:
    """Fault reset, then the fault report after it."""
    control.reset_faults(drive)
    report = control.fault_report(drive)
    connection.report_statusword(drive.node, report.statusword)
    return report
