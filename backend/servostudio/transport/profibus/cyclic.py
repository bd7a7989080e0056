"""The cyclic Data_Exchange of one DP slave: parameterise it, then exchange its PPO every period in a thread, and
when it stops answering report that and parameterise it again until it is back (docs/profibus.md §6).

The owner gives the bytes of every output image (`outputs`) and takes every input image (`inputs`); it learns of
a lost or recovered slave through `on_link(error or None)`. The Set_Prm watchdog makes the slave drop its outputs
when this master goes quiet (the tool dies, the cable is cut), as the drive's own safety.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from servostudio.errors import ServoStudioError
from servostudio.transport.profibus.exchange import SlaveExchange
from servostudio.transport.profibus.ppo import Ppo

if TYPE_CHECKING:  # the master makes its exchanges (DpMaster.exchange)
    from servostudio.transport.profibus.master import DpMaster

PERIOD = 0.002
"""Seconds between two Data_Exchanges (the TTA-PRO wants its PZD at least every few milliseconds)."""
WATCHDOG = 0.2
"""Seconds of silence after which the slave leaves data exchange."""


class CyclicExchange(SlaveExchange):
    """The project's master's exchange: Set_Prm / Chk_Cfg itself, then one Data_Exchange per cycle; a lost slave is
    parameterised again at its next attempt."""

    def __init__(
        self,
        master: DpMaster,
        address: int,
        ppo: Ppo,
        outputs: Callable[[], bytes],
        inputs: Callable[[bytes], None],
        on_link: Callable[[ServoStudioError | None], None] = lambda _: None,
        period: float = PERIOD,
        watchdog: float | None = WATCHDOG,
    ) -> None:
        super().__init__(address, ppo, outputs, inputs, on_link, period, watchdog)
        self.master = master

    def start(self) -> CyclicExchange:
        """Parameterise now (errors go to the caller), then exchange in the background."""
        self._parameterise()
        self._run_in_background(f"profibus-dx-{self.address}")
        return self

    def _parameterise(self) -> None:
        ident = self.master.slave_diag(self.address).ident_number
        self.master.parameterise(self.address, self.ppo, self.watchdog, ident)

    def _step(self) -> None:
        if self.error is not None:
            self._parameterise()
            self._recovered()
        self._inputs(self.master.data_exchange(self.address, self._outputs()))
        self.cycles += 1
