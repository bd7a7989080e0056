"""Acceptance fixtures: one real-time simulated XtrapulsPac behind a socketcand server, reached by an independent
peer that uses only the `canopen` library (`BaseNode402` with the built-in EDS), as an integrator's script would.

Every wait is bounded by a wall-clock timeout and fails with the last status word seen, so a stuck drive gives a
readable failure instead of a hanging suite (the axis and its waits: ``tests/support/canopen_axis.py``).
"""

from __future__ import annotations

import canopen
import pytest
from canopen.profiles.p402 import BaseNode402
from tests.support.canopen_axis import NODE_ID, SYNC_PERIOD, WAIT, XTRAPULSPAC_EDS, Axis, configure_pdos

from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.socketcand import SocketcandServer


@pytest.fixture
def axis():
    """A fresh drive per test (the commissioned default machine), paced in real time, and its canopen peer.

    The peer produces SYNC; the control word goes through the default RPDO 1 (type 255), the operation mode and
    set-points by SDO.
    """
    network = SimulatedNetwork(str(NODE_ID))
    network.start()
    server = SocketcandServer(network, port=0).start()
    client = canopen.Network()
    client.NOTIFIER_CYCLE = 0.1  # the reader thread notices disconnect() within 0.1 s instead of 1 s
    try:
        host, port = server.address
        client.connect(interface="socketcand", host=host, port=port, channel="can0")
        node = BaseNode402(NODE_ID, XTRAPULSPAC_EDS)
        node.sdo.RESPONSE_TIMEOUT = 5.0
        node.TIMEOUT_SWITCH_STATE_FINAL = WAIT
        node.TIMEOUT_SWITCH_STATE_SINGLE = 2.0
        node.TIMEOUT_SWITCH_OP_MODE = WAIT
        node.TIMEOUT_CHECK_TPDO = 1.0
        client.add_node(node)
        node.nmt.state = "PRE-OPERATIONAL"
        configure_pdos(node)
        node.setup_402_state_machine(read_pdos=True)
        axis = Axis(node)
        client.sync.start(SYNC_PERIOD)
        node.nmt.state = "OPERATIONAL"
        axis.wait_state("SWITCH ON DISABLED")
        yield axis
    finally:
        client.sync.stop()
        if client.bus is not None:
            client.disconnect()
        server.stop()
        network.stop()
