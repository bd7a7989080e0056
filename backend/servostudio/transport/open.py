"""Open the python-can bus a spec names (every kind except ``sim``, which the server builds in-process)."""

from __future__ import annotations

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
    except (OSError, ImportError, ValueError) as error:
        raise can.CanInitializationError(f"cannot open {spec}: {error}") from error
