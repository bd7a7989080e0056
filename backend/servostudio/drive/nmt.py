"""NMT commands (CiA 301): one frame on COB-ID 0, ``[command, node]``; node 0 addresses every node."""

from __future__ import annotations

import enum
import weakref
from collections.abc import Callable

from servostudio.drive.link import BusLink
from servostudio.errors import InvalidInput


class NmtCommand(enum.IntEnum):
    START = 0x01
    STOP = 0x02
    PRE_OPERATIONAL = 0x80
    RESET_NODE = 0x81
    RESET_COMMUNICATION = 0x82

    @classmethod
    def parse(cls, text: str) -> NmtCommand:
        """Accept the names the CLI and REST use: start, stop, pre-operational, reset-node, reset-communication."""
        key = text.strip().lower().replace("-", "_").replace(" ", "_")
        aliases = {
            "preop": "pre_operational",
            "reset": "reset_node",
            "reset_comm": "reset_communication",
            "operational": "start",
        }
        key = aliases.get(key, key)
        try:
            return cls[key.upper()]
        except KeyError:
            names = ", ".join(name.lower().replace("_", "-") for name in cls.__members__)
            raise InvalidInput(f"unknown NMT command {text!r}; use one of {names}") from None


#: NMT state byte of heartbeat / boot-up frames (0x700 + node)
NMT_STATES = {0x00: "INITIALISING", 0x04: "STOPPED", 0x05: "OPERATIONAL", 0x7F: "PRE-OPERATIONAL"}


#: hears an NMT command's outcome: None once the frame is on the bus, else the error that kept it off
NmtHeard = Callable[[BaseException | None], None]
#: judges an NMT command before it is sent (raising refuses it) and returns what hears its outcome
NmtGate = Callable[[NmtCommand, int], NmtHeard]
_gates: weakref.WeakKeyDictionary[BusLink, NmtGate] = weakref.WeakKeyDictionary()


def guard_nmt(link: BusLink, gate: NmtGate) -> None:
    """Have ``gate`` (the bus connection's motion guard) judge every NMT command sent on ``link`` from now on,
    whoever sends it — the NMT route, a capture starting its silent nodes, a measurement — so none goes around it."""
    _gates[link] = gate


def send_nmt(link: BusLink, command: NmtCommand, node: int = 0) -> None:
    """Send one NMT command (node 0: all nodes), judged first by the link's gate if it has one."""
    if not 0 <= node <= 127:
        raise InvalidInput(f"node ID {node} outside 0..127 (0 = all nodes)")
    gate = _gates.get(link)
    heard = gate(command, node) if gate is not None else _unheard
    try:
        link.send(0x000, bytes([int(command), node]))
    except BaseException as error:
        heard(error)
        raise
    heard(None)


def _unheard(error: BaseException | None) -> None:
    """A link without a gate (a bare link of a test or tool) logs nothing."""


#: what an SDO answer proves: a STOPPED or initialising node answers no SDO (CiA 301 §7.3.2.2)
ANSWERS_SDO = "PRE-OPERATIONAL or OPERATIONAL"


def known_nmt_state(announced: str | None, answered_sdo: bool) -> dict[str, str | None]:
    """What is known of a node's NMT state, and from what: its own heartbeat or boot-up (exact), else an SDO answer
    (at least pre-operational), else nothing.  A heartbeat saying STOPPED is stale once the node answers SDO."""
    if announced is not None and not (answered_sdo and announced in ("STOPPED", "INITIALISING")):
        return {"nmt_state": announced, "nmt_source": "heartbeat", "nmt_text": announced}
    if answered_sdo:
        return {"nmt_state": None, "nmt_source": "sdo", "nmt_text": f"{ANSWERS_SDO} (answers SDO; no heartbeat seen)"}
    return {"nmt_state": None, "nmt_source": None, "nmt_text": "unknown (no heartbeat, no SDO answer)"}
