"""Open the python-can bus a spec names (every kind except ``sim``, which the server builds in-process)."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, metadata

import can

from servostudio.transport.socketcand import SocketcandBus
from servostudio.transport.spec import BusSpec, BusSpecError


def open_bus(spec: BusSpec) -> can.BusABC:
    """Open the bus; raise ``can.CanInitializationError`` (or ``can.CanError``) when the interface is not there."""
    if spec.kind == "sim":
        raise BusSpecError("the 'sim' bus is built by the communication server, not opened by the transport layer")
    if spec.kind == "socketcand":
        return SocketcandBus(channel=spec.channel, host=spec.host, port=spec.port)
    try:
        return can.Bus(**spec.python_can_config())
    except can.CanInterfaceNotImplementedError as error:
        raise can.CanInitializationError(f"cannot open {spec}: {error}{_install_hint(spec.kind)}") from error
    except (OSError, ImportError, ValueError, TypeError, NameError) as error:
        # python-can's backends report a missing vendor library or a wrong option in any of these
        raise can.CanInitializationError(f"cannot open {spec}: {error}") from error


#: python-can extras named differently from their interface
_EXTRA_OF = {"udp_multicast": "multicast", "gs_usb": "gs-usb"}


def _install_hint(kind: str) -> str:
    """Name the optional package that brings an interface's driver, when python-can declares one."""
    extra = _EXTRA_OF.get(kind, kind)
    try:
        extras = metadata("python-can").get_all("Provides-Extra") or []
    except PackageNotFoundError:
        return ""
    return f' (its driver package is missing: pip install "python-can[{extra}]")' if extra in extras else ""
