"""The DP master of a `profibus:` bus spec (`transport/spec.py`: `profibus:PORT[@BAUD][?master=ADDR]`;
docs/profibus.md §7):

- a serial device (an RS-485 adapter, the simulator's pseudo-terminal): pyprofibus's DPM1 over its serial PHY
  (`PyprofibusMaster`), from the optional extra `servostudio[profibus]` (GPL-2.0-or-later);
- `socket://HOST:PORT` (the simulator's TCP stream): the project's own master (`DpMaster`), because pyprofibus's
  serial PHY opens device paths only (`serial.Serial().port = …`, not `serial_for_url`).
"""

from __future__ import annotations

from servostudio.transport.profibus.interface import DpLine
from servostudio.transport.profibus.master import DEFAULT_BAUDRATE, ByteLink, DpLinkError, DpMaster
from servostudio.transport.spec import BusSpec

URL_PREFIX = "socket://"


class ProfibusExtraMissing(DpLinkError):
    """A serial PROFIBUS line needs pyprofibus, which is not installed."""


def open_dp_line(spec: BusSpec) -> DpLine:
    """The master of the line, its port opened (`DpLinkError` when it cannot be)."""
    baudrate = spec.bitrate or DEFAULT_BAUDRATE
    if spec.channel.startswith(URL_PREFIX):
        return DpMaster(ByteLink(spec.channel, baudrate), spec.profibus_master)
    try:  # the optional extra: imported only for a serial line
        from servostudio.transport.profibus.pyprofibus_master import PyprofibusMaster
    except ImportError as error:
        raise ProfibusExtraMissing(
            f"PROFIBUS line {spec.channel} needs pyprofibus (GPL-2.0-or-later), an optional extra: "
            "pip install 'servostudio[profibus]'"
        ) from error
    return PyprofibusMaster(spec.channel, baudrate, spec.profibus_master)
