"""Fixtures of the simulator communication tests: networks of the small CiA 402 test drive and raw clients on them
(the drive, its behaviour and the client: ``tests/support/sim_test_drive.py``)."""

from __future__ import annotations

import pytest
from tests.support.sim_test_drive import DATA, RawClient, counting_factory

from servostudio.od import load_dictionary
from servostudio.sim.network import SimulatedNetwork


@pytest.fixture(scope="session")
def test_dictionary():
    return load_dictionary(DATA / "testdrive.eds")


@pytest.fixture
def make_network(test_dictionary):
    """Factory of networks of test drives; every network made is stopped at the end of the test."""
    made: list[SimulatedNetwork] = []

    def make(nodes: str = "1", **options) -> SimulatedNetwork:
        options.setdefault("behaviour_factory", counting_factory)
        network = SimulatedNetwork(nodes, device="testdrive", dictionaries={"testdrive": test_dictionary}, **options)
        made.append(network)
        return network

    yield make
    for network in made:
        network.stop()


@pytest.fixture
def raw_client():
    """Factory: a RawClient on a network, shut down at the end of the test."""
    clients: list[RawClient] = []

    def make(network: SimulatedNetwork) -> RawClient:
        client = RawClient(network)
        clients.append(client)
        return client

    yield make
    for client in clients:
        client.close()
