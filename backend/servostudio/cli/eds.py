"""`servostudio eds …`: list, show, check and import object dictionaries."""

from __future__ import annotations

import argparse
from pathlib import Path

from servostudio.cli.output import emit
from servostudio.od import EdsLibrary
from servostudio.services import dictionaries
from servostudio.services.settings import Settings


def register(commands: argparse._SubParsersAction) -> None:
    eds = commands.add_parser("eds", help="object dictionaries (EDS library)")
    eds.add_argument(
        "--user-dir",
        type=Path,
        help="user EDS library directory (default: $SERVOSTUDIO_USER_EDS_DIR, else the user's data)",
    )
    actions = eds.add_subparsers(dest="action", required=True)

    actions.add_parser("list", help="devices of the library").set_defaults(handler=_list)

    show = actions.add_parser("show", help="objects of one device, or one object")
    show.add_argument("device")
    show.add_argument("object", nargs="?", help='address or name, e.g. 0x6041, "60F9,2", KPv')
    show.set_defaults(handler=_show)

    check = actions.add_parser("check", help="validate an EDS (and its .props) without importing it")
    check.add_argument("eds", type=Path)
    check.add_argument("--props", type=Path)
    check.set_defaults(handler=_check)

    imp = actions.add_parser("import", help="validate an EDS and add it to the user library")
    imp.add_argument("eds", type=Path)
    imp.add_argument("--props", type=Path)
    imp.set_defaults(handler=_import)


def _library(args: argparse.Namespace) -> EdsLibrary:
    settings = Settings.given(user_eds_dir=args.user_dir)
    return EdsLibrary(settings.builtin_eds_dir, settings.user_eds_dir)


def _describe(od) -> dict:
    return {
        "device": od.device,
        "product_name": od.product_name,
        "vendor_id": od.vendor_id,
        "product_code": od.product_code,
        "revision": od.revision,
        "objects": len(od.objects()),
        "entries": len(od),
        "source": str(od.source),
    }


def _entry(var) -> dict:
    return {
        "index": f"0x{var.index:04X}",
        "subindex": var.subindex,
        "name": var.name,
        "object": var.parent_name,
        "data_type": var.data_type.name,
        "access": var.access.value,
        "low": var.low,
        "high": var.high,
        "default": var.default_expr,
        "configured": var.parameter_expr,
        "unit": var.unit,
        "save_type": var.save_type.value,
        "group": var.group,
        "description": var.description,
    }


def _list(args: argparse.Namespace) -> int:
    library = _library(args)
    return emit([_describe(library.load(device)) for device in library.devices()])


def _show(args: argparse.Namespace) -> int:
    od = dictionaries.dictionary(_library(args), args.device)
    if args.object is None:
        return emit({**_describe(od), "entries": [_entry(var) for var in od.variables()]})
    return emit(_entry(dictionaries.entry(od, args.object)))


def _check(args: argparse.Namespace) -> int:
    return emit(_describe(dictionaries.check_file(args.eds, args.props)))


def _import(args: argparse.Namespace) -> int:
    library = _library(args)
    device = dictionaries.import_file(library, args.eds, args.props)
    return emit(_describe(library.load(device)))
