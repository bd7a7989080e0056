"""Plain-dict views of project results: one definition shared by the REST models and the CLI's JSON output."""

from __future__ import annotations

import dataclasses

from servostudio.services.projects.compare import CompareRow
from servostudio.services.projects.errors import ProjectError
from servostudio.services.projects.motors import Motor
from servostudio.services.projects.parameter_values import display
from servostudio.services.projects.parameters import ParameterRow
from servostudio.services.projects.service import AxisChoice, ValueChange
from servostudio.services.projects.store import ProjectStore, Snapshot
from servostudio.services.projects.templates import ApplicationTemplate


def project_view(snapshot: Snapshot) -> dict:
    project = snapshot.project
    return {
        "name": project.name,
        "description": project.description,
        "buses": [dataclasses.asdict(bus) for bus in project.buses],
        "axes": [dataclasses.asdict(axis) for axis in project.axes],
        "revision": snapshot.revision,
    }


def summaries(store: ProjectStore) -> list[dict]:
    """Every project of the store; one whose files cannot be read is listed with the reason instead of failing all."""
    result = []
    for name in store.names():
        try:
            snapshot = store.open(name)
        except ProjectError as error:
            result.append({"name": name, "description": "", "axis_count": 0, "revision": "", "error": str(error)})
            continue
        result.append(
            {
                "name": name,
                "description": snapshot.project.description,
                "axis_count": len(snapshot.project.axes),
                "revision": snapshot.revision,
                "error": None,
            }
        )
    return result


def parameter_view(row: ParameterRow) -> dict:
    variable = row.variable
    return {
        "index": variable.index,
        "subindex": variable.subindex,
        "name": variable.label,
        "group": variable.group,
        "data_type": variable.data_type.name,
        "access": variable.access.value,
        "save_type": variable.save_type.value,
        "unit": variable.unit,
        "value": display(variable, row.value),
        "default": display(variable, row.default),
        "differs_from_default": row.differs_from_default,
        "file": row.file,
        "editable": row.editable_reason is None,
        "not_editable_reason": row.editable_reason,
    }


def value_change_view(change: ValueChange) -> dict:
    """One project value a change replaces, old and new as the parameter rows show values."""
    variable = change.variable
    return {
        "index": variable.index,
        "subindex": variable.subindex,
        "name": variable.label,
        "unit": variable.unit,
        "old": display(variable, change.old),
        "new": display(variable, change.new),
    }


def compare_view(row: CompareRow) -> dict:
    variable = row.variable
    return {
        "index": variable.index,
        "subindex": variable.subindex,
        "name": variable.label,
        "group": variable.group,
        "unit": variable.unit,
        "values": {name: display(variable, value) for name, value in row.values.items()},
        "differs": row.differs,
    }


def choice_view(choice: AxisChoice) -> dict:
    return {
        "changed": [parameter_view(row) for row in choice.change.rows],
        "notes": choice.notes,
        "project": project_view(choice.snapshot),
    }


def template_view(template: ApplicationTemplate) -> dict:
    return {
        "key": template.key,
        "title": template.title,
        "description": template.description,
        "settings": [{"index": s.index, "subindex": s.sub, "value": s.value, "why": s.why} for s in template.settings],
        "groups": list(template.groups) if template.groups is not None else None,
    }


def motor_view(motor: Motor) -> dict:
    return {
        "reference": motor.reference,
        "description": motor.description,
        "source": motor.source,
        "motor_data": dict(motor.motor_data),
        "objects": {f"0x{index:04X},{sub}": value for (index, sub), value in motor.objects.items()},
        "builtin": motor.builtin,
    }
