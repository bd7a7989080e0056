"""Select a catalog motor for an axis whose drive is live: the drive gets the motor data and derives the rest itself.

Offline, ``motorselect`` reproduces the drive's side effects of writing 0x6410 (copies into 0x6080, 0x340F, 0x3410…,
current limits 0x6075/0x6073 capped by the drive's own ratings 0x6510, which the project cannot know). With a drive
there is nothing to reproduce: the motor's values are written to the drive (each checked like an online write
before the first is sent), then the written objects and every object the layout says the drive derives are read
back and stored in the project, together with the axis's motor reference, in one project change. The notes name
each derived object the drive changed.
"""

from __future__ import annotations

from dataclasses import replace

from servostudio.drive.access import DEFAULT_WAIT, DriveAccessError
from servostudio.drive.sdo import SdoAbortError
from servostudio.od import Variable
from servostudio.services.projects.errors import ParameterRefused
from servostudio.services.projects.live.links import AxisLink
from servostudio.services.projects.live.source import DriveValues
from servostudio.services.projects.motors import Motor
from servostudio.services.projects.motorselect import LAYOUTS, MotorDataLayout
from servostudio.services.projects.parameter_values import display
from servostudio.services.projects.parameters import ParameterChange, parameter_row
from servostudio.services.projects.service import AxisChoice, ProjectService
from servostudio.services.projects.store import Snapshot

Key = tuple[int, int]


def select_motor_live(
    service: ProjectService, project: str, link: AxisLink, reference: str, expected_revision: str | None = None
) -> AxisChoice:
    motor = service.motors.get(reference)
    layout = LAYOUTS.get(link.axis.device)
    if layout is None:
        raise ParameterRefused(
            f"device '{link.axis.device}' does not take catalog motors (the catalog uses the "
            "XtrapulsPac 0x6410 motor data layout)"
        )
    drive = link.drive()
    writes = _motor_writes(motor, layout)
    checked: list[tuple[Variable, object]] = []
    for key, value in writes:  # all checked before the first frame is sent
        try:
            variable, _raw, _data = drive.prepare_write(drive.variable(key), value)
        except DriveAccessError as error:
            raise ParameterRefused(f"motor '{motor.reference}': {error}; nothing was written") from None
        checked.append((variable, value))
    watched = _watched(drive.dictionary, writes, motor, layout)
    before = DriveValues(drive, watched)
    futures = [(variable, drive.submit_write(variable, value)) for variable, value in checked]
    for position, (variable, future) in enumerate(futures):
        try:
            future.result(DEFAULT_WAIT)
        except SdoAbortError as error:
            raise ParameterRefused(
                f"the drive refused {variable.label}: {error.reason}; {position} of "
                f"{len(futures)} motor values had been written, the project is unchanged"
            ) from None
    after = DriveValues(drive, watched)
    written = {key for key, _value in writes}
    notes = [
        f"the drive set {variable.label}: {display(variable, before.read(*variable.key))} -> "
        f"{display(variable, after.read(*variable.key))}"
        for variable in watched
        if variable.key not in written and before.read(*variable.key) != after.read(*variable.key)
    ]
    with service.store.edit(project, expected_revision) as edit:
        values = service.parameters.axis_values(edit, link.axis.name)
        taken = []
        for variable in watched:
            value = after.read(*variable.key)
            if value is None or values.editable_reason(variable) is not None:
                continue
            values.stage(variable, value)
            taken.append(variable)
        values.commit(edit, link.axis.name)
        service.store.replace_axis(edit, replace(edit.axis(link.axis.name), motor=motor.reference))
    rows = [parameter_row(values, variable) for variable in taken]
    return AxisChoice(ParameterChange(rows, edit.revision), notes, Snapshot(edit.project, edit.revision))


def _motor_writes(motor: Motor, layout: MotorDataLayout) -> list[tuple[Key, object]]:
    """Motor data sub-entries in sub-entry order, then the motor's other objects."""
    data = sorted(((layout.subs[name], value) for name, value in motor.motor_data.items()), key=lambda item: item[0])
    return [*data, *sorted(motor.objects.items())]


def _watched(dictionary, writes: list[tuple[Key, object]], motor: Motor, layout: MotorDataLayout) -> list[Variable]:
    """The written objects and what the drive derives from them (copies, current limits), in dictionary order."""
    keys = {key for key, _value in writes}
    keys |= {layout.copies[name] for name in motor.motor_data if name in layout.copies}
    if {"stall_current", "peak_current"} & set(motor.motor_data):
        keys |= {layout.rated_current, layout.max_current}
    return sorted((variable for key in keys if (variable := dictionary.get(*key)) is not None), key=lambda v: v.key)
