"""Bus spec strings: one short text names a CAN interface, its channel and bit rate.

``socketcan:can0``, ``pcan:PCAN_USBBUS1@1000000``, ``ixxat:0@500000``, ``kvaser:0``,
``slcan:/dev/ttyACM0@1000000``, ``socketcand:HOST:PORT[/CHANNEL]``, ``virtual:NAME``,
``serial:PORT_OR_URL[@BAUD]`` (the XtrapulsPac RS-232 link) and ``sim[:NODES]`` (simulated drives in
this process, NODES as for ``servostudio sim``, e.g. ``1:xtrapulspac,2:cd1k``).  A spec is what the user types on
the command line and what the REST API takes, so the parser names the problem precisely.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

KINDS = ("socketcan", "pcan", "ixxat", "kvaser", "slcan", "socketcand", "virtual", "serial", "sim")
_WITH_BITRATE = {"pcan", "ixxat", "kvaser", "slcan", "serial"}
_INTEGER_CHANNEL = {"ixxat", "kvaser"}
SERIAL_BAUDRATES = (9600, 19200, 38400, 57600, 115200)
DEFAULT_SERIAL_BAUDRATE = 19200
DEFAULT_SOCKETCAND_CHANNEL = "can0"
DEFAULT_SIM_NODES = "1,2,3"
_RATE = re.compile(r"^(\d+)([kKmM]?)$")
_SIM_NODES = re.compile(r"^\d+(:[A-Za-z0-9_-]+)?(,\d+(:[A-Za-z0-9_-]+)?)*$")


class BusSpecError(ValueError):
    """A spec string that does not name a usable bus; the message says which part is wrong and why."""


@dataclass(frozen=True)
class BusSpec:
    """A parsed bus spec; ``str(spec)`` gives back the canonical text."""

    kind: str
    channel: str = ""
    bitrate: int | None = None
    host: str = ""
    port: int = 0

    def __str__(self) -> str:
        if self.kind == "socketcand":
            return f"socketcand:{self.host}:{self.port}/{self.channel}"
        if self.kind == "sim":
            return "sim" if self.channel == DEFAULT_SIM_NODES else f"sim:{self.channel}"
        text = f"{self.kind}:{self.channel}"
        return f"{text}@{self.bitrate}" if self.bitrate is not None else text

    def python_can_config(self) -> dict[str, object]:
        """Keyword arguments for ``can.Bus(**config)``; not available for ``sim`` (opened in-process)."""
        if self.kind == "sim":
            raise BusSpecError("the 'sim' bus is opened in-process, not through python-can")
        if self.kind == "socketcand":
            return {"interface": "socketcand", "host": self.host, "port": self.port, "channel": self.channel}
        if self.kind == "serial":
            return {
                "interface": "servostudio_rs232",
                "channel": self.channel,
                "baudrate": self.bitrate or DEFAULT_SERIAL_BAUDRATE,
            }
        config: dict[str, object] = {"interface": self.kind, "channel": self.channel}
        if self.kind in _INTEGER_CHANNEL:
            config["channel"] = int(self.channel)
        if self.bitrate is not None:
            config["bitrate"] = self.bitrate
        return config


def parse_bus_spec(text: str) -> BusSpec:
    """Parse a bus spec string; raise BusSpecError naming the wrong part."""
    text = text.strip()
    kind, colon, rest = text.partition(":")
    kind = kind.lower()
    if kind not in KINDS:
        raise BusSpecError(f"bus {text!r}: unknown interface {kind!r}; expected one of {', '.join(KINDS)}")
    if kind == "sim":
        return _parse_sim(text, rest if colon else DEFAULT_SIM_NODES)
    if not rest:
        raise BusSpecError(f"bus {text!r}: missing channel after '{kind}:'")
    if kind == "socketcand":
        return _parse_socketcand(text, rest)
    channel, bitrate = _split_bitrate(text, kind, rest)
    if not channel:
        raise BusSpecError(f"bus {text!r}: missing channel before '@'")
    if kind in _INTEGER_CHANNEL and not channel.isdigit():
        raise BusSpecError(f"bus {text!r}: {kind} channel must be a number, not {channel!r}")
    if kind == "serial" and bitrate is not None and bitrate not in SERIAL_BAUDRATES:
        allowed = ", ".join(map(str, SERIAL_BAUDRATES))
        raise BusSpecError(f"bus {text!r}: serial baud rate {bitrate} not supported; use one of {allowed}")
    return BusSpec(kind=kind, channel=channel, bitrate=bitrate)


def _split_bitrate(text: str, kind: str, rest: str) -> tuple[str, int | None]:
    channel, at, rate = rest.rpartition("@")
    if not at:
        return rest, None
    if kind not in _WITH_BITRATE:
        raise BusSpecError(f"bus {text!r}: {kind} takes no '@bitrate' (set it on the interface itself)")
    match = _RATE.match(rate)
    if not match:
        raise BusSpecError(f"bus {text!r}: bit rate {rate!r} is not a number (e.g. 500000, 500k or 1M)")
    value = int(match.group(1)) * {"": 1, "k": 1000, "m": 1_000_000}[match.group(2).lower()]
    if value <= 0:
        raise BusSpecError(f"bus {text!r}: bit rate must be positive")
    return channel, value


def _parse_socketcand(text: str, rest: str) -> BusSpec:
    address, slash, channel = rest.partition("/")
    host, colon, port_text = address.rpartition(":")
    if not colon or not host:
        raise BusSpecError(f"bus {text!r}: expected socketcand:HOST:PORT[/CHANNEL]")
    if not port_text.isdigit() or not 0 < int(port_text) < 65536:
        raise BusSpecError(f"bus {text!r}: port {port_text!r} is not a TCP port number (1..65535)")
    if slash and not channel:
        raise BusSpecError(f"bus {text!r}: missing channel after '/'")
    return BusSpec(kind="socketcand", host=host, port=int(port_text), channel=channel or DEFAULT_SOCKETCAND_CHANNEL)


def _parse_sim(text: str, nodes: str) -> BusSpec:
    if not _SIM_NODES.match(nodes):
        raise BusSpecError(f"bus {text!r}: simulated nodes must look like '1,2,3' or '1:xtrapulspac,2:cd1k'")
    for item in nodes.split(","):
        node = int(item.partition(":")[0])
        if not 1 <= node <= 127:
            raise BusSpecError(f"bus {text!r}: node {node} outside 1..127")
    return BusSpec(kind="sim", channel=nodes)
