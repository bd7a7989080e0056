"""The procedure service against simulated drives in this process, on hidden seeded plants, with virtual time run
faster than the wall clock by a thread of the test's own (a procedure of seconds takes a fraction of one; the bench:
``tests/support/procedure_bench.py``)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.procedure_bench import Bench, open_bench


@pytest.fixture
def bench_factory() -> Iterator:
    opened: list[Bench] = []

    def make(nodes: str = "1", seed: int | None = None, speed: float = 5.0) -> Bench:
        opened.append(open_bench(nodes, seed, speed))
        return opened[-1]

    yield make
    for bench in opened:
        bench.manager.close_all()
