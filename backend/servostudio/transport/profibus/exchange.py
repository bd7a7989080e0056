"""What the cyclic Data_Exchange of one DP slave is for every master (`interface.DataExchange`): the owner's
images out and in, a thread that runs one cycle every period (every `RETRY_PERIOD` while the slave is lost), and
one report of a lost and of a recovered slave. A master's exchange says how it starts and what one cycle is
(`CyclicExchange` in `cyclic.py`, `PyprofibusExchange` in `pyprofibus_master.py`)."""

from __future__ import annotations

import logging
import threading

from servostudio.errors import ServoStudioError
from servostudio.transport.profibus.interface import Inputs, LinkReport, Outputs
from servostudio.transport.profibus.ppo import Ppo

log = logging.getLogger(__name__)

RETRY_PERIOD = 0.1
"""Seconds between two attempts to bring a lost slave back."""


class SlaveExchange:
    def __init__(
        self,
        address: int,
        ppo: Ppo,
        outputs: Outputs,
        inputs: Inputs,
        on_link: LinkReport,
        period: float,
        watchdog: float | None,
    ) -> None:
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

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def _run_in_background(self, name: str) -> None:
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(self.period if self.error is None else RETRY_PERIOD):
            try:
                self._step()
            except ServoStudioError as error:
                self._lost(error)

    def _step(self) -> None:
        """One cycle; a `ServoStudioError` from it loses the slave."""
        raise NotImplementedError

    def _lost(self, error: ServoStudioError) -> None:
        if self.error is None:
            log.warning("PROFIBUS slave %d lost: %s", self.address, error)
        self.error = error
        self._on_link(error)

    def _recovered(self) -> None:
        log.info("PROFIBUS slave %d back in data exchange", self.address)
        self.error = None
        self._on_link(None)
