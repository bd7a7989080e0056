"""`servostudio project …`: the project store from the command line (same service as the REST API).

Exit codes (the kind of the error, ``servostudio.errors``): 0 done; 3 refused (bad value, rule broken, conflicting
change, unsafe archive, a drive that is not the axis's device; nothing written); 4 not found (project, axis, object,
motor, template); 5 communication (bus not connected, drive not answering, values the drive refused).
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
from pathlib import Path

from servostudio.cli.audit import audit_log, guarded_connections, local_actor
from servostudio.cli.output import emit
from servostudio.errors import CommunicationError, InvalidInput, NotFound
from servostudio.od import EdsLibrary
from servostudio.services import dictionaries
from servostudio.services.audit import acting_as
from servostudio.services.projects import Axis, Bus, DriveMismatch, ProjectService
from servostudio.services.projects.fsutil import atomic_write
from servostudio.services.projects.jsonview import (
    choice_view,
    compare_view,
    motor_view,
    parameter_view,
    project_view,
    summaries,
    template_view,
    value_change_view,
)
from servostudio.services.projects.live import LiveProjects
from servostudio.services.projects.motors import motor_from_text
from servostudio.services.projects.templates import templates_for
from servostudio.services.settings import Settings


def register(commands: argparse._SubParsersAction) -> None:
    project = commands.add_parser("project", help="projects, axes and offline parameters")
    project.add_argument("--projects", type=Path, default=Path("projects"), help="project store directory")
    project.add_argument(
        "--user-eds-dir", type=Path, help="user EDS library (default: $SERVOSTUDIO_USER_EDS_DIR, else the user's data)"
    )
    actions = project.add_subparsers(dest="action", required=True)

    def action(name: str, handler, summary: str) -> argparse.ArgumentParser:
        parser = actions.add_parser(name, help=summary)
        parser.set_defaults(handler=lambda args: _run(handler, args))
        return parser

    def revision(parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--revision", help="refuse the change if the project changed since this revision")

    def via(parser: argparse.ArgumentParser) -> None:
        parser.add_argument(
            "--via",
            action="append",
            default=[],
            metavar="BUS=SPEC",
            help="reach a project bus through another bus spec for this command, e.g. "
            "sim=socketcand:127.0.0.1:29536 (repeatable)",
        )

    action("list", _list, "projects of the store")
    create = action("create", _create, "create an empty project")
    create.add_argument("name")
    create.add_argument("--description", default="")
    create.add_argument(
        "--bus",
        action="append",
        default=[],
        metavar="NAME=INTERFACE[@BITRATE]",
        help="a bus, e.g. sim=sim or can0=socketcan:can0@500000 (repeatable)",
    )
    action("show", _show, "a project with its buses and axes").add_argument("name")
    delete = action("delete", _delete, "delete a project")
    delete.add_argument("name")
    revision(delete)
    for name, handler, text in (
        ("rename", _rename, "rename a project"),
        ("duplicate", _duplicate, "copy a project under a new name"),
    ):
        parser = action(name, handler, text)
        parser.add_argument("name")
        parser.add_argument("new_name")
        revision(parser)

    add = action("axis-add", _axis_add, "add an axis")
    add.add_argument("name")
    add.add_argument("axis")
    add.add_argument("--device", required=True, help="device key, e.g. xtrapulspac")
    add.add_argument("--node", type=int, required=True, help="node ID")
    add.add_argument("--bus", required=True)
    add.add_argument("--description", default="")
    revision(add)
    edit = action("axis-edit", _axis_edit, "change an axis (name, device, node ID, bus, description)")
    edit.add_argument("name")
    edit.add_argument("axis")
    edit.add_argument("--new-name")
    edit.add_argument("--device")
    edit.add_argument("--node", type=int)
    edit.add_argument("--bus")
    edit.add_argument("--description")
    revision(edit)
    remove = action("axis-remove", _axis_remove, "remove an axis and its files")
    remove.add_argument("name")
    remove.add_argument("axis")
    revision(remove)

    setter = action("set", _set, "set parameters of an axis in the project (all or nothing)")
    setter.add_argument("name")
    setter.add_argument("axis")
    setter.add_argument("assignments", nargs="+", metavar="ADDRESS=VALUE", help='e.g. 0x6060=-3 "60F9,2=1200"')
    revision(setter)
    getter = action("get", _get, "one parameter of an axis: project value, default, file")
    getter.add_argument("name")
    getter.add_argument("axis")
    getter.add_argument("address")
    reset = action("reset", _reset, "drop project values: the objects follow their defaults again")
    reset.add_argument("name")
    reset.add_argument("axis")
    reset.add_argument("addresses", nargs="+")
    revision(reset)
    params = action("params", _params, "parameters of an axis")
    params.add_argument("name")
    params.add_argument("axis")
    params.add_argument("--group")
    params.add_argument("--only-set", action="store_true", help="only objects the project files set")
    params.add_argument("--only-differences", action="store_true", help="only values that differ from default")
    params.add_argument("--all", action="store_true", help="also objects not saved in a drive file")
    compare = action("compare", _compare, "compare project values with the dictionary defaults (and the drive)")
    compare.add_argument("name")
    compare.add_argument("axis")
    compare.add_argument("--group")
    compare.add_argument("--only-differences", action="store_true")
    compare.add_argument("--drive", action="store_true", help="add the live drive's values (opens the axis's bus)")
    compare.add_argument(
        "--read-only", action="store_true", help="also the read-only entries, apart (key read_only; never counted)"
    )
    via(compare)
    take = action("take", _take, "store the drive's values in the project (default: every differing object)")
    take.add_argument("name")
    take.add_argument("axis")
    take.add_argument("addresses", nargs="*", metavar="ADDRESS")
    revision(take)
    via(take)
    write = action("write", _write, "write the project's values to the drive (default: every differing object)")
    write.add_argument("name")
    write.add_argument("axis")
    write.add_argument("addresses", nargs="*", metavar="ADDRESS")
    write.add_argument("--store", action="store_true", help="save the drive's parameters to flash afterwards")
    via(write)
    commission = action("commission", _commission, "check every axis's drive; --download or --upload the files")
    commission.add_argument("name")
    direction = commission.add_mutually_exclusive_group()
    direction.add_argument(
        "--download",
        dest="direction",
        action="store_const",
        const="download",
        help="project values → drives (validated, written, verified, stored)",
    )
    direction.add_argument(
        "--upload", dest="direction", action="store_const", const="upload", help="drives' files → project"
    )
    commission.add_argument("--axis", action="append", dest="axes", metavar="AXIS", help="only this axis (repeatable)")
    revision(commission)
    via(commission)
    scan = action("scan", _scan, "scan a bus and add an axis for every identified node")
    scan.add_argument("name")
    scan.add_argument(
        "--bus",
        required=True,
        metavar="BUS_OR_SPEC",
        help="a bus of the project or a bus spec, e.g. "
        "sim or socketcand:127.0.0.1:29536 (a new spec is added to the project)",
    )
    scan.add_argument("--bus-name", help="name of the new bus (default: derived from the spec)")
    scan.add_argument("--create", action="store_true", help="create the project if it does not exist")
    revision(scan)

    archive = action("archive", _archive, "pack a project into one zip file")
    archive.add_argument("name")
    archive.add_argument("output", type=Path)
    unarchive = action("unarchive", _unarchive, "unpack a project archive into the store")
    unarchive.add_argument("archive", type=Path)
    unarchive.add_argument("--name", help="store it under this name")
    dcf = action("dcf", _dcf, "write the DCF (CiA 306) of an axis")
    dcf.add_argument("name")
    dcf.add_argument("axis")
    dcf.add_argument("output", type=Path)
    dcf_import = action("dcf-import", _dcf_import, "set an axis's offline values to what a DCF configures")
    dcf_import.add_argument("name")
    dcf_import.add_argument("axis")
    dcf_import.add_argument("dcf", type=Path)
    dcf_import.add_argument("--dry-run", action="store_true", help="check it and say what would change; write nothing")
    revision(dcf_import)
    action(
        "revisions", _revisions, "kept revisions: the project before each change that replaced many values"
    ).add_argument("name")
    restore = action("revision-restore", _revision_restore, "make the project what it was at a kept revision")
    restore.add_argument("name")
    restore.add_argument("kept", metavar="REVISION", help="a kept revision (see `revisions`)")
    revision(restore)

    action("motor-list", _motor_list, "motors of the catalog")
    motor_add = action("motor-add", _motor_add, "add a motor file to the user catalog")
    motor_add.add_argument("file", type=Path)
    action("motor-remove", _motor_remove, "remove a user motor from the catalog").add_argument("reference")
    select = action("motor-select", _motor_select, "select a catalog motor for an axis")
    select.add_argument("name")
    select.add_argument("axis")
    select.add_argument("reference")
    select.add_argument(
        "--drive", action="store_true", help="write the motor to the live drive and read back what it derived"
    )
    revision(select)
    via(select)
    templates = action("template-list", _template_list, "Device Config templates of a device")
    templates.add_argument("--device", default="xtrapulspac")
    apply = action("template-apply", _template_apply, "apply a Device Config template to an axis")
    apply.add_argument("name")
    apply.add_argument("axis")
    apply.add_argument("template")
    revision(apply)


@functools.cache
def _library(builtin_dir: Path, user_dir: Path) -> EdsLibrary:
    """One library per directory pair, so a process running several commands parses each EDS once."""
    return EdsLibrary(builtin_dir, user_dir)


def _run(handler, args: argparse.Namespace) -> int:
    """Run an action on the store; errors go to ``main``, which exits with their kind's code."""
    settings = Settings.given(projects_dir=args.projects, user_eds_dir=args.user_eds_dir)
    library = _library(settings.builtin_eds_dir, settings.user_eds_dir)
    audit = audit_log(settings)
    service = ProjectService(settings.projects_dir, library, settings.motors_dir, audit)
    args.connections = guarded_connections(audit, library=library)  # live actions open buses in it
    try:
        with acting_as(local_actor()):
            return emit(handler(service, args))
    finally:
        args.connections.close_all()


def _live(service: ProjectService, args: argparse.Namespace) -> LiveProjects:
    """Live commands open the buses they need; ``_run`` closes them when the command ends."""
    return LiveProjects(service, args.connections)


def _via(args: argparse.Namespace) -> dict[str, str]:
    routes = {}
    for text in getattr(args, "via", []):
        bus, equals, spec = text.partition("=")
        if not equals or not bus or not spec:
            raise InvalidInput(f"--via {text!r}: expected BUS=SPEC")
        routes[bus] = spec
    return routes


def _list(service: ProjectService, args: argparse.Namespace) -> list[dict]:
    return summaries(service.store)


def _create(service: ProjectService, args: argparse.Namespace) -> dict:
    return project_view(service.store.create(args.name, args.description, tuple(_bus(text) for text in args.bus)))


def _bus(text: str) -> Bus:
    name, equals, rest = text.partition("=")
    interface, at, bitrate = rest.partition("@")
    if not equals or not interface or (at and not bitrate.isdigit()):
        raise InvalidInput(f"--bus {text!r}: expected NAME=INTERFACE or NAME=INTERFACE@BITRATE")
    return Bus(name, interface, int(bitrate) if at else None)


def _show(service: ProjectService, args: argparse.Namespace) -> dict:
    return project_view(service.store.open(args.name))


def _delete(service: ProjectService, args: argparse.Namespace) -> dict:
    service.store.delete(args.name, args.revision)
    return {"deleted": args.name}


def _rename(service: ProjectService, args: argparse.Namespace) -> dict:
    return project_view(service.store.rename(args.name, args.new_name, args.revision))


def _duplicate(service: ProjectService, args: argparse.Namespace) -> dict:
    return project_view(service.store.duplicate(args.name, args.new_name))


def _axis_add(service: ProjectService, args: argparse.Namespace) -> dict:
    axis = Axis(args.axis, args.device, args.node, args.bus, args.description)
    return project_view(service.store.add_axis(args.name, axis, args.revision))


def _axis_edit(service: ProjectService, args: argparse.Namespace) -> dict:
    changes = {
        key: value
        for key, value in (
            ("name", args.new_name),
            ("device", args.device),
            ("node_id", args.node),
            ("bus", args.bus),
            ("description", args.description),
        )
        if value is not None
    }
    return project_view(service.store.edit_axis(args.name, args.axis, args.revision, **changes))


def _axis_remove(service: ProjectService, args: argparse.Namespace) -> dict:
    return project_view(service.store.remove_axis(args.name, args.axis, args.revision))


def _set(service: ProjectService, args: argparse.Namespace) -> dict:
    changes = {}
    for text in args.assignments:
        address, equals, value = text.partition("=")
        if not equals:
            raise InvalidInput(f"{text!r}: expected ADDRESS=VALUE")
        changes[address] = value
    change = service.parameters.set(args.name, args.axis, changes, args.revision)
    return {"parameters": [parameter_view(row) for row in change.rows], "revision": change.revision}


def _get(service: ProjectService, args: argparse.Namespace) -> dict:
    row, _revision = service.parameters.get(args.name, args.axis, args.address)
    return parameter_view(row)


def _reset(service: ProjectService, args: argparse.Namespace) -> dict:
    change = service.parameters.unset(args.name, args.axis, args.addresses, args.revision)
    return {"parameters": [parameter_view(row) for row in change.rows], "revision": change.revision}


def _params(service: ProjectService, args: argparse.Namespace) -> dict:
    rows, revision = service.parameters.rows(
        args.name,
        args.axis,
        group=args.group,
        only_set=args.only_set,
        only_differences=args.only_differences,
        include_unsaved=args.all,
    )
    return {"parameters": [parameter_view(row) for row in rows], "revision": revision}


def _compare(service: ProjectService, args: argparse.Namespace) -> dict:
    if not args.drive:
        rows, revision = service.parameters.compare(
            args.name, args.axis, group=args.group, only_differences=args.only_differences
        )
        apart = service.parameters.read_only(args.name, args.axis, group=args.group) if args.read_only else []
        result = {"columns": ["project", "default"], "rows": [compare_view(row) for row in rows], "revision": revision}
        return result | ({"read_only": [compare_view(row) for row in apart]} if args.read_only else {})
    live = _live(service, args).compare(
        args.name,
        args.axis,
        group=args.group,
        only_differences=args.only_differences,
        buses=_via(args),
        read_only=args.read_only,
    )
    result = {
        "columns": ["drive", "project", "default"],
        "rows": [compare_view(row) for row in live.rows],
        "revision": live.revision,
        "refused": live.refused,
    }
    return result | ({"read_only": [compare_view(row) for row in live.read_only]} if args.read_only else {})


def _revisions(service: ProjectService, args: argparse.Namespace) -> list[dict]:
    return [dataclasses.asdict(item) for item in service.revisions(args.name)]


def _revision_restore(service: ProjectService, args: argparse.Namespace) -> dict:
    return project_view(service.restore_revision(args.name, args.kept, args.revision))


def _take(service: ProjectService, args: argparse.Namespace) -> dict:
    change = _live(service, args).take(args.name, args.axis, args.addresses or None, args.revision, _via(args))
    return {"parameters": [parameter_view(row) for row in change.rows], "revision": change.revision}


def _write(service: ProjectService, args: argparse.Namespace) -> dict:
    report = _live(service, args).write(args.name, args.axis, args.addresses or None, args.store, _via(args))
    if not report.ok:
        emit(report.as_dict())
        raise CommunicationError(f"axis '{args.axis}': the drive refused some values (see the report)")
    return report.as_dict()


def _commission(service: ProjectService, args: argparse.Namespace) -> dict:
    report = _live(service, args).commission(args.name, args.direction or "check", args.axes, args.revision, _via(args))
    if report.ok:
        return report.as_dict()
    emit(report.as_dict())
    failed = [axis for axis in report.axes if not axis.ok]
    only_mismatch = all(axis.link.status == "wrong_device" for axis in failed)
    names = ", ".join(axis.link.axis.name for axis in failed)
    message = f"project '{args.name}': axes {names} not commissioned (see the report)"
    raise DriveMismatch(message) if only_mismatch else CommunicationError(message)


def _scan(service: ProjectService, args: argparse.Namespace) -> dict:
    report = _live(service, args).scan(args.name, args.bus, args.bus_name, args.revision, args.create)
    return {
        "bus": report.bus.name,
        "bus_added": report.bus_added,
        "nodes": [node.as_dict() for node in report.nodes],
        "project": project_view(report.snapshot),
    }


def _archive(service: ProjectService, args: argparse.Namespace) -> dict:
    return {"archive": str(service.archive(args.name, args.output))}


def _unarchive(service: ProjectService, args: argparse.Namespace) -> dict:
    return project_view(service.unarchive(args.archive, args.name))


def _dcf(service: ProjectService, args: argparse.Namespace) -> dict:
    text = service.dcf(args.name, args.axis)
    atomic_write(args.output, text.encode("latin-1"))
    return {"dcf": str(args.output)}


def _dcf_import(service: ProjectService, args: argparse.Namespace) -> dict:
    text = dictionaries.read_file_text(args.dcf)
    if args.dry_run:
        imported = service.preview_dcf(args.name, args.axis, text, str(args.dcf))
    else:
        imported = service.import_dcf(args.name, args.axis, text, str(args.dcf), args.revision)
    return {
        "parameters": [parameter_view(row) for row in imported.change.rows],
        "changes": [value_change_view(change) for change in imported.changes],
        "skipped": imported.skipped,
        "revision": imported.change.revision,
    }


def _motor_list(service: ProjectService, args: argparse.Namespace) -> list[dict]:
    return [motor_view(motor) for motor in service.motors.motors()]


def _motor_add(service: ProjectService, args: argparse.Namespace) -> dict:
    try:
        text = args.file.read_text(encoding="utf-8")
    except OSError as error:
        raise NotFound(f"{args.file}: {error.strerror}") from None
    return motor_view(service.motors.add(motor_from_text(text, args.file)))


def _motor_remove(service: ProjectService, args: argparse.Namespace) -> dict:
    service.motors.remove(args.reference)
    return {"removed": args.reference}


def _motor_select(service: ProjectService, args: argparse.Namespace) -> dict:
    if args.drive:
        return choice_view(
            _live(service, args).select_motor(args.name, args.axis, args.reference, args.revision, _via(args))
        )
    return choice_view(service.select_motor(args.name, args.axis, args.reference, args.revision))


def _template_list(service: ProjectService, args: argparse.Namespace) -> list[dict]:
    return [template_view(template) for template in templates_for(args.device)]


def _template_apply(service: ProjectService, args: argparse.Namespace) -> dict:
    return choice_view(service.apply_template(args.name, args.axis, args.template, args.revision))
