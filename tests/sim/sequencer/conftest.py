"""Benches of the sequencer seen from outside: one real-time simulated XtrapulsPac and an independent `canopen` peer
on the in-process bus, plus a probe on the simulator's thread (the bench, its probe and the objects it watches:
``tests/support/sequencer_bench.py``)."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence

import pytest
from tests.support.sequencer_bench import (
    CAPTURED,
    CURRENT,
    NODE_ID,
    POSITION,
    STATUS_WORD,
    VELOCITY,
    Bench,
    Key,
    commissioned,
)

from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.plant import Plant


@pytest.fixture
def bench_factory(tmp_path) -> Iterator[Callable[..., Bench]]:
    """Benches on fresh real-time drives (the commissioned default machine unless a plant is given); each closed
    and stopped at the end of the test. `program` is a SEQUENCE.TXT the drive finds in its flash at power-on."""
    made: list[tuple[Bench, SimulatedNetwork]] = []

    def make(probe: Sequence[Key] = (), plant: Plant | None = None, program: str | None = None) -> Bench:
        if program is not None:
            (tmp_path / f"node{NODE_ID}").mkdir(exist_ok=True)
            (tmp_path / f"node{NODE_ID}" / "SEQUENCE.TXT").write_text(program, encoding="latin-1")
        factory = commissioned(plant) if plant is not None else None
        network = SimulatedNetwork(str(NODE_ID), state_dir=tmp_path, behaviour_factory=factory)
        network.start()
        bench = Bench(network, tmp_path, probe)
        made.append((bench, network))
        return bench

    yield make
    for bench, network in made:
        bench.close()
        network.stop()


@pytest.fixture
def bench(bench_factory) -> Bench:
    """A bench on the commissioned default machine, probing position, speed, current and status word."""
    return bench_factory(probe=(POSITION, VELOCITY, CURRENT, STATUS_WORD, CAPTURED))
