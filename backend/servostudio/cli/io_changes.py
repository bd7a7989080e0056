"""The I/O change a command line asks for (``servostudio io --input IN3=limit_positive:inverted …``), as the REST
body of ``PUT …/io`` (docs/io.md), so the command is the same through a server and on a bus of its own.

``NAME=FUNCTION`` sets a function, ``NAME=FUNCTION:inverted`` (or ``:normal``) its polarity too, ``NAME=:inverted``
the polarity alone; ``--set KEY=VALUE`` a setting (a number, ``0x`` hex, or text such as a pointer).
"""

from __future__ import annotations

import argparse
from typing import Any

from servostudio.errors import InvalidInput
from servostudio.services import io

POLARITIES = {"inverted": True, "normal": False}


class BadIoArgument(InvalidInput):
    """A ``--input`` / ``--output`` / ``--set`` that is not ``NAME=…``."""


def change_body(args: argparse.Namespace) -> dict[str, Any]:
    """The ``PUT …/io`` body of the command's ``--input``, ``--output`` and ``--set`` options."""
    return {
        "inputs": [_row(text, "--input") for text in args.inputs],
        "outputs": [_row(text, "--output") for text in args.outputs],
        "settings": dict(_setting(text) for text in args.settings),
    }


def change_of(args: argparse.Namespace) -> io.IoChange:
    """The same change for ``services.io`` on a bus of the command's own."""
    body = change_body(args)
    return io.IoChange(
        inputs=[io.InputChange(**row) for row in body["inputs"]],
        outputs=[io.OutputChange(**row) for row in body["outputs"]],
        settings=body["settings"],
    )


def asks_a_change(args: argparse.Namespace) -> bool:
    return bool(args.inputs or args.outputs or args.settings)


def _row(text: str, option: str) -> dict[str, Any]:
    name, sign, rest = text.partition("=")
    function, colon, polarity = rest.partition(":")
    if not sign or not name or (colon and polarity not in POLARITIES) or not (function or colon):
        raise BadIoArgument(f"{option} {text!r}: give NAME=FUNCTION, NAME=FUNCTION:inverted|normal or NAME=:inverted")
    return {"name": name, "function": function or None, "inverted": POLARITIES[polarity] if colon else None}


def _setting(text: str) -> tuple[str, int | str]:
    key, sign, value = text.partition("=")
    if not sign or not key or not value:
        raise BadIoArgument(f"--set {text!r}: give KEY=VALUE")
    try:
        return key, int(value, 0)
    except ValueError:
        return key, value
