"""What a DP master of this package offers its users (the TTA-PRO client, the bus connection, the scan), so that
the two masters are interchangeable (docs/profibus.md §7):

- `PyprofibusMaster` (`pyprofibus_master.py`): pyprofibus's class-1 master DPM1 over its serial PHY, the
  transport of a `profibus:PORT` line (an RS-485 adapter, the simulator's pseudo-terminal);
- `DpMaster` (`master.py`): the project's own master on a pyserial URL, for the simulator's TCP stream
  (`profibus:socket://HOST:PORT`), which pyprofibus's PHY cannot open.

Both raise only errors of the one root: `DpNoResponse` (Timeout), `DpRefused` (Communication), `DpLinkError`
(Unavailable), all in `master.py`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from servostudio.errors import ServoStudioError
from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus.ppo import Ppo

Outputs = Callable[[], bytes]
"""Gives the output image (PKW + PZD) for the next Data_Exchange."""
Inputs = Callable[[bytes], None]
"""Takes each input image the slave sent back."""
LinkReport = Callable[[ServoStudioError | None], None]
"""Told once when the slave is lost (the error) and once when it is back (None)."""


class DataExchange(Protocol):
    """The cyclic Data_Exchange of one slave, run in a thread by the master."""

    error: ServoStudioError | None
    """Why the slave is not in data exchange now; None while it is."""
    cycles: int
    """Data_Exchanges completed so far."""

    def start(self) -> DataExchange:
        """Parameterise the slave now (its errors go to the caller), then exchange in the background."""
        ...

    def stop(self) -> None: ...


class DpLine(Protocol):
    """A class-1 DP master on one line."""

    address: int
    """This master's station address."""

    def slave_diag(self, address: int, timeout: float | None = None, retries: int | None = None) -> dp.SlaveDiag: ...

    def global_control(self, command: int, group_select: int = 0) -> None: ...

    def exchange(
        self,
        address: int,
        ppo: Ppo,
        outputs: Outputs,
        inputs: Inputs,
        on_link: LinkReport,
        period: float,
        watchdog: float | None,
    ) -> DataExchange:
        """A cyclic Data_Exchange with `address` in `ppo` every `period` s, the slave's watchdog set to `watchdog`
        s (None: off); not started."""
        ...

    def close(self) -> None: ...
