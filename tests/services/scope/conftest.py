"""The capture service against simulated drives in this process (the server's ``sim`` bus; the bench:
``tests/support/scope_bench.py``), and one connection to the simulated drives over socketcand (whose endpoint a test
cuts)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.embedded_sim import SDO_TIMEOUT, open_sim
from tests.support.motion import controlling
from tests.support.scope_bench import ScopeBench, until_booted

from servostudio.services.bus import ConnectionManager


@pytest.fixture
def bench() -> Iterator[ScopeBench]:
    manager = ConnectionManager()
    open_sim(manager, "sim:1,2:cd1k")
    try:
        scope_bench = ScopeBench(manager.get("sim"))
        for node in (1, 2):
            until_booted(scope_bench.drive(node))
        with controlling(manager, "sim", (1, 2)):  # a capture's NMT start of an enabled axis needs its controller
            yield scope_bench
    finally:
        manager.close_all()


@pytest.fixture
def connection(socketcand):
    manager = ConnectionManager()
    opened = manager.open(socketcand.spec, wait=5.0)
    opened.engine.timeout = SDO_TIMEOUT
    yield opened
    manager.close_all()
