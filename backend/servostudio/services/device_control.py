"""Device control as the server offers it: the CiA 402 state and the faults of one drive.

Every status word read here is reported to the bus monitor, so ``drive_state`` events follow changes made through
the API as well; every control word goes through the motion guard (``services.motion``).
"""

from __future__ import annotations

from servostudio.drive import control
from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.services.audit import current_actor
from servostudio.services.bus import BusConnection
from servostudio.services.motion import MotionGuard


def drive_state(connection: BusConnection, drive: Drive) -> dict[str, object]:
    """CiA 402 state, status word and the NMT state the node last announced (a PROFIBUS-DP drive has no NMT state:
    none is given)."""
    state, statusword = control.read_state(drive)
    connection.report_statusword(drive.node, statusword)
    answer: dict[str, object] = {"node": drive.node, "state": state.value if state else None, "statusword": statusword}
    if drive.profile.canopen:
        answer["nmt_state"] = connection.nmt_state(drive.node)
    return answer


def change_state(connection: BusConnection, motion: MotionGuard, drive: Drive, target: str) -> dict[str, object]:
    """Walk the drive to the state named ``target``.  The motion guard judges every control word on the way;
    enabling is refused before the first step unless the caller armed the axis (no drive is left half-way up)."""
    wanted = State.parse(target)
    if wanted is State.OPERATION_ENABLED:
        axis = (connection.id, drive.node)
        motion.require_controller(current_actor(), axis, f"enabling node {drive.node} on bus {connection.id}")
    control.set_state(drive, wanted)
    return drive_state(connection, drive)


def reset_faults(connection: BusConnection, drive: Drive) -> control.FaultReport:
    """Fault reset, then the fault report after it."""
    control.reset_faults(drive)
    report = control.fault_report(drive)
    connection.report_statusword(drive.node, report.statusword)
    return report
