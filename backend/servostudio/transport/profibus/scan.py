"""The scan of a DP line, the same for every master (`interface.DpLine`): Slave_Diag to each address with a short
timeout and no retry; the stations that answered, with their ident numbers (docs/profibus.md §7)."""

from __future__ import annotations

from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus.interface import DpLine
from servostudio.transport.profibus.master import DpNoResponse, DpRefused

SCAN_TIMEOUT = 0.02
"""Seconds an absent station costs a scan (no retry): 125 addresses in about 2.5 s."""
STATION_ADDRESSES = range(1, 126)


def scan(
    line: DpLine, addresses: range | list[int] = STATION_ADDRESSES, timeout: float = SCAN_TIMEOUT
) -> dict[int, dp.SlaveDiag]:
    """Every address that answered a Slave_Diag; one that is silent or refuses is not there."""
    found: dict[int, dp.SlaveDiag] = {}
    for address in addresses:
        try:
            found[address] = line.slave_diag(address, timeout=timeout, retries=0)
        except (DpNoResponse, DpRefused):
            continue
    return found
