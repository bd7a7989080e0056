"""The cyclic Data_Exchange of one DP slave: parameterise it, then exchange its PPO every period in a thread, and
when it stops answering report that and parameterise it again until it is back (docs/profibus.md §6).

The owner gives the bytes of every output image (`outputs`) and takes every input image (`inputs`); it learns of
a lost or recovered slave through `on_link(error or None)`. The Set_Prm watchdog makes the slave drop its outputs
when this master goes quiet (the tool dies, the cable is cut), as the drive's own safety.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

from servostudio.errors import ServoStudioError
from servostudio.transport.profibus.ppo import Ppo

if TYPE_CHECKING:  # the master makes its exchanges (DpMaster.exchange)
    from servostudio.transport.profibus.master import DpMaster

log = logging.getLogger(__name__)

PERIOD = 0.002
"""Seconds between two Data_Exchanges (the TTA-PRO wants its PZD at least every few milliseconds)."""
WATCHDOG = 0.2
"""Seconds of silence after which the slave leaves data exchange."""
RETRY_PERIOD = 0.1
"""Seconds between two parameterisation attempts of a lost slave."""


class CyclicExchange:
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
        self.master = master
        self.address = address
        self.ppo = ppo
        self._outputs = outputs
        self._inputs = inputs
        self._on_link = on_link
        self.period = period
        self.watchdog = watchdog
        self.error: ServoStudioError | None = None
        self.cycles = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> CyclicExchange:
        """Parameterise now (errors go to the caller), then exchange in the background."""
        self._parameterise()
        self._thread = threading.Thread(target=self._run, name=f"profibus-dx-{self.address}", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def _parameterise(self) -> None:
        ident = self.master.slave_diag(self.address).ident_number
        self.master.parameterise(self.address, self.ppo, self.watchdog, ident)

    def _run(self) -> None:
        while not self._stop.wait(self.period if self.error is None else RETRY_PERIOD):
            try:
                self._step()
            except ServoStudioError as error:
                self._lost(error)

    def _step(self) -> None:
        if self.error is not None:
            self._parameterise()
            self._recovered()
        self._inputs(self.master.data_exchange(self.address, self._outputs()))
        self.cycles += 1

    def _lost(self, error: ServoStudioError) -> None:
        if self.error is None:
            log.warning("PROFIBUS slave %d lost: %s", self.address, error)
        self.error = error
        self._on_link(error)

    def _recovered(self) -> None:
        log.info("PROFIBUS slave %d back in data exchange", self.address)
        self.error = None
        self._on_link(None)
