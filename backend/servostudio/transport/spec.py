"""Bus spec strings: one short text names a CAN interface, its channel and bit rate.

``socketcan:can0``, ``pcan:PCAN_USBBUS1@1000000``, ``ixxat:0@500000``, ``kvaser:0``,
``slcan:/dev/ttyACM0@1000000``, ``socketcand:HOST:PORT[/CHANNEL]``, ``virtual:NAME``,
``serial:PORT_OR_URL[@BAUD]`` (the XtrapulsPac RS-232 link), ``profibus:PORT[@BAUD][?master=ADDR]`` (a PROFIBUS-DP
line: a serial device or a pyserial URL such as ``socket://HOST:PORT``, ``tcp:HOST:PORT`` for short; the TTA-PRO) and
``sim[:NODES]`` (simulated drives in this process, NODES as for ``servostudio sim``, e.g.
``1:xtrapulspac,2:cd1k``).  Any other interface python-can knows — its built-in backends and the plugins installed
beside it (``gs_usb:``, ``udp_multicast:``, ``vector:``, …) — is spelled the same way,
``INTERFACE:CHANNEL[@BITRATE]``, and every kind takes the interface's own options as a query, ``?name=value&…``
(``gs_usb:canable@1M?index=0``).  The name ``serial`` is the XtrapulsPac link, so python-can's own generic
``serial`` interface is not offered.  A spec is what the user types on the command line
and what the REST API takes, so the parser names the problem precisely.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from typing import Any

from can.interfaces import VALID_INTERFACES

from servostudio.errors import InvalidInput

#: kinds of our own; every other python-can interface is accepted as well (see ``known_kinds``)
OWN_KINDS = ("socketcand", "serial", "profibus", "sim")
#: interfaces whose bit rate is set outside the program (``ip link``, the other process), so '@' would mislead
_WITHOUT_BITRATE = {"socketcan", "socketcand", "virtual", "udp_multicast", "sim"}
_INTEGER_CHANNEL = {"ixxat", "kvaser"}
SERIAL_BAUDRATES = (9600, 19200, 38400, 57600, 115200)
DEFAULT_SERIAL_BAUDRATE = 19200
#: the PROFIBUS-DP baud rates (EN 50170); without one the DP master's default, 1.5 Mbit/s
PROFIBUS_BAUDRATES = (9600, 19200, 45450, 93750, 187500, 500000, 1500000, 3000000, 6000000, 12000000)
DEFAULT_PROFIBUS_MASTER = 2
#: DP master addresses: 0..125 (126 is the default address of an unset slave, 127 the broadcast)
PROFIBUS_MASTERS = range(126)
DEFAULT_SOCKETCAND_CHANNEL = "can0"
DEFAULT_SIM_NODES = "1,2,3"
_RATE = re.compile(r"^(\d+)([kKmM]?)$")
_OPTION_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
#: python-can's own interface of that name is shadowed by ours (the RS-232 link plugin is reached as ``serial:``)
_SHADOWED = {"serial", "servostudio_rs232"}


def known_kinds() -> tuple[str, ...]:
    """Every kind a spec may start with: ours and python-can's interfaces (built-in and installed plugins)."""
    python_can = sorted(set(VALID_INTERFACES) - _SHADOWED - set(OWN_KINDS))
    return (*OWN_KINDS, *python_can)


_SIM_NODES = re.compile(r"^\d+(:[A-Za-z0-9_-]+)?(,\d+(:[A-Za-z0-9_-]+)?)*$")


class BusSpecError(InvalidInput):
    """A spec string that does not name a usable bus; the message says which part is wrong and why."""


@dataclass(frozen=True)
class BusSpec:
    """A parsed bus spec; ``str(spec)`` gives back the canonical text."""

    kind: str
    channel: str = ""
    bitrate: int | None = None
    host: str = ""
    port: int = 0
    #: the interface's own keyword options, in the order given (``?index=0&bus=1``)
    options: tuple[tuple[str, str], ...] = ()

    def __str__(self) -> str:
        return self._address() + _query(self.options)

    def _address(self) -> str:
        if self.kind == "socketcand":
            return f"socketcand:{self.host}:{self.port}/{self.channel}"
        if self.kind == "sim":
            return "sim" if self.channel == DEFAULT_SIM_NODES else f"sim:{self.channel}"
        text = f"{self.kind}:{self.channel}"
        return f"{text}@{self.bitrate}" if self.bitrate is not None else text

    @property
    def profibus_master(self) -> int:
        """A ``profibus`` spec's master address (``?master=``, 2 by default)."""
        return int(dict(self.options).get("master", DEFAULT_PROFIBUS_MASTER))

    def python_can_config(self) -> dict[str, Any]:
        """Keyword arguments for ``can.Bus(**config)``; not available for ``sim`` (opened in-process) nor for
        ``profibus`` (no CAN bus: the DP master opens the line).

        The values are ``Any`` because ``can.Bus`` takes its interface options as ``**kwargs: Any``.
        """
        if self.kind == "sim":
            raise BusSpecError("the 'sim' bus is opened in-process, not through python-can")
        if self.kind == "profibus":
            raise BusSpecError("a 'profibus' bus is a PROFIBUS-DP line, not a CAN bus: python-can does not open it")
        return {**self._base_config(), **{name: _option_value(text) for name, text in self.options}}

    def _base_config(self) -> dict[str, Any]:
        if self.kind == "socketcand":
            return {"interface": "socketcand", "host": self.host, "port": self.port, "channel": self.channel}
        if self.kind == "serial":
            return {
                "interface": "servostudio_rs232",
                "channel": self.channel,
                "baudrate": self.bitrate or DEFAULT_SERIAL_BAUDRATE,
            }
        config: dict[str, Any] = {"interface": self.kind, "channel": self.channel}
        if self.kind in _INTEGER_CHANNEL:
            config["channel"] = int(self.channel)
        if self.bitrate is not None:
            config["bitrate"] = self.bitrate
        return config


def _query(options: tuple[tuple[str, str], ...]) -> str:
    return "?" + "&".join(f"{name}={value}" for name, value in options) if options else ""


def _option_value(text: str) -> int | float | bool | str:
    """An option's Python value: python-can's interfaces take numbers and flags as such, not as text."""
    lowered = text.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    for convert in (int, float):
        try:
            return convert(text)
        except ValueError:
            continue
    return text


def parse_bus_spec(text: str) -> BusSpec:
    """Parse a bus spec string; raise BusSpecError naming the wrong part."""
    text = text.strip()
    kind, colon, rest = text.partition(":")
    kind = kind.lower()
    if kind not in known_kinds():
        raise BusSpecError(f"bus {text!r}: unknown interface {kind!r}; expected one of {', '.join(known_kinds())}")
    if kind == "serial":  # a pyserial URL may carry a query of its own (rfc2217://HOST:PORT?logging=debug)
        return _parse_address(text, kind, rest, bool(colon))
    rest, options = _split_options(text, rest)
    if options and kind == "sim":
        raise BusSpecError(f"bus {text!r}: the simulated bus takes no options")
    if kind == "profibus":
        return replace(_parse_profibus(text, rest), options=_profibus_options(text, options))
    return replace(_parse_address(text, kind, rest, bool(colon)), options=options)


def _parse_address(text: str, kind: str, rest: str, has_colon: bool) -> BusSpec:
    if kind == "sim":
        return _parse_sim(text, rest if has_colon else DEFAULT_SIM_NODES)
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


def _split_options(text: str, rest: str) -> tuple[str, tuple[tuple[str, str], ...]]:
    """``CHANNEL?a=1&b=x`` → (``CHANNEL``, options); a name must be a Python keyword-argument name."""
    address, question, query = rest.partition("?")
    if not question:
        return rest, ()
    options: list[tuple[str, str]] = []
    for item in query.split("&"):
        name, equals, value = item.partition("=")
        if not equals or not _OPTION_NAME.match(name) or not value:
            raise BusSpecError(f"bus {text!r}: option {item!r} must look like name=value")
        if name in ("interface", "channel", "bitrate") or any(name == seen for seen, _ in options):
            raise BusSpecError(f"bus {text!r}: option {name!r} is given twice or is part of the spec itself")
        options.append((name, value))
    return address, tuple(options)


def _split_bitrate(text: str, kind: str, rest: str) -> tuple[str, int | None]:
    channel, at, rate = rest.rpartition("@")
    if not at:
        return rest, None
    if kind in _WITHOUT_BITRATE:
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


def _parse_profibus(text: str, rest: str) -> BusSpec:
    """``PORT[@BAUD]``: a serial device or pyserial URL; ``tcp:HOST:PORT`` is ``socket://HOST:PORT``."""
    port, at, rate = rest.rpartition("@") if "@" in rest else (rest, "", "")
    if not port:
        raise BusSpecError(f"bus {text!r}: missing port after 'profibus:' (a serial device or socket://HOST:PORT)")
    if port.lower().startswith("tcp:"):
        port = "socket://" + port[4:]
    if port.startswith("socket://"):
        _check_tcp_address(text, port.removeprefix("socket://"))
    baud = _split_bitrate(text, "profibus", f"x@{rate}")[1] if at else None
    if baud is not None and baud not in PROFIBUS_BAUDRATES:
        allowed = ", ".join(map(str, PROFIBUS_BAUDRATES))
        raise BusSpecError(f"bus {text!r}: PROFIBUS baud rate {baud} not supported; use one of {allowed}")
    return BusSpec(kind="profibus", channel=port, bitrate=baud)


def _check_tcp_address(text: str, address: str) -> None:
    host, colon, port_text = address.rpartition(":")
    if not colon or not host or not port_text.isdigit() or not 0 < int(port_text) < 65536:
        raise BusSpecError(f"bus {text!r}: expected socket://HOST:PORT (or tcp:HOST:PORT), PORT 1..65535")


def _profibus_options(text: str, options: tuple[tuple[str, str], ...]) -> tuple[tuple[str, str], ...]:
    """Only ``master=ADDR`` (0..125), kept as its number and left out when it is the default, so every spelling
    of one line is one bus."""
    for name, value in options:
        if name != "master":
            raise BusSpecError(f"bus {text!r}: a profibus bus takes only the option master=ADDR, not {name!r}")
        if not value.isdigit() or int(value) not in PROFIBUS_MASTERS:
            raise BusSpecError(f"bus {text!r}: master address {value!r} outside 0..125")
    return tuple((name, str(int(value))) for name, value in options if int(value) != DEFAULT_PROFIBUS_MASTER)
